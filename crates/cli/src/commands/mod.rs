//! One module per subcommand.

pub mod calibrate;
pub mod compensate;
pub mod demo;
pub mod derive;
pub mod dipole;
pub mod em;
pub mod grid;
pub mod igrf;
pub mod inspect;
pub mod level;
pub mod microlevel;
pub mod observability;
pub mod pod;
pub mod report;
pub mod rotor;
pub mod simulate;
pub mod stream;

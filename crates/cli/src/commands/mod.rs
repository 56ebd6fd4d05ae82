//! One module per subcommand.

pub mod calibrate;
pub mod compensate;
pub mod demo;
pub mod dipole;
pub mod em;
pub mod igrf;
pub mod inspect;
pub mod level;
pub mod observability;
pub mod pod;
pub mod report;
pub mod rotor;
pub mod simulate;
pub mod stream;

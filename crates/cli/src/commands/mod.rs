//! One module per subcommand.

pub mod calibrate;
pub mod compensate;
pub mod demo;
pub mod dipole;
pub mod igrf;
pub mod inspect;
pub mod level;
pub mod report;
pub mod simulate;

//! Linear least squares.

pub mod normal_equations;

pub use normal_equations::{BlockProducts, LsSolution, NormalEquations};

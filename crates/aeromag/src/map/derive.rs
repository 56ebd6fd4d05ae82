//! Grids derived from grid files: the first vertical derivative, upward
//! continuation (FFT, [`aeromag_grid::products`]) and the difference of
//! two grids (e.g. against the truth grid of simulated data).

use crate::error::Result;
use aeromag_grid::Grid;
use aeromag_grid::format::read_grid;
use aeromag_grid::products::{Spectral, apply};
use std::path::{Path, PathBuf};

/// What [`derive`] computes.
#[derive(Debug, Clone, PartialEq)]
pub enum GridProduct {
    /// First vertical derivative (z down), unit per metre.
    VerticalDerivative,
    /// Upward continuation by this height, m.
    Upward(f64),
    /// The grid minus this other grid (same nodes).
    Minus(PathBuf),
}

/// Read the grid file `input` (GeoTIFF, ESRI ASCII or netCDF) and compute
/// `product` from it; blanks stay blank.
pub fn derive(input: &Path, product: &GridProduct) -> Result<Grid> {
    let grid = read_grid(input)?;
    Ok(match product {
        GridProduct::VerticalDerivative => apply(&grid, Spectral::VerticalDerivative)?,
        GridProduct::Upward(h) => apply(&grid, Spectral::UpwardContinuation(*h))?,
        GridProduct::Minus(other) => grid.difference(&read_grid(other)?)?,
    })
}

//! Grids derived from grid files: the first vertical derivative, upward
//! continuation (FFT, [`aeromag_grid::products`]) and the difference of
//! two grids (e.g. against the truth grid of simulated data).

use crate::error::{InFile, Result};
use aeromag_grid::format::read_grid;
use aeromag_grid::products::{Spectral, apply};
use aeromag_grid::{Grid, GridError};
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

/// Read the grid file `input` (GeoTIFF, ESRI ASCII, netCDF, GXF, Surfer) and compute
/// `product` from it; blanks stay blank.
///
/// Errors name the file: a grid file that cannot be read or holds values
/// it should not ([`read_grid`]), a grid too small for the product or
/// without any value, a continuation height out of
/// [`height_range`](aeromag_grid::products::height_range), grids of
/// different nodes, a difference without any value (no node is set in
/// both grids).
pub fn derive(input: &Path, product: &GridProduct) -> Result<Grid> {
    let grid = read_grid(input)?;
    let file = input.display().to_string();
    let result = match product {
        GridProduct::VerticalDerivative => {
            apply(&grid, Spectral::VerticalDerivative).in_file(&file)?
        }
        GridProduct::Upward(h) => apply(&grid, Spectral::UpwardContinuation(*h)).in_file(&file)?,
        GridProduct::Minus(other) => {
            let both = format!("{file} minus {}", other.display());
            let d = grid.difference(&read_grid(other)?).in_file(&both)?;
            if d.stats().count == 0 {
                return Err(GridError::Unusable(
                    "the difference has no value: no node is set in both grids".into(),
                ))
                .in_file(&both);
            }
            d
        }
    };
    Ok(result)
}

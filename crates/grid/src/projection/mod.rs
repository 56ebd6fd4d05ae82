//! Coordinate systems of grids: WGS 84 / UTM (zone picked from the data or
//! given), with the EPSG code and WKT the grid files carry.

pub mod utm;

pub use utm::{Utm, UtmZone};

/// The coordinate system of a grid's `x`, `y`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Crs {
    /// WGS 84 / UTM: EPSG 326zz (north) or 327zz (south).
    Utm(UtmZone),
}

impl Crs {
    /// The EPSG code (e.g. 32637 for WGS 84 / UTM zone 37N).
    pub fn epsg(&self) -> u16 {
        match self {
            Crs::Utm(z) => z.epsg(),
        }
    }

    /// The name, e.g. `WGS 84 / UTM zone 37N`.
    pub fn name(&self) -> String {
        match self {
            Crs::Utm(z) => format!("WGS 84 / {z}"),
        }
    }
}

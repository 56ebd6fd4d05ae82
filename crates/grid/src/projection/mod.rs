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

    /// OGC WKT 1 with its EPSG authority, as the grid files carry it.
    pub fn wkt(&self) -> String {
        crate::format::crs_wkt(self)
    }

    /// The system a WKT (1 or 2, OGC or ESRI flavour) names, as the grid
    /// files' readers take it: its outermost EPSG authority, else a
    /// `UTM zone 37N`-like name on a WGS 84 datum; `None` for any other.
    pub fn from_wkt(wkt: &str) -> Option<Crs> {
        crate::format::crs_from_wkt(wkt)
    }

    /// [`Crs::from_wkt`] for coordinates taken as metres: the reason, as
    /// the grid files' readers give it, when the WKT declares degrees (a
    /// geographic system) or another length unit; `Ok(None)` for an empty
    /// WKT or one naming no system this crate knows.
    pub fn from_wkt_in_metres(wkt: &str) -> Result<Option<Crs>, String> {
        use crate::format::{CoordinateUnit, not_metres_reason, wkt_unit};
        if wkt.trim().is_empty() {
            return Ok(None);
        }
        match wkt_unit(wkt) {
            Some(unit) if unit != CoordinateUnit::Metre => Err(not_metres_reason("its WKT", &unit)),
            _ => Ok(Crs::from_wkt(wkt.trim())),
        }
    }
}

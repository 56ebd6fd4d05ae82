//! WGS84 geodetic coordinates and their conversion to geocentric spherical
//! coordinates (needed by spherical-harmonic field models such as IGRF).

/// WGS84 semi-major axis, m.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// A WGS84 geodetic position.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Geodetic {
    /// Geodetic latitude, degrees, north positive.
    pub lat_deg: f64,
    /// Longitude, degrees, east positive.
    pub lon_deg: f64,
    /// Height above the WGS84 ellipsoid, m.
    pub alt_m: f64,
}

/// A geocentric spherical position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geocentric {
    /// Distance from the Earth's centre, m.
    pub r_m: f64,
    /// Geocentric colatitude θ, rad (0 at the north pole).
    pub colat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
}

impl Geodetic {
    /// Position from degrees and metres.
    pub fn new(lat_deg: f64, lon_deg: f64, alt_m: f64) -> Self {
        Self {
            lat_deg,
            lon_deg,
            alt_m,
        }
    }

    /// Earth-centred Earth-fixed Cartesian coordinates, m.
    pub fn to_ecef(&self) -> [f64; 3] {
        let e2 = WGS84_F * (2.0 - WGS84_F);
        let (sl, cl) = self.lat_deg.to_radians().sin_cos();
        let (so, co) = self.lon_deg.to_radians().sin_cos();
        let n = WGS84_A / (1.0 - e2 * sl * sl).sqrt();
        [
            (n + self.alt_m) * cl * co,
            (n + self.alt_m) * cl * so,
            (n * (1.0 - e2) + self.alt_m) * sl,
        ]
    }

    /// Geocentric spherical coordinates of this point.
    pub fn to_geocentric(&self) -> Geocentric {
        let [x, y, z] = self.to_ecef();
        let p = x.hypot(y);
        Geocentric {
            r_m: p.hypot(z),
            colat_rad: p.atan2(z),
            lon_rad: self.lon_deg.to_radians(),
        }
    }

    /// Angle ψ = (geodetic latitude − geocentric latitude), rad. A vector with
    /// geocentric components (north `Bθ`-based, down `Br`-based) is rotated to
    /// the geodetic (ellipsoidal) north/down by this angle:
    /// `X = X_c cos ψ + Z_c sin ψ`, `Z = −X_c sin ψ + Z_c cos ψ`.
    pub fn geodetic_minus_geocentric_lat(&self) -> f64 {
        let g = self.to_geocentric();
        let geoc_lat = std::f64::consts::FRAC_PI_2 - g.colat_rad;
        self.lat_deg.to_radians() - geoc_lat
    }

    /// Local flat-earth offsets (north, east, down) in metres of `other`
    /// relative to `self`, using the ellipsoid's radii of curvature at `self`.
    /// Accurate to better than 0.1 % over survey blocks of tens of km. The
    /// longitude difference is the shorter way round: a survey across the
    /// antimeridian (179.9° and −179.9°) is 0.2° wide, not 359.8° (levelling
    /// formed crossovers 22 000 km apart).
    pub fn ned_offset_to(&self, other: &Geodetic) -> [f64; 3] {
        let (rm, rn) = self.radii_of_curvature();
        let dn = (other.lat_deg - self.lat_deg).to_radians() * (rm + self.alt_m);
        // Wrapped only beyond ±180°, so that every other difference keeps
        // its bits.
        let dlon = match other.lon_deg - self.lon_deg {
            d if d > 180.0 => d - 360.0,
            d if d < -180.0 => d + 360.0,
            d => d,
        };
        let de = dlon.to_radians() * (rn + self.alt_m) * self.lat_deg.to_radians().cos();
        [dn, de, self.alt_m - other.alt_m]
    }

    /// The point displaced by (north, east) metres and with height `alt_m`.
    pub fn offset_by(&self, north_m: f64, east_m: f64, alt_m: f64) -> Geodetic {
        let (rm, rn) = self.radii_of_curvature();
        Geodetic {
            lat_deg: self.lat_deg + (north_m / (rm + self.alt_m)).to_degrees(),
            lon_deg: self.lon_deg
                + (east_m / ((rn + self.alt_m) * self.lat_deg.to_radians().cos())).to_degrees(),
            alt_m,
        }
    }

    /// Meridian (M) and prime-vertical (N) radii of curvature, m.
    pub fn radii_of_curvature(&self) -> (f64, f64) {
        let e2 = WGS84_F * (2.0 - WGS84_F);
        let s = self.lat_deg.to_radians().sin();
        let w = (1.0 - e2 * s * s).sqrt();
        (WGS84_A * (1.0 - e2) / (w * w * w), WGS84_A / w)
    }
}

#[cfg(test)]
mod tests {
    /// Across the antimeridian the east offset is the short way round, and
    /// the same as between 19.9° and 20.1°.
    #[test]
    fn offsets_across_the_antimeridian_are_the_short_way_round() {
        let at = |lon: f64| super::Geodetic::new(-17.0, lon, 0.0);
        let across = at(179.9).ned_offset_to(&at(-179.9));
        let plain = at(19.9).ned_offset_to(&at(20.1));
        assert!(
            (across[1] - plain[1]).abs() < 1e-6,
            "{across:?} vs {plain:?}"
        );
        let back = at(-179.9).ned_offset_to(&at(179.9));
        assert!((back[1] + plain[1]).abs() < 1e-6, "{back:?}");
    }

    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn equator_and_pole() {
        let g = Geodetic::new(0.0, 0.0, 0.0).to_geocentric();
        assert_relative_eq!(g.r_m, WGS84_A, epsilon = 1e-6);
        assert_relative_eq!(g.colat_rad, std::f64::consts::FRAC_PI_2, epsilon = 1e-15);
        let p = Geodetic::new(90.0, 0.0, 0.0).to_geocentric();
        assert_relative_eq!(p.r_m, WGS84_A * (1.0 - WGS84_F), epsilon = 1e-6);
    }

    #[test]
    fn offset_round_trip() {
        let o = Geodetic::new(45.0, 10.0, 300.0);
        let p = o.offset_by(1234.0, -567.0, 300.0);
        let [n, e, d] = o.ned_offset_to(&p);
        assert_relative_eq!(n, 1234.0, epsilon = 1e-6);
        assert_relative_eq!(e, -567.0, epsilon = 1e-6);
        assert_relative_eq!(d, 0.0, epsilon = 1e-9);
    }

    #[test]
    fn geocentric_latitude_is_smaller_in_the_north() {
        let d = Geodetic::new(45.0, 0.0, 0.0).geodetic_minus_geocentric_lat();
        // about 0.1924 degrees at 45°
        assert!((d.to_degrees() - 0.1924).abs() < 1e-3);
    }
}

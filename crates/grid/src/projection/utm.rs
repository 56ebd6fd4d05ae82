//! WGS 84 / UTM: the transverse Mercator projection of the 60 UTM zones,
//! zone choice (with the Norway and Svalbard exceptions), zone names and
//! EPSG codes, and the WKT a `.prj` file or GDAL reads.
//!
//! # Method
//!
//! Krüger's series to order n⁶ as given by C. F. F. Karney, "Transverse
//! Mercator with an accuracy of a few nanometres", *J. Geodesy* 85 (2011)
//! 475–485, implemented here from the paper's equations. Karney reports the
//! series errors to be below 5 nm within 3900 km of the central meridian,
//! which covers a UTM zone and several zones either side (this module
//! accepts up to 30° of longitude from the central meridian).
//!
//! With the ellipsoid's flattening `f`, third flattening `n = f / (2 − f)`,
//! eccentricity `e = √(f (2 − f))`, latitude φ and longitude λ from the
//! central meridian:
//!
//! - conformal latitude: `τ = tan φ`, `σ = sinh(e atanh(e τ / √(1 + τ²)))`,
//!   `τ′ = τ √(1 + σ²) − σ √(1 + τ²)`;
//! - Gauss–Schreiber transverse Mercator on the conformal sphere:
//!   `ξ′ = atan2(τ′, cos λ)`, `η′ = asinh(sin λ / √(τ′² + cos² λ))`;
//! - Krüger's series: `ξ + iη = ζ′ + Σⱼ αⱼ sin(2j ζ′)` with `ζ′ = ξ′ + iη′`
//!   (j = 1…6), i.e. `ξ = ξ′ + Σ αⱼ sin 2jξ′ cosh 2jη′`,
//!   `η = η′ + Σ αⱼ cos 2jξ′ sinh 2jη′`;
//! - `x = k₀ A η`, `y = k₀ A ξ` with the rectifying radius
//!   `A = a / (1 + n) · (1 + n²/4 + n⁴/64 + n⁶/256)`.
//!
//! The inverse runs the series `ζ′ = ζ − Σⱼ βⱼ sin(2j ζ)`, then
//! `τ′ = sin ξ′ / √(sinh² η′ + cos² ξ′)`, `λ = atan2(sinh η′, cos ξ′)`, and
//! solves `τ′(τ) = τ′` for τ by Newton's method with
//! `dτ′/dτ = (1 − e²) √(1 + τ′²) √(1 + τ²) / (1 + (1 − e²) τ²)`.
//!
//! The coefficients αⱼ and βⱼ are polynomials in n (Karney 2011, to n⁶):
//!
//! ```text
//! α₁ = 1/2 n − 2/3 n² + 5/16 n³ + 41/180 n⁴ − 127/288 n⁵ + 7891/37800 n⁶
//! α₂ = 13/48 n² − 3/5 n³ + 557/1440 n⁴ + 281/630 n⁵ − 1983433/1935360 n⁶
//! α₃ = 61/240 n³ − 103/140 n⁴ + 15061/26880 n⁵ + 167603/181440 n⁶
//! α₄ = 49561/161280 n⁴ − 179/168 n⁵ + 6601661/7257600 n⁶
//! α₅ = 34729/80640 n⁵ − 3418889/1995840 n⁶
//! α₆ = 212378941/319334400 n⁶
//!
//! β₁ = 1/2 n − 2/3 n² + 37/96 n³ − 1/360 n⁴ − 81/512 n⁵ + 96199/604800 n⁶
//! β₂ = 1/48 n² + 1/15 n³ − 437/1440 n⁴ + 46/105 n⁵ − 1118711/3870720 n⁶
//! β₃ = 17/480 n³ − 37/840 n⁴ − 209/4480 n⁵ + 5569/90720 n⁶
//! β₄ = 4397/161280 n⁴ − 11/504 n⁵ − 830251/7257600 n⁶
//! β₅ = 4583/161280 n⁵ − 108847/3991680 n⁶
//! β₆ = 20648693/638668800 n⁶
//! ```
//!
//! The sums over j are evaluated with Clenshaw's recurrence in complex
//! arithmetic (one sine, cosine, sinh and cosh per point).
//!
//! # UTM
//!
//! WGS 84 (a = 6 378 137 m, 1/f = 298.257 223 563), scale on the central
//! meridian k₀ = 0.9996, false easting 500 000 m, false northing 0 m in the
//! north and 10 000 000 m in the south. Zone `z` has its central meridian at
//! `6z − 183` degrees. Angles are in degrees and coordinates in metres
//! throughout the public API.

use std::fmt;
use std::str::FromStr;

use crate::error::{GridError, Result};
use crate::median;

/// WGS 84 semi-major axis, metres.
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS 84 inverse flattening.
const WGS84_INV_F: f64 = 298.257_223_563;
/// UTM scale factor on the central meridian.
const UTM_K0: f64 = 0.9996;
/// UTM false easting, metres.
const FALSE_EASTING_M: f64 = 500_000.0;
/// UTM false northing in the southern hemisphere, metres.
const FALSE_NORTHING_SOUTH_M: f64 = 10_000_000.0;

/// Southern limit of the UTM zones (zone choice), degrees.
const ZONE_LAT_MIN_DEG: f64 = -80.0;
/// Northern limit of the UTM zones (zone choice), degrees.
const ZONE_LAT_MAX_DEG: f64 = 84.0;
/// Southern limit of [`Utm::forward`] (the zones overlap UPS by 30′), degrees.
pub const FORWARD_LAT_MIN_DEG: f64 = -80.5;
/// Northern limit of [`Utm::forward`], degrees.
pub const FORWARD_LAT_MAX_DEG: f64 = 84.5;
/// Largest longitude difference from the central meridian that
/// [`Utm::forward`] accepts, degrees.
const FORWARD_MAX_DLON_DEG: f64 = 30.0;

/// Krüger's α coefficients: row j−1 holds the coefficients of n¹…n⁶ in αⱼ.
const ALPHA: [[f64; 6]; 6] = [
    [
        1.0 / 2.0,
        -2.0 / 3.0,
        5.0 / 16.0,
        41.0 / 180.0,
        -127.0 / 288.0,
        7891.0 / 37800.0,
    ],
    [
        0.0,
        13.0 / 48.0,
        -3.0 / 5.0,
        557.0 / 1440.0,
        281.0 / 630.0,
        -1983433.0 / 1935360.0,
    ],
    [
        0.0,
        0.0,
        61.0 / 240.0,
        -103.0 / 140.0,
        15061.0 / 26880.0,
        167603.0 / 181440.0,
    ],
    [
        0.0,
        0.0,
        0.0,
        49561.0 / 161280.0,
        -179.0 / 168.0,
        6601661.0 / 7257600.0,
    ],
    [
        0.0,
        0.0,
        0.0,
        0.0,
        34729.0 / 80640.0,
        -3418889.0 / 1995840.0,
    ],
    [0.0, 0.0, 0.0, 0.0, 0.0, 212378941.0 / 319334400.0],
];

/// Krüger's β coefficients: row j−1 holds the coefficients of n¹…n⁶ in βⱼ.
const BETA: [[f64; 6]; 6] = [
    [
        1.0 / 2.0,
        -2.0 / 3.0,
        37.0 / 96.0,
        -1.0 / 360.0,
        -81.0 / 512.0,
        96199.0 / 604800.0,
    ],
    [
        0.0,
        1.0 / 48.0,
        1.0 / 15.0,
        -437.0 / 1440.0,
        46.0 / 105.0,
        -1118711.0 / 3870720.0,
    ],
    [
        0.0,
        0.0,
        17.0 / 480.0,
        -37.0 / 840.0,
        -209.0 / 4480.0,
        5569.0 / 90720.0,
    ],
    [
        0.0,
        0.0,
        0.0,
        4397.0 / 161280.0,
        -11.0 / 504.0,
        -830251.0 / 7257600.0,
    ],
    [0.0, 0.0, 0.0, 0.0, 4583.0 / 161280.0, -108847.0 / 3991680.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 20648693.0 / 638668800.0],
];

/// Σₖ c[k] nᵏ⁺¹ by Horner's rule.
fn series_in_n(c: &[f64; 6], n: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| (acc + ck) * n)
}

/// `Σⱼ₌₁..₆ a[j−1] sin(2j ζ)` for complex `ζ = xi + i·eta`, by Clenshaw's
/// recurrence; returns (real, imaginary) parts.
fn clenshaw_sin2(a: &[f64; 6], xi: f64, eta: f64) -> (f64, f64) {
    let (s2x, c2x) = (2.0 * xi).sin_cos();
    let (sh2y, ch2y) = ((2.0 * eta).sinh(), (2.0 * eta).cosh());
    // 2 cos(2ζ) = 2 (cos 2ξ cosh 2η − i sin 2ξ sinh 2η)
    let (cr, ci) = (2.0 * c2x * ch2y, -2.0 * s2x * sh2y);
    // b_k = a_k + 2cos(2ζ) b_{k+1} − b_{k+2}
    let (mut b1r, mut b1i, mut b2r, mut b2i) = (0.0, 0.0, 0.0, 0.0);
    for &ak in a.iter().rev() {
        let b0r = ak + cr * b1r - ci * b1i - b2r;
        let b0i = cr * b1i + ci * b1r - b2i;
        (b2r, b2i, b1r, b1i) = (b1r, b1i, b0r, b0i);
    }
    // sum = b_1 sin(2ζ), sin(2ζ) = sin 2ξ cosh 2η + i cos 2ξ sinh 2η
    let (sr, si) = (s2x * ch2y, c2x * sh2y);
    (b1r * sr - b1i * si, b1r * si + b1i * sr)
}

/// Transverse Mercator by Krüger's series to n⁶ for one ellipsoid and scale;
/// no false origin, angles in radians, lengths in the unit of `a`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Krueger {
    /// First eccentricity e.
    e: f64,
    /// 1 − e².
    one_minus_e2: f64,
    /// k₀ A: scale times rectifying radius.
    k0_a: f64,
    /// α₁…α₆ (forward series).
    alpha: [f64; 6],
    /// β₁…β₆ (inverse series).
    beta: [f64; 6],
}

impl Krueger {
    /// Coefficients for semi-major axis `a`, flattening `f` and central
    /// scale `k0`.
    fn new(a: f64, f: f64, k0: f64) -> Self {
        let n = f / (2.0 - f);
        let e2 = f * (2.0 - f);
        let n2 = n * n;
        let a_rect = a / (1.0 + n) * (1.0 + n2 * (1.0 / 4.0 + n2 * (1.0 / 64.0 + n2 / 256.0)));
        Krueger {
            e: e2.sqrt(),
            one_minus_e2: 1.0 - e2,
            k0_a: k0 * a_rect,
            alpha: ALPHA.map(|c| series_in_n(&c, n)),
            beta: BETA.map(|c| series_in_n(&c, n)),
        }
    }

    /// τ′ (tangent of the conformal latitude) from τ (tangent of the
    /// geodetic latitude).
    fn taup(&self, tau: f64) -> f64 {
        let sig = (self.e * (self.e * tau / tau.hypot(1.0)).atanh()).sinh();
        tau * sig.hypot(1.0) - sig * tau.hypot(1.0)
    }

    /// τ from τ′ by Newton's method.
    fn tau_from_taup(&self, taup: f64) -> f64 {
        // Quadratic convergence: once a step is below √ε/10 the error left
        // is below ε², so the loop stops after that step.
        let tol = f64::EPSILON.sqrt() / 10.0;
        let mut tau = taup / self.one_minus_e2;
        for _ in 0..8 {
            let taup_i = self.taup(tau);
            let dtau = (taup - taup_i) / taup_i.hypot(1.0) * (1.0 + self.one_minus_e2 * tau * tau)
                / (self.one_minus_e2 * tau.hypot(1.0));
            tau += dtau;
            if dtau.is_nan() || dtau.abs() < tol * tau.abs().max(1.0) {
                break;
            }
        }
        tau
    }

    /// (x, y) of latitude `phi` and longitude from the central meridian
    /// `lam` (radians, |lam| < π/2).
    fn forward(&self, phi: f64, lam: f64) -> (f64, f64) {
        let taup = self.taup(phi.tan());
        let (sl, cl) = lam.sin_cos();
        let xip = taup.atan2(cl);
        let etap = (sl / taup.hypot(cl)).asinh();
        let (dxi, deta) = clenshaw_sin2(&self.alpha, xip, etap);
        (self.k0_a * (etap + deta), self.k0_a * (xip + dxi))
    }

    /// (latitude, longitude from the central meridian), radians, of (x, y).
    fn inverse(&self, x: f64, y: f64) -> (f64, f64) {
        let xi = y / self.k0_a;
        let eta = x / self.k0_a;
        let (dxi, deta) = clenshaw_sin2(&self.beta, xi, eta);
        let (xip, etap) = (xi - dxi, eta - deta);
        let (sxip, cxip) = xip.sin_cos();
        let shetap = etap.sinh();
        let taup = sxip / shetap.hypot(cxip);
        let lam = shetap.atan2(cxip);
        (self.tau_from_taup(taup).atan(), lam)
    }
}

/// `lon` reduced to [−180, 180) degrees when outside [−180, 180].
fn wrap_deg(lon: f64) -> f64 {
    if (-180.0..=180.0).contains(&lon) {
        lon
    } else {
        (lon + 180.0).rem_euclid(360.0) - 180.0
    }
}

/// A UTM zone: number 1–60 and hemisphere.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtmZone {
    /// Zone number, 1–60.
    pub number: u8,
    /// Northern hemisphere (false northing 0) or southern (10 000 km).
    pub north: bool,
}

impl UtmZone {
    /// The zone `number` (1–60) in the northern (`north`) or southern
    /// hemisphere; [`GridError::Projection`] for another number.
    pub fn new(number: u8, north: bool) -> Result<Self> {
        if (1..=60).contains(&number) {
            Ok(UtmZone { number, north })
        } else {
            Err(GridError::Projection(format!(
                "UTM zone number {number} is outside 1–60"
            )))
        }
    }

    /// The standard zone of a point (degrees): 6° zones from 180° W, with
    /// the exceptions of south-west Norway (32V spans 3°–12° E between 56°
    /// and 64° N) and Svalbard (31X, 33X, 35X, 37X between 72° and 84° N);
    /// northern hemisphere from latitude 0 up.
    ///
    /// Longitude is taken modulo 360° (180° E is in zone 1). A non-finite
    /// coordinate or a latitude outside [−80°, 84°] (the polar caps belong
    /// to UPS) is a [`GridError::Projection`].
    pub fn for_point(lat_deg: f64, lon_deg: f64) -> Result<Self> {
        if !lat_deg.is_finite() || !lon_deg.is_finite() {
            return Err(GridError::Projection(format!(
                "no UTM zone for a non-finite coordinate (latitude {lat_deg}, longitude {lon_deg})"
            )));
        }
        if !(ZONE_LAT_MIN_DEG..=ZONE_LAT_MAX_DEG).contains(&lat_deg) {
            return Err(GridError::Projection(format!(
                "latitude {lat_deg}° is outside the UTM zones ({ZONE_LAT_MIN_DEG}° to \
                 {ZONE_LAT_MAX_DEG}°); the polar caps are in UPS"
            )));
        }
        let mut lon = wrap_deg(lon_deg);
        if lon >= 180.0 {
            lon -= 360.0;
        }
        // lon in [−180, 180): the standard zone, 1–60.
        let mut number = (((lon + 180.0) / 6.0).floor() as i32 + 1).clamp(1, 60) as u8;
        if (56.0..64.0).contains(&lat_deg) && (3.0..12.0).contains(&lon) {
            number = 32;
        } else if lat_deg >= 72.0 && (0.0..42.0).contains(&lon) {
            number = if lon < 9.0 {
                31
            } else if lon < 21.0 {
                33
            } else if lon < 33.0 {
                35
            } else {
                37
            };
        }
        Ok(UtmZone {
            number,
            north: lat_deg >= 0.0,
        })
    }

    /// The zone of a data set (degrees): the zone, by [`UtmZone::for_point`]
    /// (exceptions included), of the median longitude of the points whose
    /// latitude and longitude are both finite, in the hemisphere of their
    /// median latitude.
    ///
    /// The median longitude is taken in [−180°, 180°) or, when that makes
    /// the points' spread smaller (a survey across the antimeridian), in
    /// [0°, 360°). A median latitude just beyond the zones but still within
    /// the reach of [`Utm::forward`] (−80.5° to 84.5°) picks the zone at
    /// the limit.
    ///
    /// Errors: [`GridError::LengthMismatch`] when `lon` is not as long as
    /// `lat`; [`GridError::Projection`] when no point is finite or the
    /// median latitude is beyond UTM.
    pub fn for_points(lat: &[f64], lon: &[f64]) -> Result<Self> {
        if lon.len() != lat.len() {
            return Err(GridError::LengthMismatch {
                what: "longitudes",
                got: lon.len(),
                expected: lat.len(),
            });
        }
        let (mut lats, mut lons): (Vec<f64>, Vec<f64>) = lat
            .iter()
            .zip(lon)
            .filter(|(la, lo)| la.is_finite() && lo.is_finite())
            .map(|(&la, &lo)| {
                let mut lo = wrap_deg(lo);
                if lo >= 180.0 {
                    lo -= 360.0;
                }
                (la, lo)
            })
            .unzip();
        if lats.is_empty() {
            return Err(GridError::Projection(
                "no point with finite latitude and longitude to choose the UTM zone from".into(),
            ));
        }
        let spread = |v: &[f64]| {
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                    (lo.min(x), hi.max(x))
                });
            hi - lo
        };
        let mut shifted: Vec<f64> = lons
            .iter()
            .map(|&x| if x < 0.0 { x + 360.0 } else { x })
            .collect();
        let lon_med = if spread(&shifted) < spread(&lons) {
            median(&mut shifted)
        } else {
            median(&mut lons)
        };
        let lat_med = median(&mut lats);
        let lat_zone = if (FORWARD_LAT_MIN_DEG..=FORWARD_LAT_MAX_DEG).contains(&lat_med) {
            lat_med.clamp(ZONE_LAT_MIN_DEG, ZONE_LAT_MAX_DEG)
        } else {
            lat_med
        };
        UtmZone::for_point(lat_zone, lon_med)
    }

    /// Reads a zone: `37N`, `37n`, `37S` (hemisphere letters, not MGRS
    /// latitude bands), `UTM zone 37N` (the [`Display`](fmt::Display)
    /// form), `EPSG:32637` or `32737` (WGS 84 / UTM codes 32601–32660 north,
    /// 32701–32760 south). Anything else is a [`GridError::Projection`].
    pub fn parse(s: &str) -> Result<Self> {
        let bad = |why: &str| {
            GridError::Projection(format!(
                "cannot read UTM zone '{s}': {why}; expected e.g. 37N, 37S, EPSG:32637 or 32737"
            ))
        };
        let t = s.trim().to_ascii_uppercase();
        let code = if let Some(rest) = t.strip_prefix("EPSG:") {
            Some(rest.trim())
        } else if t.len() == 5 && t.bytes().all(|b| b.is_ascii_digit()) {
            Some(t.as_str())
        } else {
            None
        };
        if let Some(code) = code {
            let code: u32 = code.parse().map_err(|_| bad("not an EPSG code"))?;
            let (north, number) = match code {
                32601..=32660 => (true, code - 32600),
                32701..=32760 => (false, code - 32700),
                _ => {
                    return Err(bad(
                        "not a WGS 84 / UTM EPSG code (32601–32660 north, 32701–32760 south)",
                    ));
                }
            };
            return UtmZone::new(number as u8, north);
        }
        let mut rest = t.as_str();
        if let Some(r) = rest.strip_prefix("UTM") {
            rest = r.trim_start();
            if let Some(r) = rest.strip_prefix("ZONE") {
                rest = r.trim_start();
            }
        }
        let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
        if digits == 0 || digits > 2 {
            return Err(bad("no zone number"));
        }
        let number: u8 = rest[..digits].parse().map_err(|_| bad("no zone number"))?;
        let north = match rest[digits..].trim() {
            "N" => true,
            "S" => false,
            "" => return Err(bad("no hemisphere (N or S)")),
            _ => return Err(bad("the hemisphere must be N or S")),
        };
        if !(1..=60).contains(&number) {
            return Err(bad("the zone number must be 1–60"));
        }
        UtmZone::new(number, north)
    }

    /// Longitude of the zone's central meridian, degrees: `6 · number − 183`.
    pub fn central_meridian_deg(&self) -> f64 {
        6.0 * f64::from(self.number) - 183.0
    }

    /// EPSG code of WGS 84 / UTM in this zone: 326zz north, 327zz south.
    pub fn epsg(&self) -> u16 {
        (if self.north { 32600 } else { 32700 }) + self.number as u16
    }

    /// The OGC WKT 1 of "WGS 84 / UTM zone NN[N|S]" with its EPSG
    /// authority, as GDAL writes it (for a `.prj` file or GeoTIFF/netCDF
    /// metadata).
    pub fn wkt(&self) -> String {
        format!(
            "PROJCS[\"WGS 84 / {self}\",\
             GEOGCS[\"WGS 84\",\
             DATUM[\"WGS_1984\",\
             SPHEROID[\"WGS 84\",6378137,298.257223563,AUTHORITY[\"EPSG\",\"7030\"]],\
             AUTHORITY[\"EPSG\",\"6326\"]],\
             PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],\
             UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],\
             AUTHORITY[\"EPSG\",\"4326\"]],\
             PROJECTION[\"Transverse_Mercator\"],\
             PARAMETER[\"latitude_of_origin\",0],\
             PARAMETER[\"central_meridian\",{cm}],\
             PARAMETER[\"scale_factor\",0.9996],\
             PARAMETER[\"false_easting\",500000],\
             PARAMETER[\"false_northing\",{fn_m}],\
             UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],\
             AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH],\
             AUTHORITY[\"EPSG\",\"{epsg}\"]]",
            cm = 6 * i32::from(self.number) - 183,
            fn_m = if self.north { 0 } else { 10_000_000 },
            epsg = self.epsg(),
        )
    }
}

impl fmt::Display for UtmZone {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "UTM zone {}{}",
            self.number,
            if self.north { 'N' } else { 'S' }
        )
    }
}

impl FromStr for UtmZone {
    type Err = GridError;

    /// As [`UtmZone::parse`].
    fn from_str(s: &str) -> Result<Self> {
        UtmZone::parse(s)
    }
}

/// The transverse Mercator projection of one UTM zone (WGS 84, k₀ = 0.9996,
/// false easting 500 000 m, false northing 10 000 000 m in the south).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Utm {
    /// The zone.
    pub zone: UtmZone,
    /// Series coefficients of WGS 84 with k₀ = 0.9996.
    tm: Krueger,
}

impl Utm {
    /// The projection of `zone`.
    pub fn new(zone: UtmZone) -> Self {
        Utm {
            zone,
            tm: Krueger::new(WGS84_A_M, 1.0 / WGS84_INV_F, UTM_K0),
        }
    }

    /// Forward projection with the reason for a refusal as a message.
    fn forward_msg(&self, lat_deg: f64, lon_deg: f64) -> std::result::Result<(f64, f64), String> {
        if !lat_deg.is_finite() || !lon_deg.is_finite() {
            return Err(format!(
                "non-finite coordinate (latitude {lat_deg}, longitude {lon_deg})"
            ));
        }
        if !(FORWARD_LAT_MIN_DEG..=FORWARD_LAT_MAX_DEG).contains(&lat_deg) {
            return Err(format!(
                "latitude {lat_deg}° is outside UTM ({FORWARD_LAT_MIN_DEG}° to {FORWARD_LAT_MAX_DEG}°)"
            ));
        }
        let cm = self.zone.central_meridian_deg();
        let dlon = wrap_deg(lon_deg - cm);
        if dlon.abs() > FORWARD_MAX_DLON_DEG {
            return Err(format!(
                "longitude {lon_deg}° is {:.1}° from the central meridian {cm}° of {} \
                 (at most {FORWARD_MAX_DLON_DEG}°)",
                dlon.abs(),
                self.zone
            ));
        }
        let (x, y) = self.tm.forward(lat_deg.to_radians(), dlon.to_radians());
        let false_northing = if self.zone.north {
            0.0
        } else {
            FALSE_NORTHING_SOUTH_M
        };
        Ok((x + FALSE_EASTING_M, y + false_northing))
    }

    /// (easting, northing) in metres of a point given in degrees.
    ///
    /// [`GridError::Projection`] for a non-finite coordinate, a latitude
    /// outside [−80.5°, 84.5°] or a longitude more than 30° from the
    /// zone's central meridian (longitudes are taken modulo 360°).
    pub fn forward(&self, lat_deg: f64, lon_deg: f64) -> Result<(f64, f64)> {
        self.forward_msg(lat_deg, lon_deg)
            .map_err(GridError::Projection)
    }

    /// (latitude, longitude) in degrees of a point given as easting and
    /// northing in metres; longitude in [−180°, 180°]. Not checked: a
    /// non-finite input gives NaN, and points far outside the zone (more
    /// than ~30° of longitude away) lose accuracy.
    pub fn inverse(&self, easting_m: f64, northing_m: f64) -> (f64, f64) {
        let false_northing = if self.zone.north {
            0.0
        } else {
            FALSE_NORTHING_SOUTH_M
        };
        let (phi, lam) = self
            .tm
            .inverse(easting_m - FALSE_EASTING_M, northing_m - false_northing);
        let lon = wrap_deg(self.zone.central_meridian_deg() + lam.to_degrees());
        (phi.to_degrees(), lon)
    }

    /// Eastings and northings (metres) of series of latitudes and
    /// longitudes (degrees).
    ///
    /// [`GridError::LengthMismatch`] when `lon` is not as long as `lat`;
    /// [`GridError::Projection`] naming the first row [`Utm::forward`]
    /// refuses, counted from 1 ("data row 3: …" for `lat[2]`).
    pub fn forward_all(&self, lat: &[f64], lon: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
        if lon.len() != lat.len() {
            return Err(GridError::LengthMismatch {
                what: "longitudes",
                got: lon.len(),
                expected: lat.len(),
            });
        }
        let mut east = Vec::with_capacity(lat.len());
        let mut north = Vec::with_capacity(lat.len());
        for (k, (&la, &lo)) in lat.iter().zip(lon).enumerate() {
            let (e, n) = self
                .forward_msg(la, lo)
                .map_err(|msg| GridError::Projection(format!("data row {}: {msg}", k + 1)))?;
            east.push(e);
            north.push(n);
        }
        Ok((east, north))
    }
}

impl From<UtmZone> for Utm {
    fn from(zone: UtmZone) -> Self {
        Utm::new(zone)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// (latitude °, longitude °, zone number, north, easting m, northing m,
    /// whether the zone is the point's own by `for_point`).
    ///
    /// Easting and northing from pyproj 3.7.2 (PROJ 9.5.1):
    /// `Transformer.from_crs("EPSG:4326", f"EPSG:{326zz|327zz}",
    /// always_xy=True).transform(lon, lat)`.
    const PYPROJ: [(f64, f64, u8, bool, f64, f64, bool); 13] = [
        (
            56.3,
            37.6,
            37,
            true,
            413365.9477917116,
            6240350.23127215,
            true,
        ),
        (
            45.5,
            -75.6,
            18,
            true,
            453123.93328609027,
            5038671.569604237,
            true,
        ),
        (
            -33.9,
            151.2,
            56,
            false,
            333568.9410115521,
            6247473.33684402,
            true,
        ),
        (0.0, 3.0, 31, true, 500000.000000001, 0.0, true),
        (
            80.0,
            10.0,
            33,
            true,
            403186.945226034,
            8885748.707734114,
            true,
        ),
        (
            60.5,
            4.5,
            32,
            true,
            252928.5321297559,
            6715548.233706285,
            true,
        ),
        // 3° west of the central meridian (39° E) of zone 37.
        (
            30.0,
            36.0,
            37,
            true,
            210590.34676353616,
            3322575.9043847634,
            true,
        ),
        (
            -79.0,
            -60.0,
            21,
            false,
            436123.8375445357,
            1228384.0340933576,
            true,
        ),
        (
            84.0,
            5.0,
            31,
            true,
            523335.5645031648,
            9328498.923890686,
            true,
        ),
        (
            -0.5,
            -179.9,
            1,
            false,
            177176.0374467527,
            9944663.62243432,
            true,
        ),
        // Zones beyond: 18°, 29° and 11° from the central meridian.
        (
            50.0,
            57.0,
            37,
            true,
            1786007.5154996607,
            5695743.458431489,
            false,
        ),
        (
            10.0,
            68.0,
            37,
            true,
            3814534.291951295,
            1261241.8876964832,
            false,
        ),
        (
            -45.0,
            -100.0,
            12,
            false,
            1366947.1593664377,
            4957837.626870549,
            false,
        ),
    ];

    fn zone(number: u8, north: bool) -> UtmZone {
        UtmZone::new(number, north).unwrap()
    }

    #[test]
    fn forward_matches_pyproj() {
        let mut max_diff_m = 0.0_f64;
        for &(lat, lon, number, north, e_ref, n_ref, own) in &PYPROJ {
            let z = zone(number, north);
            if own {
                assert_eq!(
                    UtmZone::for_point(lat, lon).unwrap(),
                    z,
                    "zone of {lat}, {lon}"
                );
            }
            let (e, n) = Utm::new(z).forward(lat, lon).unwrap();
            let d = (e - e_ref).abs().max((n - n_ref).abs());
            assert!(
                d < 1e-3,
                "{lat}, {lon} in {z}: ({e}, {n}) vs ({e_ref}, {n_ref})"
            );
            max_diff_m = max_diff_m.max(d);
        }
        // Measured: 2.3e-9 m (pyproj prints to ~1e-9 m).
        assert!(max_diff_m < 1e-6, "max difference {max_diff_m} m");
    }

    #[test]
    fn inverse_matches_pyproj() {
        for &(lat, lon, number, north, e_ref, n_ref, _) in &PYPROJ {
            let (la, lo) = Utm::new(zone(number, north)).inverse(e_ref, n_ref);
            assert!((la - lat).abs() < 1e-9, "{lat}, {lon}: latitude {la}");
            assert!((lo - lon).abs() < 1e-9, "{lat}, {lon}: longitude {lo}");
        }
    }

    #[test]
    fn central_meridian_and_equator() {
        let utm = Utm::new(zone(37, true));
        let (e, n) = utm.forward(0.0, 39.0).unwrap();
        assert!((e - 500_000.0).abs() < 1e-9 && n.abs() < 1e-9);
        // Easting is odd about the central meridian.
        let (e1, n1) = utm.forward(47.3, 39.0 + 2.7).unwrap();
        let (e2, n2) = utm.forward(47.3, 39.0 - 2.7).unwrap();
        assert!((e1 - 500_000.0 + (e2 - 500_000.0)).abs() < 1e-8);
        assert!((n1 - n2).abs() < 1e-8);
        // The southern false northing.
        let (_, ns) = Utm::new(zone(37, false)).forward(-1e-9, 39.0).unwrap();
        assert!((ns - 10_000_000.0).abs() < 1e-3);
        // A longitude given modulo 360° projects the same.
        let utm1 = Utm::new(zone(1, true));
        let a = utm1.forward(10.0, 179.5).unwrap();
        let b = utm1.forward(10.0, -180.5).unwrap();
        assert!((a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6);
    }

    /// Meridian arc length on an ellipsoid of semi-major axis 1 by Simpson's
    /// rule.
    fn meridian_arc(e2: f64, phi: f64) -> f64 {
        let n = 4000;
        let h = phi / n as f64;
        let g = |p: f64| (1.0 - e2) / (1.0 - e2 * p.sin().powi(2)).powf(1.5);
        let mut s = g(0.0) + g(phi);
        for i in 1..n {
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * g(i as f64 * h);
        }
        s * h / 3.0
    }

    /// On the central meridian y is the meridian arc, so an ellipsoid much
    /// flatter than WGS 84 (n = 0.02, against 0.00168) checks A and the α
    /// and β series to their n⁶ terms against quadrature. The truncation
    /// error, O(n⁷), measures 8.9e-12 (y) and 6.5e-13 rad (φ); a 20 % error
    /// in α₆ or β₆, or 10 % in the n⁶ term of α₂, fails.
    #[test]
    fn series_match_meridian_arc_of_flat_ellipsoid() {
        let n = 0.02;
        let f = 2.0 * n / (1.0 + n);
        let e2 = f * (2.0 - f);
        let tm = Krueger::new(1.0, f, 1.0);
        for deg in 1..90 {
            let phi = f64::from(deg).to_radians();
            let arc = meridian_arc(e2, phi);
            let (x, y) = tm.forward(phi, 0.0);
            assert!(x.abs() < 1e-15, "{deg}°: x = {x}");
            assert!((y - arc).abs() < 1.2e-11, "{deg}°: y − arc = {}", y - arc);
            let (p, l) = tm.inverse(0.0, arc);
            assert!(l.abs() < 1e-15, "{deg}°: λ = {l}");
            assert!((p - phi).abs() < 8.5e-13, "{deg}°: φ error {}", p - phi);
        }
    }

    #[test]
    fn zone_for_point_standard() {
        assert_eq!(UtmZone::for_point(56.3, 37.6).unwrap(), zone(37, true));
        assert_eq!(UtmZone::for_point(-33.9, 151.2).unwrap(), zone(56, false));
        assert_eq!(UtmZone::for_point(0.0, 0.0).unwrap(), zone(31, true));
        assert_eq!(
            UtmZone::for_point(-0.0001, -0.0001).unwrap(),
            zone(30, false)
        );
        assert_eq!(UtmZone::for_point(10.0, -180.0).unwrap(), zone(1, true));
        assert_eq!(UtmZone::for_point(10.0, 180.0).unwrap(), zone(1, true));
        assert_eq!(UtmZone::for_point(10.0, 179.99).unwrap(), zone(60, true));
        assert_eq!(UtmZone::for_point(10.0, 362.0).unwrap(), zone(31, true));
        assert_eq!(UtmZone::for_point(-80.0, -60.0).unwrap(), zone(21, false));
        // Just outside the exceptions.
        assert_eq!(UtmZone::for_point(64.0, 4.5).unwrap(), zone(31, true));
        assert_eq!(UtmZone::for_point(55.99, 4.5).unwrap(), zone(31, true));
        assert_eq!(UtmZone::for_point(60.0, 2.99).unwrap(), zone(31, true));
        assert_eq!(UtmZone::for_point(71.99, 10.0).unwrap(), zone(32, true));
        assert_eq!(UtmZone::for_point(80.0, 42.0).unwrap(), zone(38, true));
        assert_eq!(UtmZone::for_point(80.0, -0.01).unwrap(), zone(30, true));
    }

    #[test]
    fn zone_for_point_norway_and_svalbard() {
        // 32V covers 3°–12° E between 56° and 64° N.
        assert_eq!(UtmZone::for_point(60.5, 4.5).unwrap(), zone(32, true));
        assert_eq!(UtmZone::for_point(56.0, 3.0).unwrap(), zone(32, true));
        assert_eq!(UtmZone::for_point(63.99, 11.99).unwrap(), zone(32, true));
        // Svalbard, 72°–84° N.
        for (lon, number) in [
            (0.0, 31),
            (8.99, 31),
            (9.0, 33),
            (20.99, 33),
            (21.0, 35),
            (32.99, 35),
            (33.0, 37),
            (41.99, 37),
        ] {
            assert_eq!(
                UtmZone::for_point(78.0, lon).unwrap(),
                zone(number, true),
                "{lon}"
            );
        }
        assert_eq!(UtmZone::for_point(72.0, 10.0).unwrap(), zone(33, true));
        assert_eq!(UtmZone::for_point(84.0, 10.0).unwrap(), zone(33, true));
        assert_eq!(UtmZone::for_point(80.0, 10.0).unwrap(), zone(33, true));
    }

    #[test]
    fn zone_for_point_rejects_bad_input() {
        for (lat, lon) in [
            (84.01, 10.0),
            (-80.01, 10.0),
            (f64::NAN, 10.0),
            (10.0, f64::NAN),
            (10.0, f64::INFINITY),
        ] {
            let err = UtmZone::for_point(lat, lon).unwrap_err();
            assert!(
                matches!(err, GridError::Projection(_)),
                "{lat}, {lon}: {err}"
            );
        }
    }

    #[test]
    fn zone_for_points_uses_medians() {
        // Mostly in zone 37 north; an outlier in zone 36 and one south, NaN rows.
        let lat = [56.0, 56.1, f64::NAN, 56.2, -1.0, 56.3];
        let lon = [37.0, 37.5, 20.0, 38.0, 34.0, f64::NAN];
        assert_eq!(UtmZone::for_points(&lat, &lon).unwrap(), zone(37, true));
        // Median latitude south.
        let lat = [-1.0, -2.0, 3.0];
        let lon = [-75.6, -75.5, -75.4];
        assert_eq!(UtmZone::for_points(&lat, &lon).unwrap(), zone(18, false));
        // The Norway exception applies to the median point.
        let lat = [60.0, 60.5, 61.0];
        let lon = [4.0, 4.5, 5.0];
        assert_eq!(UtmZone::for_points(&lat, &lon).unwrap(), zone(32, true));
        // Across the antimeridian: median 179.9° E → zone 60, not zone 30.
        let lat = [-17.0, -17.1, -17.2, -17.3];
        let lon = [179.7, 179.8, -180.0, -179.9];
        assert_eq!(UtmZone::for_points(&lat, &lon).unwrap(), zone(60, false));
        // Just north of 84° but within reach of the forward projection.
        let lat = [84.2, 84.3];
        let lon = [10.0, 10.0];
        assert_eq!(UtmZone::for_points(&lat, &lon).unwrap(), zone(33, true));
    }

    #[test]
    fn zone_for_points_errors() {
        assert!(matches!(
            UtmZone::for_points(&[1.0, 2.0], &[3.0]),
            Err(GridError::LengthMismatch {
                got: 1,
                expected: 2,
                ..
            })
        ));
        assert!(matches!(
            UtmZone::for_points(&[f64::NAN, 2.0], &[3.0, f64::NAN]),
            Err(GridError::Projection(_))
        ));
        assert!(matches!(
            UtmZone::for_points(&[], &[]),
            Err(GridError::Projection(_))
        ));
        assert!(matches!(
            UtmZone::for_points(&[88.0, 89.0], &[3.0, 4.0]),
            Err(GridError::Projection(_))
        ));
    }

    #[test]
    fn zone_new_and_codes() {
        assert!(matches!(
            UtmZone::new(0, true),
            Err(GridError::Projection(_))
        ));
        assert!(matches!(
            UtmZone::new(61, true),
            Err(GridError::Projection(_))
        ));
        let z = zone(37, true);
        assert_eq!(z.epsg(), 32637);
        assert_eq!(zone(56, false).epsg(), 32756);
        assert_eq!(z.to_string(), "UTM zone 37N");
        assert_eq!(z.central_meridian_deg(), 39.0);
        assert_eq!(zone(1, true).central_meridian_deg(), -177.0);
        assert_eq!(zone(60, true).central_meridian_deg(), 177.0);
    }

    #[test]
    fn parse_accepts_zone_names_and_epsg_codes() {
        for (s, number, north) in [
            ("37N", 37, true),
            ("37n", 37, true),
            ("37S", 37, false),
            ("37s", 37, false),
            (" 7N ", 7, true),
            ("07S", 7, false),
            ("37 N", 37, true),
            ("EPSG:32637", 37, true),
            ("epsg:32601", 1, true),
            ("EPSG: 32760", 60, false),
            ("32737", 37, false),
            ("UTM zone 37N", 37, true),
            ("utm 18s", 18, false),
        ] {
            assert_eq!(UtmZone::parse(s).unwrap(), zone(number, north), "'{s}'");
        }
        for z in [zone(1, true), zone(37, false), zone(60, true)] {
            assert_eq!(UtmZone::parse(&z.to_string()).unwrap(), z);
            assert_eq!(UtmZone::parse(&z.epsg().to_string()).unwrap(), z);
            assert_eq!(z.to_string().parse::<UtmZone>().unwrap(), z);
        }
    }

    #[test]
    fn parse_rejects_garbage() {
        for s in [
            "",
            "37",
            "37X",
            "61N",
            "0N",
            "N",
            "137N",
            "EPSG:4326",
            "EPSG:32661",
            "32600",
            "32761",
            "EPSG:",
            "EPSG:abc",
            "zone 37N",
            "37NN",
            "3 7N",
            "-37N",
        ] {
            match UtmZone::parse(s) {
                Err(GridError::Projection(msg)) => {
                    assert!(msg.contains("37N"), "message for '{s}': {msg}")
                }
                other => panic!("'{s}' gave {other:?}"),
            }
        }
    }

    #[test]
    fn forward_rejects_bad_input() {
        let utm = Utm::new(zone(37, true));
        for (lat, lon) in [
            (f64::NAN, 39.0),
            (10.0, f64::NAN),
            (f64::INFINITY, 39.0),
            (84.51, 39.0),
            (-80.51, 39.0),
            (10.0, 69.01),
            (10.0, 8.99),
            (10.0, -141.0),
        ] {
            assert!(
                matches!(utm.forward(lat, lon), Err(GridError::Projection(_))),
                "{lat}, {lon}"
            );
        }
        // The limits themselves are accepted.
        assert!(utm.forward(84.5, 69.0).is_ok());
        assert!(utm.forward(-80.5, 9.0).is_ok());
    }

    #[test]
    fn forward_all_names_the_first_bad_row() {
        let utm = Utm::new(zone(37, true));
        let lat = [56.3, 56.4, f64::NAN, 95.0];
        let lon = [37.6, 37.7, 37.8, 37.9];
        match utm.forward_all(&lat, &lon) {
            Err(GridError::Projection(msg)) => {
                assert!(msg.starts_with("data row 3:"), "{msg}")
            }
            other => panic!("{other:?}"),
        }
        let (e, n) = utm.forward_all(&lat[..2], &lon[..2]).unwrap();
        assert_eq!(e.len(), 2);
        let (e0, n0) = utm.forward(56.3, 37.6).unwrap();
        assert_eq!((e[0], n[0]), (e0, n0));
        assert!(matches!(
            utm.forward_all(&lat, &lon[..3]),
            Err(GridError::LengthMismatch {
                got: 3,
                expected: 4,
                ..
            })
        ));
        let (e, n) = utm.forward_all(&[], &[]).unwrap();
        assert!(e.is_empty() && n.is_empty());
    }

    #[test]
    fn wkt_is_gdal_wkt1() {
        // pyproj 3.7.2: CRS.from_epsg(32637).to_wkt("WKT1_GDAL").
        let expected = "PROJCS[\"WGS 84 / UTM zone 37N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",\
            SPHEROID[\"WGS 84\",6378137,298.257223563,AUTHORITY[\"EPSG\",\"7030\"]],\
            AUTHORITY[\"EPSG\",\"6326\"]],PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],\
            UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],\
            AUTHORITY[\"EPSG\",\"4326\"]],PROJECTION[\"Transverse_Mercator\"],\
            PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",39],\
            PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],\
            PARAMETER[\"false_northing\",0],UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],\
            AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH],AUTHORITY[\"EPSG\",\"32637\"]]";
        assert_eq!(zone(37, true).wkt(), expected);
        let south = zone(18, false).wkt();
        assert!(south.starts_with("PROJCS[\"WGS 84 / UTM zone 18S\""));
        assert!(south.contains("PARAMETER[\"central_meridian\",-75]"));
        assert!(south.contains("PARAMETER[\"false_northing\",10000000]"));
        assert!(south.ends_with("AUTHORITY[\"EPSG\",\"32718\"]]"));
    }

    proptest! {
        #[test]
        fn inverse_undoes_forward(
            number in 1u8..=60,
            lat in -80.0f64..84.0,
            dlon in -3.5f64..3.5,
        ) {
            for north in [true, false] {
                let z = zone(number, north);
                let utm = Utm::new(z);
                let lon = wrap_deg(z.central_meridian_deg() + dlon);
                let (e, n) = utm.forward(lat, lon).unwrap();
                let (la, lo) = utm.inverse(e, n);
                prop_assert!((la - lat).abs() < 1e-9, "latitude {} → {}", lat, la);
                let dlo = wrap_deg(lo - lon).abs();
                prop_assert!(dlo < 1e-9, "longitude {} → {}", lon, lo);
            }
        }
    }
}

//! Magnetic fields: point dipoles and the IGRF-14 main field.

pub mod dipole;
pub mod igrf;

/// The largest magnetic reading taken as one, nT (1 mT): Earth's field is
/// below 70 000 nT and an aircraft's at its sensors a few thousand; a value
/// beyond is a corrupted cell or a numeric dummy (−1e32), which would
/// otherwise run through every computation (a flux component of 1e300 gave
/// its neighbours an interference of 10²⁹⁵ nT, flagged compensated; one
/// mag of 1e308 turned an adaptive compensator's coefficients into NaN).
pub const MAX_FIELD_NT: f64 = 1e6;

/// The smallest total-field reading taken as one, nT: Earth's field is
/// above 22 000 nT everywhere (15 000 nT with room for the strongest
/// anomalies at survey heights), and survey magnetometers read from 10 000
/// or 15 000 nT up; a `mag` below, or a vector magnetometer's magnitude
/// below, is a dropout value (0, −1, −99999), a negated reading or another
/// unit (tesla, gauss, µT). A `mag` of 0 was compensated to 20.5 nT and
/// flagged compensated, in files and on `aeromag stream`.
pub const MIN_READING_NT: f64 = 1_000.0;

/// The largest height taken as one, m (1000 km, twice a magnetic satellite's
/// orbit): a value beyond is a corrupted cell or a numeric dummy, whose
/// height difference at a crossover made levelling's normal matrix
/// overflow (a singular system blamed on the fit).
pub const MAX_ALT_M: f64 = 1e6;

/// The largest |longitude| taken, degrees (east or west of Greenwich, or
/// 0–360): 1e308 was taken by `aeromag igrf` and printed with 309 digits,
/// and by Python's `igrf` (any finite value), its sine and cosine
/// meaningless.
pub const MAX_LON_DEG: f64 = 360.0;

/// The largest ground speed taken as one, m/s: an airliner cruises at
/// 250 m/s and a fast jet at 700; beyond, the value is a corrupted cell or
/// the time is not in seconds (one speed of 1e308 turned an adaptive
/// compensator's coefficients into NaN).
pub const MAX_GROUND_SPEED_M_S: f64 = 1000.0;

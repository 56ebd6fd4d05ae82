//! Calibration stage 1: reduction to a linearly polarised field of three
//! point sources (seed `001_…` part II, eq. 6; spec `em-positioning.md`,
//! "Calibration in three stages" item 1). No external information is needed.
//!
//! After pilot correction, the complex vector detected at frequency `ω_i`
//! should be real up to a constant detection phase. Its imaginary part comes
//! from the complex transmitter distortion (eddy currents: `Im k_ij H_j`,
//! eq. 5) and the imaginary part of the receiver cross-coupling
//! (`Im χ(ω_i) H_i`, eq. 3). Both are linear in the true fields, which are
//! approximated by the major axes `x_j = H_Aj` ([`crate::detection::major_axis`]):
//!
//! ```text
//! h_i ← e^{−iφ_i} h_i                       φ_i: mean major-axis phase over epochs
//! Im h_i ≈ P_i x_i + Σ_{j≠i} b_ij x_j + β_i x_i
//!        P_i real, zero diagonal; b_ij real; β_i residual phase (9 unknowns / frequency)
//! ```
//!
//! fitted by least squares over many epochs at different positions and
//! attitudes, iterating `φ_i ← φ_i + β_i` until `β_i → 0`. The correction is `h_i ← h_i − i (P_i x_i + Σ_{j≠i} b_ij x_j)`,
//! after which the field vector is the major axis of the corrected `h_i`
//! (its polarisation ratio is the quality figure). The real parts of the
//! coefficients are not observable without external information: the
//! symmetric transmitter part is stage 2 ([`super::transmitter_geometry`]),
//! the rotation part stage 3 ([`super::attitude`]).

use crate::detection::{Complex64, major_axis};
use crate::{EmError, Result};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Stage-1 coefficients for the three frequencies.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PolarisationCalibration {
    /// Mean detection phase `φ_i` per frequency, rad.
    pub phase_rad: [f64; 3],
    /// Receiver-side imaginary coupling `P_i` per frequency (dimensionless).
    pub p: [Matrix3<f64>; 3],
    /// Transmitter-side imaginary mixing `b_ij` (diagonal unused, 0).
    pub b: Matrix3<f64>,
}

impl Default for PolarisationCalibration {
    fn default() -> Self {
        Self {
            phase_rad: [0.0; 3],
            p: [Matrix3::zeros(); 3],
            b: Matrix3::zeros(),
        }
    }
}

fn rotate(h: &[Complex64; 3], phase: f64) -> [Complex64; 3] {
    let r = Complex64::from_polar(1.0, -phase);
    [h[0] * r, h[1] * r, h[2] * r]
}

fn im(h: &[Complex64; 3]) -> Vector3<f64> {
    Vector3::new(h[0].im, h[1].im, h[2].im)
}

/// Off-diagonal positions of `P_i` (the diagonal of `χ` is 1, eq. 3).
const OFF: [(usize, usize); 6] = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)];

/// Design row block (3×9) of the model `P x_i + b₁ x_j + b₂ x_k + β x_i`.
fn design(xs: &[Vector3<f64>; 3], i: usize) -> SMatrix<f64, 3, 9> {
    let mut a = SMatrix::<f64, 3, 9>::zeros();
    for (n, &(row, col)) in OFF.iter().enumerate() {
        a[(row, n)] = xs[i][col];
    }
    let others = others(i);
    for row in 0..3 {
        a[(row, 6)] = xs[others[0]][row];
        a[(row, 7)] = xs[others[1]][row];
        a[(row, 8)] = xs[i][row];
    }
    a
}

fn others(i: usize) -> [usize; 2] {
    [(i + 1) % 3, (i + 2) % 3]
}

impl PolarisationCalibration {
    /// Fit stage 1 from epochs of three complex vectors `epochs[e][i]` (one
    /// per frequency `i`, receiver axes, pilot-corrected).
    ///
    /// The imaginary receiver coupling `P_i` has a zero diagonal (`χ` has a
    /// unit diagonal, eq. 3); the diagonal term `β_i x_i` is a residual
    /// detection phase, folded into `φ_i` and the fit repeated until it
    /// vanishes, so that the real part is not rotated into the imaginary
    /// coupling.
    ///
    /// Errors (all bad input): fewer than 8 epochs, non-finite data, or a
    /// rank-deficient system (too little variety of positions and
    /// attitudes).
    pub fn fit(epochs: &[[[Complex64; 3]; 3]]) -> Result<Self> {
        if epochs.len() < 8 {
            return Err(EmError::InvalidArgument {
                reason: format!("{} epochs, need ≥ 8", epochs.len()),
            });
        }
        if epochs
            .iter()
            .flatten()
            .flatten()
            .any(|c| !c.re.is_finite() || !c.im.is_finite())
        {
            return Err(EmError::InvalidData {
                reason: "non-finite detected values".into(),
            });
        }
        // Starting phase: average of e^{2iφ*} (the major axis has a ±π ambiguity).
        let mut phase_rad = [0.0; 3];
        for (i, ph) in phase_rad.iter_mut().enumerate() {
            let s: Complex64 = epochs
                .iter()
                .map(|e| {
                    let el = major_axis(&e[i]);
                    Complex64::from_polar(el.major.norm_squared(), -2.0 * el.phase_rad)
                })
                .sum();
            *ph = 0.5 * s.arg();
        }
        let mut cal = Self {
            phase_rad,
            ..Self::default()
        };
        for _ in 0..8 {
            let mut max_beta = 0.0f64;
            let mut next = cal;
            for i in 0..3 {
                let mut ata = SMatrix::<f64, 9, 9>::zeros();
                let mut aty = SVector::<f64, 9>::zeros();
                for e in epochs {
                    let hs = [0, 1, 2].map(|j| rotate(&e[j], cal.phase_rad[j]));
                    let xs = hs.map(|h| major_axis(&h).major);
                    // Weight each epoch by 1/|x_i|² so near and far epochs count alike.
                    let w = 1.0 / xs[i].norm_squared().max(f64::MIN_POSITIVE);
                    let a = design(&xs, i);
                    ata += a.transpose() * a * w;
                    aty += a.transpose() * im(&hs[i]) * w;
                }
                let sol = ata
                    .cholesky()
                    // Bad input, not a failed fit: the data cannot
                    // determine stage 1 (every epoch carrying the same
                    // field gave "singular matrix", exit 1).
                    .ok_or_else(|| EmError::InvalidData {
                        reason: format!(
                            "the detected epochs do not determine calibration stage 1 (singular normal equations at frequency {i}): its fields do not vary, and stage 1 needs epochs at varied attitudes (a record of one repeated epoch, or one swamped by interference)"
                        ),
                    })?
                    .solve(&aty);
                let mut p = Matrix3::zeros();
                for (n, &(row, col)) in OFF.iter().enumerate() {
                    p[(row, col)] = sol[n];
                }
                next.p[i] = p;
                let [j, k] = others(i);
                next.b[(i, j)] = sol[6];
                next.b[(i, k)] = sol[7];
                // Im ≈ β Re for a phase error β: rotate further by β.
                next.phase_rad[i] = cal.phase_rad[i] + sol[8];
                max_beta = max_beta.max(sol[8].abs());
            }
            cal = next;
            if max_beta < 1e-10 {
                break;
            }
        }
        Ok(cal)
    }

    /// Apply stage 1 to one epoch: returns the real field matrix (columns =
    /// corrected major axes, receiver axes) and the three polarisation ratios
    /// after correction.
    pub fn apply(&self, epoch: &[[Complex64; 3]; 3]) -> (Matrix3<f64>, [f64; 3]) {
        let hs = [
            rotate(&epoch[0], self.phase_rad[0]),
            rotate(&epoch[1], self.phase_rad[1]),
            rotate(&epoch[2], self.phase_rad[2]),
        ];
        let xs = [
            major_axis(&hs[0]).major,
            major_axis(&hs[1]).major,
            major_axis(&hs[2]).major,
        ];
        let mut h = Matrix3::zeros();
        let mut ratios = [0.0; 3];
        for i in 0..3 {
            let mut corr = self.p[i] * xs[i];
            for j in (0..3).filter(|&j| j != i) {
                corr += xs[j] * self.b[(i, j)];
            }
            let c = [
                hs[i][0] - Complex64::new(0.0, corr[0]),
                hs[i][1] - Complex64::new(0.0, corr[1]),
                hs[i][2] - Complex64::new(0.0, corr[2]),
            ];
            let el = major_axis(&c);
            h.set_column(i, &el.major);
            ratios[i] = el.ratio;
        }
        (h, ratios)
    }
}

/// Real field matrix and polarisation ratios of an uncalibrated epoch
/// (major axes after only the mean-phase rotation of `cal`).
pub fn uncalibrated(epoch: &[[Complex64; 3]; 3], phase_rad: &[f64; 3]) -> (Matrix3<f64>, [f64; 3]) {
    let mut h = Matrix3::zeros();
    let mut ratios = [0.0; 3];
    for i in 0..3 {
        let el = major_axis(&rotate(&epoch[i], phase_rad[i]));
        h.set_column(i, &el.major);
        ratios[i] = el.ratio;
    }
    (h, ratios)
}

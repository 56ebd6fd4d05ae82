//! Calibration stage 2: transmitter geometry from known ranges and
//! directions (seed `001_…` part II; spec `em-positioning.md`, "Calibration
//! in three stages" item 2).
//!
//! The real transmitter distortion (eq. 5, after stage 1) makes the
//! effective moments `M' = (I + S) M` with `S` symmetric (6 coefficients
//! `k^II_ij`, `i ≤ j`; the antisymmetric part only turns the transmitter
//! frame, which the moments themselves define). With the receiver position
//! `r` known (not its attitude) the rotation-invariant whitened Gram matrix
//! ([`crate::positioning::whitened_gram`]) must satisfy
//!
//! ```text
//! W = M⁻ᵀ HᵀH M⁻¹ = (I + S) Ω(r)² (I + S)
//! ```
//!
//! Gauss–Newton on the six upper-triangle entries of `S`: the linearised
//! residual `dS Ω'² + Ω'² dS` with `Ω'² = Ω² (I + S)` (each point scaled by
//! `1/‖Ω²‖_F` so near and far points count alike), least squares over all
//! points; a few iterations converge to the nonlinear solution.

use crate::positioning::whitened_gram;
use crate::{EmError, Result};
use aeromag_core::field::dipole::dipole_matrix;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

fn sym_basis(k: usize) -> Matrix3<f64> {
    let (i, j) = UPPER[k];
    let mut e = Matrix3::zeros();
    e[(i, j)] = 1.0;
    e[(j, i)] = 1.0;
    e
}

/// Fit the symmetric transmitter distortion `S` (dimensionless) from field
/// matrices `fields[k]` (T, after stage 1) at known positions `positions_m[k]`
/// (m, transmitter frame), nominal moments `moments` (A·m²).
///
/// Errors: length mismatch, fewer than 2 points, singular normal equations.
pub fn fit_transmitter_geometry(
    fields: &[Matrix3<f64>],
    positions_m: &[Vector3<f64>],
    moments: &Matrix3<f64>,
) -> Result<Matrix3<f64>> {
    if fields.len() != positions_m.len() || fields.len() < 2 {
        return Err(EmError::InvalidArgument {
            reason: format!(
                "{} fields for {} positions (need ≥ 2 of each, equal counts)",
                fields.len(),
                positions_m.len()
            ),
        });
    }
    let ws: Vec<Matrix3<f64>> = fields
        .iter()
        .map(|h| whitened_gram(h, moments))
        .collect::<Result<_>>()?;
    let mut s = Matrix3::<f64>::zeros();
    for _ in 0..6 {
        let mut ata = SMatrix::<f64, 6, 6>::zeros();
        let mut atb = SVector::<f64, 6>::zeros();
        for (w, r) in ws.iter().zip(positions_m) {
            let o = dipole_matrix(r);
            let o2 = o * o;
            let scale = 1.0 / o2.norm().max(f64::MIN_POSITIVE);
            let t = Matrix3::identity() + s;
            let model = t * o2 * t;
            let res = (w - model) * scale;
            let mut a = SMatrix::<f64, 6, 6>::zeros();
            let mut b = SVector::<f64, 6>::zeros();
            for (row, &(i, j)) in UPPER.iter().enumerate() {
                b[row] = res[(i, j)];
                for k in 0..6 {
                    let e = sym_basis(k);
                    let d = (e * o2 * t + t * o2 * e) * scale;
                    a[(row, k)] = d[(i, j)];
                }
            }
            ata += a.transpose() * a;
            atb += a.transpose() * b;
        }
        let d = ata
            .cholesky()
            .ok_or_else(|| EmError::Singular {
                what: "stage-2 normal equations".into(),
            })?
            .solve(&atb);
        for k in 0..6 {
            s += sym_basis(k) * d[k];
        }
        if d.norm() < 1e-14 {
            break;
        }
    }
    Ok(s)
}

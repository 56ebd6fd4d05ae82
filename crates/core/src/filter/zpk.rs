//! Zero-pole-gain (ZPK) representation and the analog frequency transforms
//! and the bilinear transform that turn an analog low-pass prototype into a
//! digital filter.
//!
//! A rational transfer function is stored as
//!
//! ```text
//! H(s) = k · Π (s − z_i) / Π (s − p_j)
//! ```
//!
//! Transforms of the unit-cutoff analog low-pass prototype (degree
//! `d = #poles − #zeros ≥ 0`; `ω0`, `Δω` in rad/s):
//!
//! ```text
//! low-pass   s → s/ω0                 z' = ω0 z,  p' = ω0 p,           k' = k ω0^d
//! high-pass  s → ω0/s                 z' = ω0/z,  p' = ω0/p, +d zeros at 0,
//!                                     k' = k · Re(Π(−z)/Π(−p))
//! band-pass  s → (s² + ω0²)/(s Δω)    each root r → r Δω/2 ± √((r Δω/2)² − ω0²),
//!                                     +d zeros at 0,  k' = k Δω^d
//! band-stop  s → s Δω/(s² + ω0²)      each root r → (Δω/2)/r ± √(((Δω/2)/r)² − ω0²),
//!                                     +d zeros at ±iω0, k' = k · Re(Π(−z)/Π(−p))
//! ```
//!
//! The bilinear (Tustin) transform maps the analog `s`-plane to the digital
//! `z`-plane with sampling rate `fs` (Hz):
//!
//! ```text
//! s = 2 fs (z − 1)/(z + 1)   ⇔   z = (2 fs + s)/(2 fs − s)
//! ```
//!
//! so each analog root `r` becomes `(2fs + r)/(2fs − r)`, the `d` zeros at
//! infinity move to `z = −1` (the Nyquist frequency) and the gain becomes
//! `k · Re(Π(2fs − z)/Π(2fs − p))`. It maps the imaginary axis onto the unit
//! circle with the frequency warping `ω_analog = 2 fs tan(ω_digital/(2 fs))`,
//! which is why the critical frequencies are pre-warped before the analog
//! transform (see [`super::butterworth`]).
//!
//! These are the formulas of SciPy's `lp2lp_zpk`, `lp2hp_zpk`, `lp2bp_zpk`,
//! `lp2bs_zpk` and `bilinear_zpk` (SciPy reference guide,
//! `scipy.signal`), written in the same order of floating-point operations.

use super::complex::{C64, cdiv, cprod, csqrt};

/// A transfer function as zeros, poles (complex, rad/s for analog filters,
/// dimensionless `z`-plane positions for digital ones) and a real gain.
#[derive(Debug, Clone, PartialEq)]
pub struct Zpk {
    /// Zeros `z_i`.
    pub zeros: Vec<C64>,
    /// Poles `p_j`.
    pub poles: Vec<C64>,
    /// Gain `k`.
    pub gain: f64,
}

impl Zpk {
    /// Relative degree `#poles − #zeros` (saturating at 0 for improper input).
    pub fn relative_degree(&self) -> usize {
        self.poles.len().saturating_sub(self.zeros.len())
    }

    /// Low-pass → low-pass with cutoff `wo` (rad/s): `s → s/wo`.
    pub fn lp2lp(&self, wo: f64) -> Zpk {
        let w = C64::new(wo, 0.0);
        Zpk {
            zeros: self.zeros.iter().map(|&z| w * z).collect(),
            poles: self.poles.iter().map(|&p| w * p).collect(),
            gain: self.gain * wo.powf(self.relative_degree() as f64),
        }
    }

    /// Low-pass → high-pass with cutoff `wo` (rad/s): `s → wo/s`.
    pub fn lp2hp(&self, wo: f64) -> Zpk {
        let w = C64::new(wo, 0.0);
        let degree = self.relative_degree();
        let mut zeros: Vec<C64> = self.zeros.iter().map(|&z| cdiv(w, z)).collect();
        zeros.extend(std::iter::repeat_n(C64::new(0.0, 0.0), degree));
        Zpk {
            zeros,
            poles: self.poles.iter().map(|&p| cdiv(w, p)).collect(),
            gain: self.gain * self.negated_gain_ratio(),
        }
    }

    /// Low-pass → band-pass with centre `wo` and width `bw` (rad/s):
    /// `s → (s² + wo²)/(s·bw)`.
    pub fn lp2bp(&self, wo: f64, bw: f64) -> Zpk {
        let degree = self.relative_degree();
        let scale = |r: C64| (r * C64::new(bw, 0.0)) * 0.5;
        let mut zeros = split_pairs(self.zeros.iter().map(|&z| scale(z)), wo);
        zeros.extend(std::iter::repeat_n(C64::new(0.0, 0.0), degree));
        Zpk {
            zeros,
            poles: split_pairs(self.poles.iter().map(|&p| scale(p)), wo),
            gain: self.gain * bw.powf(degree as f64),
        }
    }

    /// Low-pass → band-stop with centre `wo` and width `bw` (rad/s):
    /// `s → s·bw/(s² + wo²)`.
    pub fn lp2bs(&self, wo: f64, bw: f64) -> Zpk {
        let degree = self.relative_degree();
        let half = C64::new(bw / 2.0, 0.0);
        let mut zeros = split_pairs(self.zeros.iter().map(|&z| cdiv(half, z)), wo);
        zeros.extend(std::iter::repeat_n(C64::new(0.0, wo), degree));
        zeros.extend(std::iter::repeat_n(C64::new(0.0, -wo), degree));
        Zpk {
            zeros,
            poles: split_pairs(self.poles.iter().map(|&p| cdiv(half, p)), wo),
            gain: self.gain * self.negated_gain_ratio(),
        }
    }

    /// Bilinear transform with sampling rate `fs` (Hz):
    /// `z = (2fs + s)/(2fs − s)`, zeros at infinity → `z = −1`.
    pub fn bilinear(&self, fs: f64) -> Zpk {
        let fs2 = C64::new(2.0 * fs, 0.0);
        let map = |r: C64| cdiv(fs2 + r, fs2 - r);
        let mut zeros: Vec<C64> = self.zeros.iter().map(|&z| map(z)).collect();
        zeros.extend(std::iter::repeat_n(
            C64::new(-1.0, 0.0),
            self.relative_degree(),
        ));
        let num: Vec<C64> = self.zeros.iter().map(|&z| fs2 - z).collect();
        let den: Vec<C64> = self.poles.iter().map(|&p| fs2 - p).collect();
        Zpk {
            zeros,
            poles: self.poles.iter().map(|&p| map(p)).collect(),
            gain: self.gain * cdiv(cprod(&num), cprod(&den)).re,
        }
    }

    /// `Re(Π(−z)/Π(−p))`, the gain correction of the inverting transforms.
    fn negated_gain_ratio(&self) -> f64 {
        let nz: Vec<C64> = self.zeros.iter().map(|&z| -z).collect();
        let np: Vec<C64> = self.poles.iter().map(|&p| -p).collect();
        cdiv(cprod(&nz), cprod(&np)).re
    }
}

/// `[r + √(r² − wo²) for r] ++ [r − √(r² − wo²) for r]` (the band transforms
/// duplicate every root and shift the copies to `+wo` and `−wo`).
fn split_pairs(roots: impl Iterator<Item = C64>, wo: f64) -> Vec<C64> {
    let roots: Vec<C64> = roots.collect();
    let wo2 = C64::new(wo * wo, 0.0);
    let shifts: Vec<C64> = roots.iter().map(|&r| csqrt(r * r - wo2)).collect();
    let plus = roots.iter().zip(&shifts).map(|(&r, &s)| r + s);
    let minus = roots.iter().zip(&shifts).map(|(&r, &s)| r - s);
    plus.chain(minus).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn proto() -> Zpk {
        // 2nd-order Butterworth prototype: poles e^{±i3π/4}.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        Zpk {
            zeros: vec![],
            poles: vec![C64::new(-h, h), C64::new(-h, -h)],
            gain: 1.0,
        }
    }

    /// Evaluate H(s) at a complex point.
    fn eval(zpk: &Zpk, s: C64) -> C64 {
        let num = zpk
            .zeros
            .iter()
            .fold(C64::new(zpk.gain, 0.0), |a, &z| a * (s - z));
        let den = zpk
            .poles
            .iter()
            .fold(C64::new(1.0, 0.0), |a, &p| a * (s - p));
        num / den
    }

    #[test]
    fn transforms_preserve_response_at_mapped_points() {
        let p = proto();
        let (wo, bw) = (3.0, 2.0);
        let s = C64::new(0.0, 0.7);
        // low-pass: H'(s) = H(s/wo)
        let lp = p.lp2lp(wo);
        assert!((eval(&lp, s * wo) - eval(&p, s)).norm() < 1e-13);
        // high-pass: H'(s) = H(wo/s)
        let hp = p.lp2hp(wo);
        assert!((eval(&hp, s) - eval(&p, C64::new(wo, 0.0) / s)).norm() < 1e-13);
        // band-pass: H'(s) = H((s²+wo²)/(s bw))
        let bp = p.lp2bp(wo, bw);
        let m = (s * s + wo * wo) / (s * bw);
        assert!((eval(&bp, s) - eval(&p, m)).norm() < 1e-13);
        // band-stop: H'(s) = H(s bw/(s²+wo²))
        let bs = p.lp2bs(wo, bw);
        let m = s * bw / (s * s + wo * wo);
        assert!((eval(&bs, s) - eval(&p, m)).norm() < 1e-13);
    }

    #[test]
    fn bilinear_maps_frequency_axis() {
        let p = proto().lp2lp(2.0);
        let fs = 10.0;
        let d = p.bilinear(fs);
        assert_eq!(d.zeros.len(), 2);
        assert!(d.zeros.iter().all(|&z| z == C64::new(-1.0, 0.0)));
        // H_d(e^{iΩ}) = H_a(i 2fs tan(Ω/2))
        let omega: f64 = 0.9;
        let zpt = C64::new(omega.cos(), omega.sin());
        let s = C64::new(0.0, 2.0 * fs * (omega / 2.0).tan());
        assert!((eval(&d, zpt) - eval(&p, s)).norm() < 1e-13);
    }
}

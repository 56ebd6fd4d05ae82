//! Cascaded second-order sections (biquads) and one-way filtering.
//!
//! A filter of `L` sections is the product
//!
//! ```text
//! H(z) = Π_s (b0s + b1s z⁻¹ + b2s z⁻²) / (1 + a1s z⁻¹ + a2s z⁻²)
//! ```
//!
//! Each section runs in transposed direct form II (SciPy's `sosfilt`), with
//! two state values per section:
//!
//! ```text
//! y[n]  = b0 x[n] + z0[n−1]
//! z0[n] = b1 x[n] − a1 y[n] + z1[n−1]
//! z1[n] = b2 x[n] − a2 y[n]
//! ```
//!
//! and the output of one section is the input of the next. (`z0` is
//! evaluated as `(b1 x + z1) − a1 y`, which keeps only one multiply and one
//! subtraction on the sample-to-sample dependency chain; the result differs
//! from SciPy's evaluation order only by rounding.) Sections are
//! numerically far better conditioned than the expanded polynomial
//! `B(z)/A(z)` for orders above ~4 (SciPy reference guide, `sosfilt`).
//!
//! The steady-state ("step-response") initial conditions `zi` are those of
//! SciPy's `sosfilt_zi`: for an input held at 1 forever, section `s` sees
//! the constant `Π_{t<s} H_t(1)` and its state solves `zi = A zi + B`
//! (see [`super::transfer::lfilter_zi`]).

use super::complex::C64;
use super::transfer::{LinearFilter, lfilter_zi};
use super::validate::{check_finite, check_len, invalid};
use crate::error::Result;
use crate::simd::mul_add;

/// Second-order sections, each `[b0, b1, b2, 1, a1, a2]` (SciPy's `sos` array).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sos {
    sections: Vec<[f64; 6]>,
}

impl Sos {
    /// Wraps sections `[b0, b1, b2, a0, a1, a2]`.
    ///
    /// Errors (`InvalidArgument`): no section, a non-finite coefficient, or
    /// `a0 ≠ 1` (SciPy requires normalised sections).
    pub fn new(sections: Vec<[f64; 6]>) -> Result<Self> {
        if sections.is_empty() {
            return Err(invalid("sos", "needs at least one section"));
        }
        for (i, s) in sections.iter().enumerate() {
            if s.iter().any(|c| !c.is_finite()) {
                return Err(invalid(
                    "sos",
                    format!("section {i} has a non-finite coefficient"),
                ));
            }
            if s[3] != 1.0 {
                return Err(invalid(
                    "sos",
                    format!("section {i} has a0 = {} (must be 1)", s[3]),
                ));
            }
        }
        Ok(Sos { sections })
    }

    /// The sections, `[b0, b1, b2, 1, a1, a2]` each.
    pub fn sections(&self) -> &[[f64; 6]] {
        &self.sections
    }

    /// Number of sections.
    pub fn n_sections(&self) -> usize {
        self.sections.len()
    }

    /// SciPy's default `sosfiltfilt` pad length
    /// `3·(2L + 1 − min(#{b2 = 0}, #{a2 = 0}))`, `L` sections.
    pub fn padlen(&self) -> usize {
        let bz = self.sections.iter().filter(|s| s[2] == 0.0).count();
        let az = self.sections.iter().filter(|s| s[5] == 0.0).count();
        3 * (2 * self.sections.len() + 1 - bz.min(az))
    }

    /// Largest pole radius ρ of the sections (roots of `z² + a1 z + a2`);
    /// below 1 for a stable filter. The impulse response decays as `ρᵏ`.
    pub fn pole_radius(&self) -> f64 {
        self.sections
            .iter()
            .map(|s| {
                let (a1, a2) = (s[4], s[5]);
                let disc = a1 * a1 - 4.0 * a2;
                if disc < 0.0 {
                    a2.sqrt()
                } else {
                    (a1.abs() + disc.sqrt()) / 2.0
                }
            })
            .fold(0.0, f64::max)
    }

    /// Samples after which the impulse response has decayed below `tol`
    /// relative (`ρᵏ < tol`); `None` for an unstable or marginal filter.
    /// Zero-phase filtering of overlapping blocks that share this many
    /// samples on each side reproduces whole-series filtering to `tol`.
    pub fn settling_samples(&self, tol: f64) -> Option<usize> {
        let rho = self.pole_radius();
        if rho.is_nan() || rho >= 1.0 || tol.is_nan() || tol <= 0.0 || tol >= 1.0 {
            return None;
        }
        if rho == 0.0 {
            return Some(2);
        }
        Some((tol.ln() / rho.ln()).ceil() as usize)
    }

    /// Magnitude response `|H(e^{iΩ})|`, `Ω = 2π f/fs`, at frequency `f_hz`
    /// for sampling rate `fs_hz` (both Hz).
    pub fn gain(&self, f_hz: f64, fs_hz: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f_hz / fs_hz;
        let z1 = C64::new(w.cos(), -w.sin()); // z⁻¹ on the unit circle
        let z2 = z1 * z1;
        self.sections
            .iter()
            .map(|s| (z1 * s[1] + z2 * s[2] + s[0]).norm() / (z1 * s[4] + z2 * s[5] + s[3]).norm())
            .product()
    }

    /// Steady-state initial conditions for a unit step (SciPy `sosfilt_zi`),
    /// `[z0, z1]` per section.
    ///
    /// Errors (`InvalidArgument`) when a section has a pole at `z = 1`
    /// (`1 + a1 + a2 = 0`), where no steady state exists.
    pub fn zi(&self) -> Result<Vec<[f64; 2]>> {
        let mut scale = 1.0;
        let mut out = Vec::with_capacity(self.sections.len());
        for s in &self.sections {
            let (b, a) = (&s[..3], &s[3..]);
            let z = lfilter_zi(b, a)?;
            out.push([scale * z[0], scale * z[1]]);
            scale *= (b[0] + b[1] + b[2]) / (a[0] + a[1] + a[2]);
        }
        Ok(out)
    }
}

impl LinearFilter for Sos {
    fn padlen(&self) -> usize {
        Sos::padlen(self)
    }

    fn steady_state(&self) -> Result<Vec<f64>> {
        Ok(self.zi()?.into_iter().flatten().collect())
    }

    /// Through the lane kernel with one lane: the bits of each signal
    /// filtered in lanes with others ([`Sos::run_lanes`]), fused
    /// multiply-adds included.
    fn run(&self, x: &mut [f64], state: &mut [f64], reverse: bool) {
        let (samples, _) = x.as_chunks_mut::<1>();
        let mut lanes: Vec<[f64; 1]> = state.iter().map(|&v| [v]).collect();
        self.run_lanes(samples, &mut lanes, reverse);
        for (s, l) in state.iter_mut().zip(lanes) {
            *s = l[0];
        }
    }
}

impl Sos {
    /// [`LinearFilter::run`] on `L` independent signals at once, interleaved
    /// sample by sample (sample `k` of signal `l` is lane `l` of
    /// `io.load(k)`; `state` holds `2 × sections` rows of `L` lanes). Every
    /// lane does exactly the arithmetic of the one-signal loop
    /// ([`LinearFilter::run`] runs this kernel with one lane), so each
    /// output is bit-identical to filtering its signal alone; the `L`
    /// recurrences are independent, so they run in SIMD lanes instead of
    /// waiting on one biquad chain's latency. Uses AVX where the processor
    /// has it (detected at run time; the same bits either way) and fused
    /// multiply-adds where it has them and they are asked for
    /// ([`crate::simd`]). `io` says where the samples come from and where the results
    /// go: in place ([`LaneIo`] for `&mut [[f64; L]]`), from separate
    /// signals into lanes ([`Gather`]) or from lanes into separate signals
    /// ([`Scatter`]), so that a zero-phase pass need not copy its signals
    /// into lanes and back in passes of their own.
    pub(crate) fn run_lanes<const L: usize, IO: LaneIo<L>>(
        &self,
        io: IO,
        state: &mut [[f64; L]],
        reverse: bool,
    ) {
        crate::simd::run(Lanes {
            sections: &self.sections,
            io,
            state,
            reverse,
        })
    }
}

/// Where [`Sos::run_lanes`] reads each sample's `L` lanes and writes the
/// result (`k < len()`).
pub(crate) trait LaneIo<const L: usize> {
    /// Samples to run.
    fn len(&self) -> usize;
    /// Sample `k`'s lanes.
    fn load(&self, k: usize) -> [f64; L];
    /// Store sample `k`'s result.
    fn store(&mut self, k: usize, v: [f64; L]);
}

/// In place: each sample's result replaces it.
impl<const L: usize> LaneIo<L> for &mut [[f64; L]] {
    #[inline(always)]
    fn len(&self) -> usize {
        <[_]>::len(self)
    }
    #[inline(always)]
    fn load(&self, k: usize) -> [f64; L] {
        self[k]
    }
    #[inline(always)]
    fn store(&mut self, k: usize, v: [f64; L]) {
        self[k] = v;
    }
}

/// From `L` separate signals (`src[l][k]`) into lanes (`dst[k][l]`); the
/// signals hold at least `dst.len()` samples.
pub(crate) struct Gather<'a, const L: usize> {
    pub src: [&'a [f64]; L],
    pub dst: &'a mut [[f64; L]],
}

impl<const L: usize> LaneIo<L> for Gather<'_, L> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.dst.len()
    }
    #[inline(always)]
    fn load(&self, k: usize) -> [f64; L] {
        std::array::from_fn(|l| self.src[l][k])
    }
    #[inline(always)]
    fn store(&mut self, k: usize, v: [f64; L]) {
        self.dst[k] = v;
    }
}

/// From lanes (`src[k][l]`) into separate signals (`dst[l][k]`, for the
/// first `dst.len() ≤ L` lanes; the others are not kept); the signals hold
/// at least `src.len()` samples.
pub(crate) struct Scatter<'a, 'b, const L: usize> {
    pub src: &'a [[f64; L]],
    pub dst: &'a mut [&'b mut [f64]],
}

impl<const L: usize> LaneIo<L> for Scatter<'_, '_, L> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.src.len()
    }
    #[inline(always)]
    fn load(&self, k: usize) -> [f64; L] {
        self.src[k]
    }
    #[inline(always)]
    fn store(&mut self, k: usize, v: [f64; L]) {
        for (x, v) in self.dst.iter_mut().zip(v) {
            x[k] = v;
        }
    }
}

/// The arguments of [`Sos::run_lanes`] as a [`crate::simd::Kernel`].
struct Lanes<'a, const L: usize, IO> {
    sections: &'a [[f64; 6]],
    io: IO,
    state: &'a mut [[f64; L]],
    reverse: bool,
}

impl<const L: usize, IO: LaneIo<L>> crate::simd::Kernel for Lanes<'_, L, IO> {
    type Output = ();
    #[inline(always)]
    fn run(self) {
        lanes_dispatch::<L, IO, false>(self.sections, self.io, self.state, self.reverse)
    }
    #[inline(always)]
    fn run_fused(self) {
        lanes_dispatch::<L, IO, true>(self.sections, self.io, self.state, self.reverse)
    }
}

/// The lane kernel with the number of sections known at compile time (so
/// the state stays in registers) for the usual filters of 1–8 sections,
/// and with the multiplications by 1 left out when every section after the
/// first has `b0 = b2 = 1` (a Butterworth band-pass, high- or low-pass from
/// [`super::zpk2sos`]: the gain in the first section, the zeros at ±1 in
/// the others). `1 · x` is `x` exactly, so the bits are the same either
/// way; the sections' arithmetic is about a sixth less. `FUSED`: with
/// fused multiply-adds ([`crate::simd::mul_add`]), which take the
/// sections' arithmetic from 30 operations per sample to 17 for four
/// sections.
#[inline(always)]
fn lanes_dispatch<const L: usize, IO: LaneIo<L>, const FUSED: bool>(
    sections: &[[f64; 6]],
    io: IO,
    state: &mut [[f64; L]],
    reverse: bool,
) {
    if L == 1 {
        // One signal: the general loop. With the sections' state in
        // registers the compiler packs each section's two state values
        // into one register and spends the chain's cycles on shuffles
        // (`bandpass_20_columns_1e5/one_at_a_time` 23.5 → 33.5 ms).
        return lanes_any::<L, IO, FUSED>(sections, io, state, reverse);
    }
    let unit_rest = sections.iter().skip(1).all(|s| s[0] == 1.0 && s[2] == 1.0);
    macro_rules! fixed {
        ($s:literal) => {
            if unit_rest {
                lanes_fixed::<$s, L, true, IO, FUSED>(sections, io, state, reverse)
            } else {
                lanes_fixed::<$s, L, false, IO, FUSED>(sections, io, state, reverse)
            }
        };
    }
    match sections.len() {
        1 => fixed!(1),
        2 => fixed!(2),
        3 => fixed!(3),
        4 => fixed!(4),
        5 => fixed!(5),
        6 => fixed!(6),
        7 => fixed!(7),
        8 => fixed!(8),
        _ => lanes_any::<L, IO, FUSED>(sections, io, state, reverse),
    }
}

/// `body` for each sample `k` of a pass over `n` samples, last to first
/// when `reverse`: two loops rather than a closure, which kept the
/// filter's state out of registers (twice as slow), or an index computed
/// per sample (5 % slower).
macro_rules! in_order {
    ($n:expr, $reverse:expr, |$k:ident| $body:block) => {
        if $reverse {
            for $k in (0..$n).rev() $body
        } else {
            for $k in 0..$n $body
        }
    };
}

/// [`lanes_dispatch`] for `S` sections; `UNIT_REST`: every section after
/// the first has `b0 = b2 = 1`.
#[inline(always)]
fn lanes_fixed<
    const S: usize,
    const L: usize,
    const UNIT_REST: bool,
    IO: LaneIo<L>,
    const FUSED: bool,
>(
    sections: &[[f64; 6]],
    mut io: IO,
    state: &mut [[f64; L]],
    reverse: bool,
) {
    let c: [[f64; 6]; S] = std::array::from_fn(|i| sections[i]);
    let mut z: [[[f64; L]; 2]; S] = std::array::from_fn(|i| [state[2 * i], state[2 * i + 1]]);
    in_order!(io.len(), reverse, |k| {
        let mut v = io.load(k);
        lanes_step::<S, L, UNIT_REST, FUSED>(&c, &mut z, &mut v);
        io.store(k, v);
    });
    for (i, zs) in z.iter().enumerate() {
        state[2 * i] = zs[0];
        state[2 * i + 1] = zs[1];
    }
}

/// One sample of `L` lanes through `S` sections (`UNIT_REST`: `b0 = b2 =
/// 1` after the first section, whose products `1 · x` are left out;
/// `FUSED`: with fused multiply-adds).
#[inline(always)]
fn lanes_step<const S: usize, const L: usize, const UNIT_REST: bool, const FUSED: bool>(
    c: &[[f64; 6]; S],
    z: &mut [[[f64; L]; 2]; S],
    v: &mut [f64; L],
) {
    let mut x = *v;
    for (k, (s, zs)) in c.iter().zip(z.iter_mut()).enumerate() {
        let unit = UNIT_REST && k > 0;
        let [z0, z1] = zs;
        let mut y = [0.0; L];
        for l in 0..L {
            y[l] = section::<FUSED>(s, unit, x[l], &mut z0[l], &mut z1[l]);
        }
        x = y;
    }
    *v = x;
}

/// One sample `x` through the section `s` with state `z0`, `z1` (module
/// docs); `unit`: `b0 = b2 = 1`, whose products are left out. With `FUSED`,
/// each product and the sum it enters are one fused multiply-add
/// ([`mul_add`]), so that `z0 = (b1 x + z1) − a1 y` is rounded twice
/// instead of four times. Without, `−a1 · y + t` is the bits of `t − a1 ·
/// y` (negation is exact and IEEE addition commutes), so the one formula
/// serves both.
#[inline(always)]
fn section<const FUSED: bool>(s: &[f64; 6], unit: bool, x: f64, z0: &mut f64, z1: &mut f64) -> f64 {
    let y = if unit {
        x + *z0
    } else {
        mul_add::<FUSED>(s[0], x, *z0)
    };
    *z0 = mul_add::<FUSED>(-s[4], y, mul_add::<FUSED>(s[1], x, *z1));
    *z1 = mul_add::<FUSED>(-s[5], y, if unit { x } else { s[2] * x });
    y
}

#[inline(always)]
fn lanes_any<const L: usize, IO: LaneIo<L>, const FUSED: bool>(
    sections: &[[f64; 6]],
    mut io: IO,
    state: &mut [[f64; L]],
    reverse: bool,
) {
    in_order!(io.len(), reverse, |k| {
        let mut x = io.load(k);
        for (s, z) in sections.iter().zip(state.chunks_exact_mut(2)) {
            let [z0, z1] = z else { unreachable!() };
            for l in 0..L {
                x[l] = section::<FUSED>(s, false, x[l], &mut z0[l], &mut z1[l]);
            }
        }
        io.store(k, x);
    });
}

/// One-way (causal) filtering through the sections from zero initial state,
/// equal to SciPy's `sosfilt(sos, x)`.
///
/// Errors: `TooShort` for an empty `x`, `NonFinite` naming the first
/// non-finite sample.
pub fn sosfilt(sos: &Sos, x: &[f64]) -> Result<Vec<f64>> {
    check_len("x", x.len(), 1)?;
    check_finite("x", x)?;
    let mut y = x.to_vec();
    let mut state = vec![0.0; 2 * sos.n_sections()];
    sos.run(&mut y, &mut state, false);
    Ok(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CoreError;

    #[test]
    fn constructor_validates() {
        assert!(Sos::new(vec![]).is_err());
        assert!(Sos::new(vec![[1.0, 0.0, 0.0, 2.0, 0.0, 0.0]]).is_err());
        assert!(Sos::new(vec![[1.0, f64::NAN, 0.0, 1.0, 0.0, 0.0]]).is_err());
        assert!(Sos::new(vec![[1.0, 0.5, 0.0, 1.0, -0.5, 0.0]]).is_ok());
    }

    #[test]
    fn padlen_counts_first_order_sections() {
        let s = Sos::new(vec![
            [1.0, 1.0, 0.0, 1.0, -0.5, 0.0],
            [1.0, 2.0, 1.0, 1.0, -0.2, 0.3],
        ])
        .unwrap();
        assert_eq!(s.padlen(), 3 * (5 - 1));
    }

    #[test]
    fn impulse_response_of_one_pole() {
        // y[n] = x[n] + 0.5 y[n−1] → h[n] = 0.5^n
        let s = Sos::new(vec![[1.0, 0.0, 0.0, 1.0, -0.5, 0.0]]).unwrap();
        let mut x = vec![0.0; 6];
        x[0] = 1.0;
        let y = sosfilt(&s, &x).unwrap();
        for (n, v) in y.iter().enumerate() {
            assert_eq!(*v, 0.5f64.powi(n as i32));
        }
    }

    #[test]
    fn zi_is_the_step_steady_state() {
        let s = Sos::new(vec![
            [0.2, 0.3, 0.1, 1.0, -0.6, 0.2],
            [1.0, -0.4, 0.3, 1.0, 0.1, 0.05],
        ])
        .unwrap();
        let mut state: Vec<f64> = s.zi().unwrap().into_iter().flatten().collect();
        let mut x = vec![1.0; 20];
        s.run(&mut x, &mut state, false);
        let dc: f64 = s
            .sections()
            .iter()
            .map(|c| (c[0] + c[1] + c[2]) / (c[3] + c[4] + c[5]))
            .product();
        for v in x {
            assert!((v - dc).abs() < 1e-14);
        }
    }

    #[test]
    fn sosfilt_errors() {
        let s = Sos::new(vec![[1.0, 0.0, 0.0, 1.0, -0.5, 0.0]]).unwrap();
        assert!(matches!(
            sosfilt(&s, &[]),
            Err(CoreError::TooShort { min: 1, .. })
        ));
        assert_eq!(
            sosfilt(&s, &[1.0, f64::INFINITY]),
            Err(CoreError::NonFinite {
                name: "x",
                index: 1
            })
        );
    }
}

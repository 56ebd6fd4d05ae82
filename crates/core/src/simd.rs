//! Kernels compiled three times: for any x86-64, with AVX, and with AVX and
//! fused multiply-add (FMA), chosen at run time.
//!
//! The release build targets every x86-64 processor (SSE2 only), so a loop
//! over `[f64; 4]` lanes runs two lanes per instruction. [`run`] calls a
//! [`Kernel`] through a copy compiled with AVX (four lanes per instruction)
//! when the processor has it. Both copies do the same multiplications and
//! additions in the same order (Rust never fuses them into FMA by itself),
//! so their results are bit-identical; only the speed differs.
//!
//! A kernel may also say how to run with FMA ([`Kernel::run_fused`]: a
//! product and a sum in one instruction, rounded once). [`run`] calls it
//! only where the processor has FMA (x86-64 from 2013 on) and the
//! environment variable `AEROMAG_FMA` is set (to anything; read once per
//! process). It is off by default because its results differ from those
//! without FMA by rounding, so the same flight would give other last
//! digits on another processor (the quick demo's `eddy_nt` 0.09046 against
//! 0.09047), and because it gains little: the Tolles-Lawson fit is bound
//! by memory, not arithmetic (10⁷ samples: 2 % faster; the band-pass of
//! 20 columns alone 8 %, `cargo bench --bench filters`). With or without,
//! one machine gives the same bits whatever the thread count.
//!
//! Where the compiler's own vectorisation of such a loop goes wrong (it may
//! pack the loop across independent sums instead of along the lanes, and
//! then spends its instructions on shuffles), the kernel is written with
//! explicit AVX instructions beside the plain loop it must equal:
//! [`lane_dots`] and [`lane_dots_pairs`], the dot products of the normal
//! equations (multiply, then add, lane by lane: the same bits).
//!
//! ```
//! use aeromag_core::simd::{Kernel, run};
//! struct SumOfSquares<'a>(&'a [f64]);
//! impl Kernel for SumOfSquares<'_> {
//!     type Output = f64;
//!     #[inline(always)]
//!     fn run(self) -> f64 {
//!         let mut acc = [0.0; 4];
//!         for c in self.0.chunks_exact(4) {
//!             for l in 0..4 {
//!                 acc[l] += c[l] * c[l];
//!             }
//!         }
//!         (acc[0] + acc[1]) + (acc[2] + acc[3])
//!     }
//! }
//! assert_eq!(run(SumOfSquares(&[1.0, 2.0, 3.0, 4.0])), 30.0);
//! ```

/// A computation to compile with and without AVX (and FMA). Mark `run`
/// (and the functions it calls in its hot loop) `#[inline(always)]`: code
/// that is not inlined into the AVX copy is compiled for plain x86-64.
pub trait Kernel: Sized {
    /// What the kernel returns.
    type Output;
    /// Do the work.
    fn run(self) -> Self::Output;
    /// Do the work where the processor has FMA, with fused multiply-adds
    /// (`f64::mul_add`, one instruction there) where the kernel wants them.
    /// The default is [`Kernel::run`]: the same bits as without FMA.
    #[inline(always)]
    fn run_fused(self) -> Self::Output {
        self.run()
    }
}

/// A copy of the kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Plain x86-64 (or another architecture).
    Plain,
    /// AVX, without fused multiply-adds.
    Avx,
    /// AVX with fused multiply-adds ([`Kernel::run_fused`]).
    AvxFma,
}

impl Level {
    /// Whether this processor can run the copy.
    pub fn available(self) -> bool {
        match self {
            Level::Plain => true,
            #[cfg(target_arch = "x86_64")]
            Level::Avx => std::arch::is_x86_feature_detected!("avx"),
            #[cfg(target_arch = "x86_64")]
            Level::AvxFma => {
                std::arch::is_x86_feature_detected!("avx")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }
}

/// The copy of the kernels [`run`] calls: AVX where the processor has it,
/// with FMA only where it has that too and `AEROMAG_FMA` is set (read once
/// per process; module docs).
pub fn level() -> Level {
    static LEVEL: std::sync::OnceLock<Level> = std::sync::OnceLock::new();
    *LEVEL.get_or_init(|| {
        if std::env::var_os("AEROMAG_FMA").is_some() && Level::AvxFma.available() {
            Level::AvxFma
        } else if Level::Avx.available() {
            Level::Avx
        } else {
            Level::Plain
        }
    })
}

thread_local! {
    /// [`with_level`]'s choice for this thread.
    static CHOSEN: std::cell::Cell<Option<Level>> = const { std::cell::Cell::new(None) };
}

/// `f()` with the kernels that run on this thread at `level` instead of
/// [`level`] (kernels that `f` runs on other threads are not affected):
/// for tests and comparisons of the copies. `None` if the processor
/// cannot run `level`.
pub fn with_level<R>(level: Level, f: impl FnOnce() -> R) -> Option<R> {
    if !level.available() {
        return None;
    }
    /// Puts back the thread's previous choice, also if `f` panics.
    struct Restore(Option<Level>);
    impl Drop for Restore {
        fn drop(&mut self) {
            CHOSEN.with(|c| c.set(self.0));
        }
    }
    let _restore = Restore(CHOSEN.with(|c| c.replace(Some(level))));
    Some(f())
}

/// Every copy of the kernels, plainest first.
pub const LEVELS: [Level; 3] = [Level::Plain, Level::Avx, Level::AvxFma];

/// The copy of the kernels that runs on this thread: [`with_level`]'s
/// choice, else [`level`].
fn current() -> Level {
    CHOSEN.with(|c| c.get()).unwrap_or_else(level)
}

/// Run `kernel` with AVX (and FMA) when the processor has it, otherwise as
/// compiled ([`level`], [`with_level`]).
#[inline]
pub fn run<K: Kernel>(kernel: K) -> K::Output {
    match current() {
        // SAFETY: the processor supports AVX and FMA (checked by `level`
        // or `with_level`), the only requirement of calling a function
        // compiled with them.
        #[cfg(target_arch = "x86_64")]
        Level::AvxFma => unsafe { run_avx_fma(kernel) },
        // SAFETY: as above, for AVX.
        #[cfg(target_arch = "x86_64")]
        Level::Avx => unsafe { run_avx(kernel) },
        _ => kernel.run(),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn run_avx<K: Kernel>(kernel: K) -> K::Output {
    kernel.run()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,fma")]
fn run_avx_fma<K: Kernel>(kernel: K) -> K::Output {
    kernel.run_fused()
}

/// `a · b + c`, rounded once (one FMA instruction) when `FUSED`, else the
/// product rounded and then the sum: for kernels written once for both
/// [`Kernel::run`] (`FUSED = false`) and [`Kernel::run_fused`].
#[inline(always)]
pub fn mul_add<const FUSED: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FUSED { a.mul_add(b, c) } else { a * b + c }
}

/// Dot products in lanes, a tile of them at a time:
/// `out[r][c][l] = Σ_k a[r][4k+l] · b[c][4k+l]` over the whole groups of
/// four rows (`k < ⌊m/4⌋`, `m` the shortest slice), each lane summed in
/// row order, so that lane `l` of every product is the same bits as the
/// scalar loop `s[l] += a[4k+l] * b[4k+l]` (multiply, then add: no FMA),
/// whatever the tile. The caller adds the lanes and the rows left over.
///
/// With AVX this is written with explicit four-lane instructions: the
/// compiler's own vectorisation of the scalar loop interleaved the products
/// across lanes and spent most instructions on shuffles. A tile of `R × C`
/// products loads `R + C` vectors per group of rows and keeps `R · C` sums
/// in flight (`R · C ≤ 8` keeps them in registers).
pub fn lane_dots<const R: usize, const C: usize>(
    a: [&[f64]; R],
    b: [&[f64]; C],
) -> [[[f64; 4]; C]; R] {
    lane_dots_of::<R, C, false>(a, b)
}

/// Four dot products `a[t] · b[t]` in lanes, summed as [`lane_dots`]
/// sums them (`out[t][l]`): the products that do not fill a tile.
pub fn lane_dots_pairs(a: [&[f64]; 4], b: [&[f64]; 4]) -> [[f64; 4]; 4] {
    let s = lane_dots_of::<4, 4, true>(a, b);
    std::array::from_fn(|t| s[t][t])
}

/// The products `a[r] · b[c]` of a tile (`DIAGONAL`: those with `r = c`
/// alone; the others are left at zero), with AVX where the processor has
/// it.
fn lane_dots_of<const R: usize, const C: usize, const DIAGONAL: bool>(
    a: [&[f64]; R],
    b: [&[f64]; C],
) -> [[[f64; 4]; C]; R] {
    let m = a.iter().chain(&b).map(|x| x.len()).min().unwrap_or(0);
    let (a, b) = (a.map(|x| &x[..m]), b.map(|x| &x[..m]));
    #[cfg(target_arch = "x86_64")]
    if current() != Level::Plain {
        // SAFETY: the processor supports AVX (checked by `level` or
        // `with_level`), and every slice holds `m` values.
        return unsafe { lane_dots_avx::<R, C, DIAGONAL>(a, b, m / 4) };
    }
    lane_dots_portable::<R, C, DIAGONAL>(a, b, m / 4)
}

/// [`lane_dots_of`] as plain loops (any processor).
fn lane_dots_portable<const R: usize, const C: usize, const DIAGONAL: bool>(
    a: [&[f64]; R],
    b: [&[f64]; C],
    groups: usize,
) -> [[[f64; 4]; C]; R] {
    let mut s = [[[0.0f64; 4]; C]; R];
    for k in 0..groups {
        for (r, (sr, ar)) in s.iter_mut().zip(&a).enumerate() {
            for (c, (src, bc)) in sr.iter_mut().zip(&b).enumerate() {
                if DIAGONAL && r != c {
                    continue;
                }
                for l in 0..4 {
                    src[l] += ar[4 * k + l] * bc[4 * k + l];
                }
            }
        }
    }
    s
}

/// [`lane_dots_of`] over `groups` groups of four rows, with AVX.
///
/// # Safety
/// The processor must support AVX and every slice must hold at least
/// `4 · groups` values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn lane_dots_avx<const R: usize, const C: usize, const DIAGONAL: bool>(
    a: [&[f64]; R],
    b: [&[f64]; C],
    groups: usize,
) -> [[[f64; 4]; C]; R] {
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let mut s: [[__m256d; C]; R] = [[_mm256_setzero_pd(); C]; R];
    for k in 0..groups {
        // SAFETY: row 4k + 3 < 4 · groups ≤ every slice's length.
        let (av, bv): ([__m256d; R], [__m256d; C]) = unsafe {
            (
                a.map(|x| _mm256_loadu_pd(x.as_ptr().add(4 * k))),
                b.map(|x| _mm256_loadu_pd(x.as_ptr().add(4 * k))),
            )
        };
        for r in 0..R {
            for c in 0..C {
                if !DIAGONAL || r == c {
                    s[r][c] = _mm256_add_pd(s[r][c], _mm256_mul_pd(av[r], bv[c]));
                }
            }
        }
    }
    let mut out = [[[0.0f64; 4]; C]; R];
    for (o, v) in out.iter_mut().zip(s) {
        for (o, v) in o.iter_mut().zip(v) {
            // SAFETY: `o` holds four values.
            unsafe { _mm256_storeu_pd(o.as_mut_ptr(), v) };
        }
    }
    out
}

/// Whether every value is finite: blocks without an early exit inside
/// vectorise (several times faster than `iter().all(..)` on long slices).
#[inline]
pub fn all_finite(x: &[f64]) -> bool {
    x.chunks(256)
        .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane sums are those of the plain loops, bit for bit, with AVX
    /// or without (on a processor with AVX both paths run here).
    #[test]
    fn lane_dots_are_the_plain_loops() {
        let col = |j: usize, m: usize| -> Vec<f64> {
            (0..m)
                .map(|k| ((k * (j + 3) + 1) as f64 * 0.731).sin() * 10f64.powi(j as i32 % 5 - 2))
                .collect()
        };
        for m in [0, 3, 4, 9, 130] {
            let c: Vec<Vec<f64>> = (0..8).map(|j| col(j, m + j % 3)).collect();
            let groups = m / 4;
            let tile = lane_dots([&c[0], &c[1]], [&c[2], &c[3], &c[4], &c[5]]);
            assert_eq!(
                tile,
                lane_dots_portable::<2, 4, false>(
                    [&c[0][..m], &c[1][..m]],
                    [&c[2][..m], &c[3][..m], &c[4][..m], &c[5][..m]],
                    groups
                )
            );
            let pairs = lane_dots_pairs([&c[0], &c[1], &c[6], &c[7]], [&c[7], &c[2], &c[6], &c[3]]);
            for (t, (i, j)) in [(0, 7), (1, 2), (6, 6), (7, 3)].into_iter().enumerate() {
                let one =
                    lane_dots_portable::<1, 1, false>([&c[i][..m]], [&c[j][..m]], groups)[0][0];
                assert_eq!(
                    pairs[t].map(f64::to_bits),
                    one.map(f64::to_bits),
                    "m {m} pair {t}"
                );
            }
            // Lane l of a product: its rows 4k + l, summed in order.
            if m >= 4 {
                let mut lane1 = 0.0;
                for k in 0..groups {
                    lane1 += c[0][4 * k + 1] * c[2][4 * k + 1];
                }
                assert_eq!(tile[0][0][1].to_bits(), lane1.to_bits());
            }
        }
    }
}

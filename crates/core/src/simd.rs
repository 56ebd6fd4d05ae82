//! Kernels compiled twice: for any x86-64 and with AVX, chosen at run time.
//!
//! The release build targets every x86-64 processor (SSE2 only), so a loop
//! over `[f64; 4]` lanes runs two lanes per instruction. [`run`] calls a
//! [`Kernel`] through a copy compiled with AVX (four lanes per instruction)
//! when the processor has it. Both copies do the same multiplications and
//! additions in the same order (Rust never fuses them into FMA), so the
//! results are bit-identical on every machine; only the speed differs.
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

/// A computation to compile with and without AVX. Mark `run` (and the
/// functions it calls in its hot loop) `#[inline(always)]`: code that is
/// not inlined into the AVX copy is compiled for plain x86-64.
pub trait Kernel {
    /// What the kernel returns.
    type Output;
    /// Do the work.
    fn run(self) -> Self::Output;
}

/// Run `kernel` with AVX when the processor has it, otherwise as compiled.
#[inline]
pub fn run<K: Kernel>(kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor supports AVX (checked just above), the only
        // requirement of calling a function compiled with it.
        return unsafe { run_avx(kernel) };
    }
    kernel.run()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn run_avx<K: Kernel>(kernel: K) -> K::Output {
    kernel.run()
}

/// Whether every value is finite: blocks without an early exit inside
/// vectorise (several times faster than `iter().all(..)` on long slices).
#[inline]
pub fn all_finite(x: &[f64]) -> bool {
    x.chunks(256)
        .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()))
}

//! First-order lag of the field derivative for the lagged eddy-current terms.
//!
//! An eddy-current loop (inductance `L`, resistance `R`, area `A`, normal `n`)
//! driven by the changing field obeys `L di/dt + R i = −A n·dB/dt`: its
//! current is `dB/dt` passed through the lag `τ g' + g = u` with `τ = L/R`
//! (the `l9` group of [`super::terms`]; aeromag's extension of the
//! Leliak model, spec `compensation.md`, "The interference model").
//!
//! Discretisation: exact for an input that is linear between samples
//! (first-order hold), over the actual time steps `Δt_k = t_k − t_{k−1}`:
//!
//! ```text
//! a   = exp(−Δt/τ)
//! g_k = a g_{k−1} + (1 − a) u_{k−1} + (u_k − u_{k−1}) (1 − τ (1 − a)/Δt)
//! ```
//!
//! A constant input is passed unchanged (`g = u`); the lag starts in that
//! steady state (`g_0 = u_0`) and restarts there after a non-finite sample or
//! a time step that is not positive, so a gap never poisons what follows.

/// The lag `τ g' + g = u` stepped sample by sample.
#[derive(Debug, Clone, Copy)]
pub struct FirstOrderLag {
    tau_s: f64,
    /// Previous `(t, u, g)`.
    prev: Option<(f64, f64, f64)>,
    /// The coefficients `(Δt, a, 1 − τ(1 − a)/Δt)` of the last step, kept
    /// while the step stays the same (an `exp` per sample costs more than
    /// the recursion; the values are those a fresh computation gives).
    coef: (f64, f64, f64),
}

impl FirstOrderLag {
    /// A lag of time constant `tau_s` (s, > 0) at rest.
    pub fn new(tau_s: f64) -> Self {
        Self {
            tau_s,
            prev: None,
            coef: (f64::NAN, f64::NAN, f64::NAN),
        }
    }

    /// The output at time `t_s` (s) for input `u` (any unit; the output has
    /// the same).
    pub fn step(&mut self, t_s: f64, u: f64) -> f64 {
        let g = match self.prev {
            Some((t0, u0, g0)) if u0.is_finite() && g0.is_finite() && t_s > t0 => {
                let dt = t_s - t0;
                if dt != self.coef.0 {
                    let a = (-dt / self.tau_s).exp();
                    self.coef = (dt, a, 1.0 - self.tau_s * (1.0 - a) / dt);
                }
                let (_, a, h) = self.coef;
                a * g0 + (1.0 - a) * u0 + (u - u0) * h
            }
            _ => u,
        };
        self.prev = Some((t_s, u, g));
        g
    }

    /// Samples after which a unit disturbance of the state has decayed below
    /// `tol` at the sampling interval `dt_s` (s).
    pub fn settling_samples(tau_s: f64, dt_s: f64, tol: f64) -> usize {
        if !(dt_s > 0.0 && tau_s > 0.0 && tol > 0.0 && tol < 1.0) {
            return 0;
        }
        (tau_s / dt_s * (1.0 / tol).ln()).ceil() as usize
    }
}

/// The three-axis lags for every `τ` of a term set, stepped together.
#[derive(Debug, Clone)]
pub struct LagBank {
    lags: Vec<[FirstOrderLag; 3]>,
    out: Vec<[f64; 3]>,
}

impl LagBank {
    /// One three-axis lag per `τ` (s).
    pub fn new(taus_s: &[f64]) -> Self {
        Self {
            lags: taus_s.iter().map(|&t| [FirstOrderLag::new(t); 3]).collect(),
            out: vec![[0.0; 3]; taus_s.len()],
        }
    }

    /// The lagged derivatives at `t_s` for the derivative `db`, one per `τ`.
    pub fn step(&mut self, t_s: f64, db: [f64; 3]) -> &[[f64; 3]] {
        for (lag, o) in self.lags.iter_mut().zip(self.out.iter_mut()) {
            for c in 0..3 {
                o[c] = lag[c].step(t_s, db[c]);
                // The axes share τ and the time step: one `exp` for three.
                if c < 2 {
                    lag[c + 1].coef = lag[c].coef;
                }
            }
        }
        &self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The continuous-time response of the lag to a ramp `u = r t` from rest
    /// in steady state at 0 is `g = r (t − τ (1 − e^{−t/τ}))`; the
    /// first-order-hold recursion is exact for it at any, even uneven, step.
    #[test]
    fn exact_for_a_ramp_on_uneven_steps() {
        let (tau, r) = (0.4, 3.0);
        let mut lag = FirstOrderLag::new(tau);
        let mut t = 0.0;
        let mut k = 0;
        while t < 5.0 {
            let g = lag.step(t, r * t);
            let exact = r * (t - tau * (1.0 - (-t / tau).exp()));
            assert!((g - exact).abs() < 1e-12, "t {t}: {g} vs {exact}");
            t += 0.05 + 0.04 * (k % 3) as f64;
            k += 1;
        }
    }

    /// A sine of period T comes out with the amplitude `1/√(1+(ωτ)²)` and
    /// the phase lag `atan(ωτ)` of the continuous lag (steady state; the
    /// input is sampled at 100 Hz, so the hold error is ~1e-4).
    #[test]
    fn sine_gain_and_phase() {
        let (tau, f) = (0.3, 0.5);
        let w = 2.0 * std::f64::consts::PI * f;
        let mut lag = FirstOrderLag::new(tau);
        let dt = 0.01;
        let (mut s, mut c) = (0.0, 0.0);
        let n = 4000;
        for k in 0..n {
            let t = k as f64 * dt;
            let g = lag.step(t, (w * t).sin());
            if k >= 2000 {
                s += g * (w * t).sin();
                c += g * (w * t).cos();
            }
        }
        let m = (n - 2000) as f64 / 2.0;
        let (gain, phase) = ((s * s + c * c).sqrt() / m, (-c).atan2(s));
        assert!(
            (gain - 1.0 / (1.0 + (w * tau).powi(2)).sqrt()).abs() < 1e-3,
            "gain {gain}"
        );
        assert!((phase - (w * tau).atan()).abs() < 1e-3, "phase {phase}");
    }

    #[test]
    fn restarts_after_a_gap_and_never_panics() {
        let mut lag = FirstOrderLag::new(0.5);
        assert_eq!(lag.step(0.0, 2.0), 2.0);
        assert!(lag.step(0.1, f64::NAN).is_nan());
        assert_eq!(lag.step(0.2, 5.0), 5.0);
        assert_eq!(lag.step(0.2, 7.0), 7.0); // repeated time: restart
        assert!(lag.step(0.3, 7.0) == 7.0);
        assert_eq!(FirstOrderLag::settling_samples(0.5, 0.1, 1e-15), 173);
        assert_eq!(FirstOrderLag::settling_samples(0.5, 0.0, 1e-15), 0);
    }
}

//! Exact discretisations of the first-order lag `τ dy/dt + y = u(t)`.
//!
//! With `a = exp(−Δt/τ)`:
//!
//! * **Zero-order hold** (`u` constant on `[t_k, t_{k+1})`, e.g. the rate of
//!   change of a piecewise-linear field):
//!   `y_{k+1} = a y_k + (1 − a) u_k`.
//! * **Piecewise-linear input** (`u` linear between samples with slope
//!   `s_k = (u_{k+1} − u_k)/Δt`): the particular solution is `u(t) − τ s_k`,
//!   hence `y_{k+1} = u_{k+1} − τ s_k + a (y_k − u_k + τ s_k)`.
//!
//! Both are exact (no truncation error) for inputs of the stated form; they
//! are used for the eddy currents of the airframe (time constants 0.1–1 s,
//! spec `simulator.md` "Platform interference truth") and the optional lag of
//! the scalar magnetometer ("Sensors").

/// Zero-order-hold response: `y_0 = y0`, `y_{k+1} = a y_k + (1 − a) u_k`,
/// for `k = 0…n−2` where `n = u.len()` (the last input sample is not used).
/// `tau_s ≤ 0` returns the input delayed by one step (the limit `a → 0`).
pub fn lag_zoh(u: &[f64], dt_s: f64, tau_s: f64, y0: f64) -> Vec<f64> {
    let a = if tau_s > 0.0 {
        (-dt_s / tau_s).exp()
    } else {
        0.0
    };
    let mut y = Vec::with_capacity(u.len());
    if u.is_empty() {
        return y;
    }
    let mut v = y0;
    y.push(v);
    for &uk in &u[..u.len() - 1] {
        v = a * v + (1.0 - a) * uk;
        y.push(v);
    }
    y
}

/// Response to a piecewise-linear input sampled at step `dt_s`, starting in
/// the steady state of the initial ramp (`y_0 = u_0 − τ s_0`). `tau_s = 0`
/// returns the input unchanged.
pub fn lag_linear(u: &[f64], dt_s: f64, tau_s: f64) -> Vec<f64> {
    if tau_s <= 0.0 || u.len() < 2 {
        return u.to_vec();
    }
    let a = (-dt_s / tau_s).exp();
    let mut y = Vec::with_capacity(u.len());
    let s0 = (u[1] - u[0]) / dt_s;
    let mut v = u[0] - tau_s * s0;
    y.push(v);
    for k in 0..u.len() - 1 {
        let s = (u[k + 1] - u[k]) / dt_s;
        v = u[k + 1] - tau_s * s + a * (v - u[k] + tau_s * s);
        y.push(v);
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoh_step_response_is_exponential() {
        let (dt, tau) = (0.1, 0.37);
        let mut u = vec![0.0; 50];
        u[10..].iter_mut().for_each(|x| *x = 2.0);
        let y = lag_zoh(&u, dt, tau, 0.0);
        for (k, &yk) in y.iter().enumerate() {
            let t = (k as f64 - 10.0) * dt;
            let expect = if k <= 10 {
                0.0
            } else {
                2.0 * (1.0 - (-t / tau).exp())
            };
            assert!((yk - expect).abs() < 1e-14, "k={k}: {yk} vs {expect}");
        }
    }

    #[test]
    fn linear_input_matches_the_analytic_solution_of_a_ramp_then_hold() {
        // u = 0 until t0, then ramp of slope s until t1, then constant.
        let (dt, tau, s) = (0.1, 0.5, 3.0);
        let (t0, t1) = (1.0, 2.0);
        let u: Vec<f64> = (0..60)
            .map(|k| {
                let t = k as f64 * dt;
                s * (t - t0).clamp(0.0, t1 - t0)
            })
            .collect();
        let y = lag_linear(&u, dt, tau);
        for (k, &yk) in y.iter().enumerate() {
            let t = k as f64 * dt;
            let ramp = |t: f64| {
                if t <= 0.0 {
                    0.0
                } else {
                    s * (t - tau * (1.0 - (-t / tau).exp()))
                }
            };
            // superposition of a ramp at t0 and a negative ramp at t1
            let expect = ramp(t - t0) - ramp(t - t1);
            assert!((yk - expect).abs() < 1e-12, "k={k}: {yk} vs {expect}");
        }
    }

    #[test]
    fn zero_tau_is_identity() {
        let u = [1.0, 2.0, 4.0];
        assert_eq!(lag_linear(&u, 0.1, 0.0), u.to_vec());
    }
}

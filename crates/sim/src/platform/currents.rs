//! On-board electric currents: true current `I(t)` of each loop and its
//! recorded channel.
//!
//! `I(t) = I_mean + I_sw s(t) + f(t)` with a telegraph switching state
//! `s ∈ {0, 1}` that toggles at the events of a Poisson process of rate
//! `switches_per_hour` (a load switched on and off: de-icing, transmitter,
//! pumps), and a first-order Gauss–Markov fluctuation `f` (RMS
//! `fluctuation_a`, time constant `fluctuation_tau_s`). The recorded channel
//! adds white noise `channel_noise_a`. Spec `simulator.md`: "optional fields
//! of on-board electrical currents recorded on current channels".

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::aircraft::CurrentLoop;
use crate::random::gauss_markov::gauss_markov;
use crate::random::normal;

/// True and recorded currents (A) of one loop.
#[derive(Debug, Clone, PartialEq)]
pub struct CurrentSeries {
    /// True current, A.
    pub true_a: Vec<f64>,
    /// Recorded channel, A.
    pub recorded_a: Vec<f64>,
}

/// Generate `n` samples at step `dt_s` of the current of `lp`.
pub fn generate(lp: &CurrentLoop, n: usize, dt_s: f64, rng: &mut ChaCha8Rng) -> CurrentSeries {
    let p_switch = (lp.switches_per_hour / 3600.0 * dt_s).min(1.0);
    let mut on: bool = rng.random_bool(0.5);
    let fluct = gauss_markov(rng, n, dt_s, lp.fluctuation_a, lp.fluctuation_tau_s);
    let mut true_a = Vec::with_capacity(n);
    let mut recorded_a = Vec::with_capacity(n);
    for f in fluct {
        if p_switch > 0.0 && rng.random_bool(p_switch) {
            on = !on;
        }
        let i = lp.mean_a + if on { lp.switched_a } else { 0.0 } + f;
        true_a.push(i);
        recorded_a.push(i + lp.channel_noise_a * normal(rng));
    }
    CurrentSeries { true_a, recorded_a }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn switching_levels_and_channel_noise() {
        let lp = CurrentLoop {
            fluctuation_a: 0.0,
            switches_per_hour: 60.0,
            ..Default::default()
        };
        let s = generate(&lp, 36_000, 0.1, &mut rng_for(4, Stream::Currents));
        // only two levels, and both occur within an hour at 60 switches/hour
        assert!(
            s.true_a
                .iter()
                .all(|&i| i == lp.mean_a || i == lp.mean_a + lp.switched_a)
        );
        assert!(s.true_a.contains(&lp.mean_a));
        assert!(s.true_a.contains(&(lp.mean_a + lp.switched_a)));
        let noise: f64 = s
            .true_a
            .iter()
            .zip(&s.recorded_a)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / 36_000.0;
        assert!((noise.sqrt() / lp.channel_noise_a - 1.0).abs() < 0.03);
    }
}

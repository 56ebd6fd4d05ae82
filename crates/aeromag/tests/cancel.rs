//! Cancelling a long workflow through its observer
//! ([`aeromag::Observer::cancelled`]): the Kalman calibration and minimum
//! curvature gridding stop at the next check with the cancelled error (not
//! bad input), and give the same result to the bit when asked but never
//! told to stop.

use aeromag::map::{GridOptions, grid_flight};
use aeromag::prelude::*;
use aeromag::simulate::{ScenarioKind, simulate_flight};

/// Says to stop from its `limit + 1`-th question on, and counts what the
/// workflow does after that.
struct StopAfter {
    limit: usize,
    asked: usize,
    /// Questions, stages and progress calls after the first `true`.
    after: usize,
}

impl StopAfter {
    fn new(limit: usize) -> Self {
        Self {
            limit,
            asked: 0,
            after: 0,
        }
    }

    fn stopped(&self) -> bool {
        self.asked > self.limit
    }
}

impl Observer for StopAfter {
    fn stage(&mut self, _name: &str) {
        if self.stopped() {
            self.after += 1;
        }
    }
    fn progress(&mut self, _done: u64, _total: u64) {
        if self.stopped() {
            self.after += 1;
        }
    }
    fn cancelled(&mut self) -> bool {
        if self.stopped() {
            self.after += 1;
        }
        self.asked += 1;
        self.stopped()
    }
}

/// Runs `work` with an observer that never stops it (the result must be
/// `plain`'s, and the questions are counted), then with observers that stop
/// it after a quarter, half and all but one of those questions.
fn stops_promptly<T: std::fmt::Debug>(
    plain: &T,
    work: impl Fn(&mut dyn Observer) -> aeromag::Result<T>,
) {
    let mut never = StopAfter::new(usize::MAX);
    let asked = work(&mut never).unwrap();
    assert_eq!(
        format!("{asked:?}"),
        format!("{plain:?}"),
        "asking changed the result"
    );
    let total = never.asked;
    assert!(total >= 20, "asked only {total} times");
    for limit in [total / 4, total / 2, total - 1] {
        let mut obs = StopAfter::new(limit);
        let e = work(&mut obs).unwrap_err();
        assert!(e.is_cancelled(), "{e}");
        assert!(!e.is_bad_input(), "{e}");
        assert_eq!(e.to_string(), "cancelled");
        assert_eq!(
            obs.asked,
            limit + 1,
            "went on asking after the first `true`"
        );
        assert_eq!(obs.after, 0, "went on after being told to stop");
    }
}

#[test]
fn a_kalman_calibration_stops_when_its_observer_says_so() {
    let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1)).unwrap();
    let opts = CalibrateOptions::kalman();
    let plain = calibrate(&cal, &opts, &mut Silent).unwrap();
    stops_promptly(&plain.model, |obs| {
        calibrate(&cal, &opts, obs).map(|c| c.model)
    });
}

#[test]
fn minimum_curvature_gridding_stops_when_its_observer_says_so() {
    let pattern = "[pattern]\nline_count = 10\nline_length_m = 5000.0\ntie_count = 3\n";
    let survey = simulate_flight(ScenarioKind::Survey, Some(pattern), Some(11)).unwrap();
    let opts = GridOptions {
        column: Some("true_anomaly".into()),
        cell_m: Some(50.0),
        ..GridOptions::default()
    };
    let plain = grid_flight(&survey, &opts, &mut Silent).unwrap();
    stops_promptly(&plain.grid.values, |obs| {
        grid_flight(&survey, &opts, obs).map(|g| g.grid.values)
    });
}

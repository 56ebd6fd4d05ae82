//! Method 2 (Kalman) against Method 1 (band-pass least squares) on the
//! simulator: calibrate on the calibration box, compensate an independent
//! survey flight, compare with the truth.

use aeromag_compensation::kalman::{fit_kalman, ground_speed_from_velocity, KalmanConfig, KalmanFit, KalmanSegment};
use aeromag_compensation::metrics::residual_by_line;
use aeromag_compensation::tolles_lawson::design::interference;
use aeromag_compensation::tolles_lawson::fit_ls::{fit_band_pass_ls, LsConfig, LsFit, Segment};
use aeromag_compensation::tolles_lawson::segments::split_segments;
use aeromag_compensation::tolles_lawson::{Convention, TermSet, DEFAULT_BT_SCALE_NT};
use aeromag_sim::{simulate, ScenarioKind, Simulation};
use std::ops::Range;

fn col<'a>(s: &'a Simulation, name: &str) -> &'a [f64] {
    s.column(name).unwrap_or_else(|| panic!("simulator column {name}"))
}

struct Flight<'a> {
    sim: &'a Simulation,
    speed: Vec<f64>,
}

impl<'a> Flight<'a> {
    fn new(sim: &'a Simulation) -> Self {
        Self { speed: ground_speed_from_velocity(col(sim, "vn"), col(sim, "ve")), sim }
    }
    fn usable(&self) -> Vec<bool> {
        vec![true; self.sim.n_rows()]
    }
    fn segment(&self, r: Range<usize>) -> Segment<'_> {
        let s = self.sim;
        Segment {
            time: &col(s, "time")[r.clone()],
            flux: [&col(s, "flux_x")[r.clone()], &col(s, "flux_y")[r.clone()], &col(s, "flux_z")[r.clone()]],
            mag: &col(s, "mag")[r],
        }
    }
    fn kalman_segment(&self, r: Range<usize>) -> KalmanSegment<'_> {
        KalmanSegment { data: self.segment(r.clone()), alt_m: &col(self.sim, "alt")[r.clone()], speed_m_s: &self.speed[r] }
    }
    /// Legs split at line changes (the least-squares practice).
    fn legs(&self) -> Vec<Range<usize>> {
        split_segments(col(self.sim, "time"), Some(col(self.sim, "line")), &self.usable(), 1.5, 1).0
    }
    /// Contiguous stretches (split only at time gaps).
    fn contiguous(&self) -> Vec<Range<usize>> {
        split_segments(col(self.sim, "time"), None, &self.usable(), 1.5, 1).0
    }
}

fn ls_fit(cal: &Flight) -> LsFit {
    let legs = cal.legs();
    let segs: Vec<Segment> = legs.iter().map(|r| cal.segment(r.clone())).collect();
    fit_band_pass_ls(&segs, &LsConfig::default()).expect("LS fit")
}

fn kalman_fit(cal: &Flight, cfg: &KalmanConfig) -> KalmanFit {
    let runs = cal.contiguous();
    let segs: Vec<KalmanSegment> = runs.iter().map(|r| cal.kalman_segment(r.clone())).collect();
    fit_kalman(&segs, cfg).expect("Kalman fit")
}

/// Survey residuals of a coefficient set: (RMS of `mag − interference −
/// true_external`, RMS of `true_interf − interference`), per survey/tie line
/// with the line mean removed, pooled.
fn survey_error(survey: &Flight, coef: &[f64]) -> (f64, f64) {
    let s = survey.sim;
    let line = col(s, "line");
    let terms = TermSet::observable16();
    let n = s.n_rows();
    let mut model = vec![f64::NAN; n];
    let legs: Vec<Range<usize>> = survey.legs().into_iter().filter(|r| line[r.start] != 0.0).collect();
    for r in &legs {
        let seg = survey.segment(r.clone());
        let a = interference(&terms, Convention::Physical, DEFAULT_BT_SCALE_NT, coef, seg.time, seg.flux);
        model[r.clone()].copy_from_slice(&a);
    }
    let mag = col(s, "mag");
    let comp: Vec<f64> = (0..n).map(|i| mag[i] - model[i]).collect();
    let (_, total) = residual_by_line(&comp, col(s, "true_external"), Some(line), &legs);
    let (_, interf) = residual_by_line(col(s, "true_interf"), &model, Some(line), &legs);
    (total, interf)
}

const REALISTIC: &str = "[anomaly]\narea = \"realistic\"\n";

#[test]
#[ignore]
fn explore() {
    let survey_sim = simulate(ScenarioKind::Survey, None, Some(11)).unwrap();
    let survey = Flight::new(&survey_sim);
    for (label, toml) in [("quiet", None), ("realistic", Some(REALISTIC))] {
        let cal_sim = simulate(ScenarioKind::Calibration, toml, Some(7)).unwrap();
        let cal = Flight::new(&cal_sim);
        let t0 = std::time::Instant::now();
        let ls = ls_fit(&cal);
        let t1 = t0.elapsed();
        let kf = kalman_fit(&cal, &KalmanConfig::default());
        let t2 = t0.elapsed() - t1;
        let (ls_tot, ls_int) = survey_error(&survey, &ls.coef);
        let (kf_tot, kf_int) = survey_error(&survey, &kf.coef);
        println!("== {label}: LS {t1:?}, Kalman {t2:?}");
        println!("   LS     survey residual {ls_tot:.4} nT, interference error {ls_int:.4} nT");
        println!("   Kalman survey residual {kf_tot:.4} nT, interference error {kf_int:.4} nT");
        println!("   noise {:?}", kf.noise);
        println!("   tuning {:?}", kf.tuning);
        println!("   NIV {:.3}, innov rms {:.4}, resid {:.4}, z0 {:.1}", kf.normalized_innovation_variance, kf.innovation_rms_nt, kf.residual_rms_nt, kf.z0_m);
        println!("   warnings {:?}", kf.warnings);
        for j in 0..kf.coef.len() {
            println!("   {:6} LS {:10.4} ± {:8.4}   KF {:10.4} ± {:8.4}", kf.names[j], ls.coef[j], ls.std[j], kf.coef[j], kf.std[j]);
        }
    }
}

#[test]
#[ignore]
fn explore_q1() {
    use aeromag_compensation::kalman::{JointFilter, NoiseModel, X2Prior, TuningConfig};
    let survey_sim = simulate(ScenarioKind::Survey, None, Some(11)).unwrap();
    let survey = Flight::new(&survey_sim);
    for (label, toml) in [("quiet", None), ("realistic", Some(REALISTIC))] {
        let cal_sim = simulate(ScenarioKind::Calibration, toml, Some(7)).unwrap();
        let cal = Flight::new(&cal_sim);
        // Likelihood of the true external field alone under the field model.
        let t = col(&cal_sim, "time");
        let ext = col(&cal_sim, "true_external");
        let alt = col(&cal_sim, "alt");
        let ym = ext.iter().sum::<f64>() / ext.len() as f64;
        let z0 = alt.iter().sum::<f64>() / alt.len() as f64;
        for q1 in [1e-18, 1e-16, 1e-14, 1e-12, 1e-10] {
            let mut f = JointFilter::new(&[], &[], &X2Prior::default(), NoiseModel { q1_nt2_per_m5: q1, q2_nt2_per_m5: 1e-16, r_nt2: 1e-6 }).unwrap();
            f.start_run().unwrap();
            let mut ll = 0.0;
            for k in 0..t.len() {
                let d = if k == 0 { 0.0 } else { 0.5 * (cal.speed[k] + cal.speed[k - 1]) * (t[k] - t[k - 1]) };
                ll += f.step(d, &[], alt[k] - z0, ext[k] - ym).unwrap().log_likelihood();
            }
            println!("{label}: true field alone, q1 {q1:e}: ll {ll:.1}");
        }
        let ls = ls_fit(&cal);
        println!("{label}: LS interference error {:.4}", survey_error(&survey, &ls.coef).1);
        for q1 in [1e-18, 1e-17, 1e-16, 1e-15, 1e-14, 1e-13, 1e-12, 1e-11, 1e-10] {
            for r in [2.3e-4, 1e-3] {
                let cfg = KalmanConfig { noise: NoiseModel { q1_nt2_per_m5: q1, q2_nt2_per_m5: 1e-16, r_nt2: r }, tuning: TuningConfig { enabled: false, ..Default::default() }, ..Default::default() };
                let kf = kalman_fit(&cal, &cfg);
                let (tot, int) = survey_error(&survey, &kf.coef);
                println!("{label}: q1 {q1:e} r {r:e}: survey {tot:.4} interf {int:.4}  ll {:.1} NIV {:.3} p_z {:.2}±{:.2}", kf.log_likelihood, kf.normalized_innovation_variance, kf.coef[2], kf.std[2]);
            }
        }
    }
}

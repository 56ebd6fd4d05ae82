use aeromag_compensation::levelling::*;
use aeromag_sim::{ScenarioKind, simulate};

fn col<'a>(sim: &'a aeromag_sim::Simulation, name: &str) -> &'a [f64] { sim.column(name).unwrap() }

fn interp(x: &[f64], s: &CrossoverSide) -> f64 { x[s.row] + s.fraction * (x[s.row + 1] - x[s.row]) }

#[test]
fn explore() {
    let sim = simulate(ScenarioKind::Survey, None, Some(7)).unwrap();
    let n = sim.n_rows();
    let c = |s: &str| col(&sim, s);
    let value: Vec<f64> = (0..n).map(|i| c("mag")[i] - c("true_interf")[i] - c("diurnal")[i] - c("igrf")[i]).collect();
    let [la, lo, al] = sensor_positions(c("lat"), c("lon"), c("alt"), c("roll"), c("pitch"), c("yaw"), [-9.5, 0.0, -0.6]).unwrap();
    let tracks = SurveyTracks { time: c("time"), lat: &la, lon: &lo, alt: &al, line: c("line"), value: &value };
    let fit = fit_levelling(&find_crossovers(&tracks, &track_derivative(&tracks, &TrackConfig::default()).unwrap(), &TrackConfig::default()).unwrap().crossovers, &LevellingConfig::default()).unwrap();
    eprintln!("k = {} ± {}, rms {} -> {}", fit.k_s, fit.k_std_s, fit.rms_before_nt, fit.rms_after_nt);
    let cfg = TrackConfig::default();
    let d = track_derivative(&tracks, &cfg).unwrap();
    let set = find_crossovers(&tracks, &d, &cfg).unwrap();
    // derivative of truth pieces
    let ext: Vec<f64> = (0..n).map(|i| c("true_external")[i] - c("true_diurnal")[i] - c("true_igrf")[i]).collect();
    let tr2 = SurveyTracks { value: &ext, ..tracks };
    let dext = track_derivative(&tr2, &cfg).unwrap();
    let tr3 = SurveyTracks { value: c("true_interf"), ..tracks };
    let dint = track_derivative(&tr3, &cfg).unwrap();
    let rms = |v: &[f64]| (v.iter().filter(|x| x.is_finite()).map(|x| x * x).sum::<f64>() / v.iter().filter(|x| x.is_finite()).count() as f64).sqrt();
    eprintln!("rms dvalue {:.3} dext {:.3} dinterf {:.3} nT/s", rms(&d), rms(&dext), rms(&dint));
    eprintln!("   d      | ext(anom) igrf   diurn  | lag     -tau*dB  heading noise | dB_a    dB_b  dI_a dI_b  dalt_true  dalt_sensor");
    for x in &set.crossovers {
        let g = |name: &str| interp(c(name), &x.a) - interp(c(name), &x.b);
        let dd = x.difference_nt();
        eprintln!("{:+.3} | {:+.3} {:+.3} {:+.3} {:+.3} | {:+.3} {:+.3} {:+.3} {:+.3} | {:+.2} {:+.2} {:+.2} {:+.2} | {:+.2} {:+.2}",
            dd, g("true_anomaly"), g("true_igrf") - g("igrf"), g("true_diurnal") - g("diurnal"), g("true_external") - g("true_external"),
            g("true_lag"), -0.1 * (x.a.derivative_nt_per_s - x.b.derivative_nt_per_s), g("true_heading_error"), g("true_mag_noise"),
            x.a.derivative_nt_per_s, x.b.derivative_nt_per_s, interp(&dint, &x.a), interp(&dint, &x.b), g("true_sensor_alt"), g("alt"));
    }
}

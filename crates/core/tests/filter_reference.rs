//! Filters and spectra against SciPy reference output.
//!
//! The JSON files in `tests/data/filter_*.json` are written by
//! `tools/reference/filter_reference.py` (SciPy 1.17, seeded numpy signals).
//! Every test prints the largest error it measured (`cargo test -- --nocapture`).
//!
//! Error measure: for a vector, `max_i |ours_i − ref_i| / max_i |ref_i|`
//! (relative to the vector's largest magnitude, so that zero crossings of a
//! filtered signal and the exact zeros of band-pass numerators do not blow
//! up a per-element ratio). For second-order sections it is taken per section
//! (row), so the tiny overall gain carried by the first section is judged
//! on its own scale.

use aeromag_core::CoreError;
use aeromag_core::filter::{
    Band, Sos, Symmetry, TransferFunction, Window, butter, filtfilt, firwin_lowpass, lfilter,
    lfilter_zi, sosfilt, sosfiltfilt, sosfiltfilt_in_place,
};
use aeromag_core::spectrum::{Detrend, Scaling, WelchConfig, welch};
use serde_json::Value;

fn load(name: &str) -> Value {
    let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn vecf(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn sections(v: &Value) -> Vec<[f64; 6]> {
    v.as_array()
        .expect("sos")
        .iter()
        .map(|row| {
            let r = vecf(row);
            [r[0], r[1], r[2], r[3], r[4], r[5]]
        })
        .collect()
}

/// `max |a − b| / max |b|` (0 when both are all zero).
fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "length mismatch");
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if scale == 0.0 { diff } else { diff / scale }
}

fn usize_of(v: &Value) -> usize {
    v.as_u64().expect("integer") as usize
}

fn band_of(case: &Value) -> Band {
    let f = vecf(&case["band"]);
    match case["kind"].as_str().expect("kind") {
        "lowpass" => Band::Lowpass { cutoff_hz: f[0] },
        "highpass" => Band::Highpass { cutoff_hz: f[0] },
        "bandpass" => Band::Bandpass {
            low_hz: f[0],
            high_hz: f[1],
        },
        "bandstop" => Band::Bandstop {
            low_hz: f[0],
            high_hz: f[1],
        },
        k => panic!("unknown kind {k}"),
    }
}

fn window_of(v: &Value) -> Window {
    let (name, param) = match v {
        Value::String(s) => (s.as_str(), f64::NAN),
        Value::Array(a) => (a[0].as_str().expect("name"), a[1].as_f64().expect("param")),
        _ => panic!("window spec {v}"),
    };
    match name {
        "boxcar" => Window::Rectangular,
        "hann" => Window::Hann,
        "hamming" => Window::Hamming,
        "blackman" => Window::Blackman,
        "blackmanharris" => Window::BlackmanHarris,
        "nuttall" => Window::Nuttall,
        "chebwin" => Window::Chebyshev {
            attenuation_db: param,
        },
        "kaiser" => Window::Kaiser { beta: param },
        n => panic!("unknown window {n}"),
    }
}

#[test]
fn butter_sos_matches_scipy() {
    let data = load("filter_butter.json");
    let cases = data["cases"].as_array().unwrap();
    let mut worst = 0.0f64;
    for case in cases {
        let order = usize_of(&case["order"]);
        let fs = case["fs"].as_f64().unwrap();
        let reference = Sos::new(sections(&case["sos"])).unwrap();
        let ours = butter(order, band_of(case), fs).unwrap();
        assert_eq!(ours.n_sections(), reference.n_sections(), "{case:?}");
        // the zero pattern decides sosfiltfilt's pad length
        assert_eq!(
            ours.padlen(),
            reference.padlen(),
            "order {order} {}",
            case["kind"]
        );
        for (a, b) in ours.sections().iter().zip(reference.sections()) {
            let e = rel_err(a, b);
            worst = worst.max(e);
            assert!(
                e <= 1e-12,
                "order {order} {} band {}: section error {e:e}",
                case["kind"],
                case["band"]
            );
        }
    }
    println!(
        "butter: {} designs, max section relative error {worst:.3e}",
        cases.len()
    );
}

/// `f()` with each copy of the kernels this processor has (plain, AVX,
/// AVX with fused multiply-adds: `aeromag_core::simd`).
fn at_every_level(f: impl Fn()) {
    for level in aeromag_core::simd::LEVELS {
        if level.available() {
            println!("kernels: {level:?}");
            aeromag_core::simd::with_level(level, &f);
        }
    }
}

#[test]
fn sosfiltfilt_matches_scipy() {
    at_every_level(sosfiltfilt_cases);
}

fn sosfiltfilt_cases() {
    let data = load("filter_zero_phase.json");
    let cases = data["sosfiltfilt"].as_array().unwrap();
    let mut worst = 0.0f64;
    for case in cases {
        let sos = Sos::new(sections(&case["sos"])).unwrap();
        let padlen = usize_of(&case["padlen"]);
        assert_eq!(sos.padlen(), padlen);
        let x = vecf(&case["x"]);
        let y = vecf(&case["y"]);
        let ours = sosfiltfilt(&sos, &x).unwrap();
        let e = rel_err(&ours, &y);
        worst = worst.max(e);
        println!(
            "  n = {:5} sections = {:2}: {e:.3e}",
            x.len(),
            sos.n_sections()
        );
        assert!(
            e <= 1e-9,
            "n = {} sections = {}: error {e:e}",
            x.len(),
            sos.n_sections()
        );
        let mut inplace = x.clone();
        sosfiltfilt_in_place(&sos, &mut inplace).unwrap();
        assert_eq!(inplace, ours);
        // one sample fewer than SciPy's minimum is refused, naming the minimum
        assert_eq!(
            sosfiltfilt(&sos, &x[..padlen]),
            Err(CoreError::TooShort {
                name: "x",
                len: padlen,
                min: padlen + 1
            })
        );
    }
    println!(
        "sosfiltfilt: {} cases, max relative error {worst:.3e}",
        cases.len()
    );
}

#[test]
fn sosfiltfilt_of_our_design_matches_scipy() {
    at_every_level(our_design_cases);
}

fn our_design_cases() {
    // End to end: our butter() + sosfiltfilt() against SciPy's butter + sosfiltfilt
    // for the compensation band-pass (order 4, 0.1–0.9 Hz at 10 Hz).
    let data = load("filter_zero_phase.json");
    let sos = butter(
        4,
        Band::Bandpass {
            low_hz: 0.1,
            high_hz: 0.9,
        },
        10.0,
    )
    .unwrap();
    let mut worst = 0.0f64;
    let mut n_cases = 0;
    for case in data["sosfiltfilt"].as_array().unwrap() {
        let reference = Sos::new(sections(&case["sos"])).unwrap();
        if reference.n_sections() != sos.n_sections()
            || rel_err(&reference.sections().concat(), &sos.sections().concat()) > 1e-6
        {
            continue;
        }
        n_cases += 1;
        let e = rel_err(
            &sosfiltfilt(&sos, &vecf(&case["x"])).unwrap(),
            &vecf(&case["y"]),
        );
        worst = worst.max(e);
        assert!(e <= 1e-9, "error {e:e}");
    }
    assert!(n_cases >= 5);
    println!("butter+sosfiltfilt (4, 0.1–0.9 Hz): {n_cases} cases, max relative error {worst:.3e}");
}

#[test]
fn filtfilt_matches_scipy() {
    let data = load("filter_zero_phase.json");
    let cases = data["filtfilt"].as_array().unwrap();
    let mut worst = 0.0f64;
    for case in cases {
        let (b, a) = (vecf(&case["b"]), vecf(&case["a"]));
        let padlen = usize_of(&case["padlen"]);
        assert_eq!(
            TransferFunction::new(b.clone(), a.clone())
                .unwrap()
                .padlen(),
            padlen
        );
        let x = vecf(&case["x"]);
        let ours = filtfilt(&b, &a, &x).unwrap();
        let e = rel_err(&ours, &vecf(&case["y"]));
        worst = worst.max(e);
        assert!(
            e <= 1e-9,
            "b = {b:?} a = {a:?} n = {}: error {e:e}",
            x.len()
        );
        assert!(matches!(
            filtfilt(&b, &a, &x[..padlen]),
            Err(CoreError::TooShort { min, .. }) if min == padlen + 1
        ));
    }
    println!(
        "filtfilt: {} cases, max relative error {worst:.3e}",
        cases.len()
    );
}

#[test]
fn one_way_filters_and_initial_conditions_match_scipy() {
    let data = load("filter_zero_phase.json");
    let worst_sos = std::cell::Cell::new(0.0f64);
    at_every_level(|| {
        for case in data["sosfilt"].as_array().unwrap() {
            let sos = Sos::new(sections(&case["sos"])).unwrap();
            let e = rel_err(
                &sosfilt(&sos, &vecf(&case["x"])).unwrap(),
                &vecf(&case["y"]),
            );
            worst_sos.set(worst_sos.get().max(e));
            assert!(e <= 1e-12, "sosfilt error {e:e}");
        }
    });
    let worst_sos = worst_sos.get();
    let mut worst_lf = 0.0f64;
    for case in data["lfilter"].as_array().unwrap() {
        let tf = TransferFunction::new(vecf(&case["b"]), vecf(&case["a"])).unwrap();
        let e = rel_err(&lfilter(&tf, &vecf(&case["x"])).unwrap(), &vecf(&case["y"]));
        worst_lf = worst_lf.max(e);
        assert!(e <= 1e-12, "lfilter error {e:e}");
    }
    let mut worst_zi = 0.0f64;
    for case in data["zi"].as_array().unwrap() {
        let (ours, reference) = if case.get("sos").is_some() {
            let sos = Sos::new(sections(&case["sos"])).unwrap();
            let r: Vec<f64> = case["zi"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(vecf)
                .collect();
            (sos.zi().unwrap().concat(), r)
        } else {
            (
                lfilter_zi(&vecf(&case["b"]), &vecf(&case["a"])).unwrap(),
                vecf(&case["zi"]),
            )
        };
        let e = rel_err(&ours, &reference);
        worst_zi = worst_zi.max(e);
        assert!(e <= 1e-12, "zi error {e:e}");
    }
    println!(
        "sosfilt max rel error {worst_sos:.3e}; lfilter {worst_lf:.3e}; sosfilt_zi/lfilter_zi {worst_zi:.3e}"
    );
}

#[test]
fn windows_match_scipy() {
    let data = load("filter_windows.json");
    let cases = data["windows"].as_array().unwrap();
    let (mut worst_cos, mut worst_cheb, mut worst_kaiser) = (0.0f64, 0.0f64, 0.0f64);
    for case in cases {
        let window = window_of(&case["window"]);
        let len = usize_of(&case["len"]);
        let sym = if case["sym"].as_bool().unwrap() {
            Symmetry::Symmetric
        } else {
            Symmetry::Periodic
        };
        let ours = window.samples(len, sym).unwrap();
        let e = rel_err(&ours, &vecf(&case["w"]));
        let (tol, worst) = match window {
            Window::Chebyshev { .. } => (1e-9, &mut worst_cheb),
            Window::Kaiser { .. } => (1e-12, &mut worst_kaiser),
            _ => (1e-12, &mut worst_cos),
        };
        *worst = worst.max(e);
        assert!(e <= tol, "{window:?} len {len} {sym:?}: error {e:e}");
    }
    println!(
        "windows: {} cases; max relative error cosine-sum {worst_cos:.3e}, chebwin {worst_cheb:.3e}, kaiser {worst_kaiser:.3e}",
        cases.len()
    );
}

#[test]
fn firwin_matches_scipy() {
    let data = load("filter_windows.json");
    let cases = data["firwin"].as_array().unwrap();
    let mut worst = 0.0f64;
    for case in cases {
        let numtaps = usize_of(&case["numtaps"]);
        let ours = firwin_lowpass(
            numtaps,
            case["cutoff"].as_f64().unwrap(),
            case["fs"].as_f64().unwrap(),
            window_of(&case["window"]),
        )
        .unwrap();
        let e = rel_err(&ours, &vecf(&case["h"]));
        worst = worst.max(e);
        assert!(
            e <= 1e-12,
            "numtaps {numtaps} {}: error {e:e}",
            case["window"]
        );
    }
    println!(
        "firwin: {} designs, max relative error {worst:.3e}",
        cases.len()
    );
}

#[test]
fn welch_matches_scipy() {
    let data = load("filter_welch.json");
    let cases = data["cases"].as_array().unwrap();
    let (mut worst_p, mut worst_f) = (0.0f64, 0.0f64);
    for case in cases {
        let x = vecf(&data["signals"][case["signal"].as_str().unwrap()]);
        let cfg = WelchConfig {
            fs_hz: case["fs"].as_f64().unwrap(),
            nperseg: usize_of(&case["nperseg"]),
            noverlap: usize_of(&case["noverlap"]),
            nfft: usize_of(&case["nfft"]),
            window: window_of(&case["window"]),
            detrend: match case["detrend"].as_str().unwrap() {
                "none" => Detrend::None,
                "constant" => Detrend::Constant,
                "linear" => Detrend::Linear,
                d => panic!("detrend {d}"),
            },
            scaling: match case["scaling"].as_str().unwrap() {
                "density" => Scaling::Density,
                "spectrum" => Scaling::Spectrum,
                s => panic!("scaling {s}"),
            },
        };
        let psd = welch(&x, &cfg).unwrap();
        let ef = rel_err(&psd.freqs_hz, &vecf(&case["f"]));
        let ep = rel_err(&psd.values, &vecf(&case["p"]));
        worst_f = worst_f.max(ef);
        worst_p = worst_p.max(ep);
        assert!(ef <= 1e-15, "{cfg:?}: frequency error {ef:e}");
        assert!(ep <= 1e-9, "{cfg:?}: PSD error {ep:e}");
    }
    println!(
        "welch: {} cases, max relative error PSD {worst_p:.3e}, frequencies {worst_f:.3e}",
        cases.len()
    );
}

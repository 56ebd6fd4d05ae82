//! Writes a sample report with a line plot, a log–log spectrum and a heatmap
//! to `/tmp/aeromag-report-sample/` (or the folder given as first argument):
//! `index.html` plus the plots as SVG and PNG.
//!
//! ```text
//! cargo run -p aeromag-report --example sample_report [-- OUT_DIR]
//! ```
//!
//! The data are synthetic and deterministic (sums of sines, a dipole
//! anomaly); they only exercise the plotting code.

use std::f64::consts::PI;
use std::path::PathBuf;

use aeromag_report::{Colormap, Heatmap, LinePlot, Report, Rgb, Series, Table};

/// Deterministic broadband "noise": a sum of incommensurate sines.
fn wiggle(t: f64) -> f64 {
    [
        (1.7, 0.3),
        (5.3, 1.1),
        (11.9, 2.3),
        (23.1, 0.7),
        (47.3, 1.9),
    ]
    .iter()
    .enumerate()
    .map(|(k, (f, p))| (2.0 * PI * f * t + p).sin() / (k as f64 + 1.0))
    .sum()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out: PathBuf = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/tmp/aeromag-report-sample"));

    // 1. Time series at 10 Hz for 10 minutes, with a data gap.
    let n = 6000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
    let interference: Vec<f64> = t
        .iter()
        .map(|&t| {
            4.0 * (2.0 * PI * t / 60.0).sin() + 1.5 * (2.0 * PI * t / 9.0).sin() + 0.3 * wiggle(t)
        })
        .collect();
    let compensated: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            if (2500..2700).contains(&i) {
                f64::NAN
            } else {
                0.08 * wiggle(0.5 * t) + 0.04 * wiggle(1.37 * t + 0.2)
            }
        })
        .collect();
    let line_numbers: Vec<f64> = t.iter().map(|&t| -6.0 + (t / 150.0).floor()).collect();
    let series_plot = LinePlot::new(
        "Compensation flight: total-field residual",
        "time (s)",
        "residual (nT)",
    )
    .with_series(Series::line("uncompensated", t.clone(), interference))
    .with_series(Series::line("compensated (LS)", t.clone(), compensated))
    .with_series(
        Series::step("line number − 6", t.clone(), line_numbers).with_color(Rgb(0x77, 0x77, 0x77)),
    );

    // 2. PSD on log-log axes: 1/f² + white floor + a rotor line; DC bin is 0.
    let fs = 10.0;
    let nf = 2049;
    let f: Vec<f64> = (0..nf)
        .map(|k| k as f64 * fs / 2.0 / (nf - 1) as f64)
        .collect();
    let psd = |red: f64, floor: f64, line: f64| -> Vec<f64> {
        f.iter()
            .map(|&f| {
                if f == 0.0 {
                    0.0
                } else {
                    red / (f * f) + floor + line * (-((f - 2.2) / 0.03).powi(2)).exp()
                }
            })
            .collect()
    };
    let psd_before = psd(2e-2, 1e-3, 0.5);
    let psd_after = psd(2e-5, 1e-4, 0.002);
    let spectrum = LinePlot::new(
        "Residual spectrum (Welch, Hann, 50 % overlap)",
        "frequency (Hz)",
        "PSD (nT²/Hz)",
    )
    .with_series(Series::line("before", f.clone(), psd_before))
    .with_series(Series::line("after", f.clone(), psd_after))
    .log_log();

    // 3. Anomaly map of a buried dipole on a 120 × 80 grid.
    let (nx, ny) = (120, 80);
    let x: Vec<f64> = (0..nx).map(|i| -600.0 + 10.0 * i as f64).collect();
    let y: Vec<f64> = (0..ny).map(|j| -400.0 + 10.0 * j as f64).collect();
    let mut values = Vec::with_capacity(nx * ny);
    // Vertical dipole of moment m under (0, 50 m) at depth d: the vertical
    // field at the surface is μ0 m / (4π) · (2d² − ρ²) / r⁵ (in nT below).
    let (m, d) = (5.0e7_f64, 150.0_f64); // A·m², m
    for &yv in &y {
        for &xv in &x {
            let rho2 = xv * xv + (yv - 50.0) * (yv - 50.0);
            let r2 = rho2 + d * d;
            let v = 1e-7 * m * (2.0 * d * d - rho2) / r2.powf(2.5) * 1e9;
            values.push(if xv > 450.0 && yv < -250.0 {
                f64::NAN
            } else {
                v
            });
        }
    }
    let mut map = Heatmap::new(
        "Total-field anomaly, survey block A",
        "easting (m)",
        "northing (m)",
        x,
        y,
        values,
        "anomaly (nT)",
    );
    map.colormap = Colormap::Diverging;
    map.equal_aspect = true;

    std::fs::create_dir_all(&out)?;
    let mut report = Report::new("aeromag sample report");
    report.paragraph(
        "Synthetic data showing every element of the report: a time-series plot with a \
         data gap, a log–log spectrum whose DC bin (0 nT²/Hz) is left out, and a \
         heatmap with missing cells.",
    );
    report
        .section("Compensation")
        .key_values(vec![
            ("FOM before (nT)".into(), "9.84".into()),
            ("FOM after (nT)".into(), "0.62".into()),
            ("improvement ratio".into(), "15.9".into()),
            ("model".into(), "Tolles–Lawson, 18 terms, ridge λ = 1e-3".into()),
        ])
        .figure(series_plot.to_svg()?, "Residual of the compensation flight before and after least-squares compensation; the gap at 250–270 s is a dropout flagged by the QC.")
        .table(Table::new(
            vec!["manoeuvre".into(), "heading".into(), "rms before (nT)".into(), "rms after (nT)".into()],
            vec![
                vec!["roll ±10°".into(), "N".into(), "3.41".into(), "0.071".into()],
                vec!["pitch ±5°".into(), "E".into(), "2.87".into(), "0.064".into()],
                vec!["yaw ±5°".into(), "S".into(), "1.95".into(), "0.058".into()],
                vec!["<script>alert('x')</script>".into(), "W".into(), "NaN".into(), "—".into()],
            ],
            "Residual rms per manoeuvre (the last row shows that user text is escaped).",
        ));
    report.section("Spectra").figure(
        spectrum.to_svg()?,
        "Power spectral density of the residual before and after compensation.",
    );
    report.section("Anomaly map").figure(
        map.to_svg()?,
        "Total-field anomaly of a vertical dipole at 150 m depth; grey cells have no data.",
    );
    report.write_html(out.join("index.html"))?;

    for (name, svg) in [
        ("residual", series_plot.to_svg()?),
        ("spectrum", spectrum.to_svg()?),
        ("anomaly", map.to_svg()?),
    ] {
        std::fs::write(out.join(format!("{name}.svg")), svg)?;
    }
    series_plot.to_png(out.join("residual.png"), 1200, 660)?;
    spectrum.to_png(out.join("spectrum.png"), 1200, 660)?;
    map.to_png(out.join("anomaly.png"), 1200, 660)?;
    println!("wrote {}", out.join("index.html").display());
    Ok(())
}

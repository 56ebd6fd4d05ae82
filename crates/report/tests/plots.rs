//! Integration tests of the plots: SVG structure, gaps, log axes, decimation,
//! determinism, PNG output and error handling.

use aeromag_report::{Colormap, Heatmap, LinePlot, ReportError, Series};

/// Checks that `svg` is well-formed XML-ish markup: every element that is
/// opened is closed in the right order, and the root is `<svg>`.
fn assert_balanced(svg: &str) {
    let mut stack: Vec<String> = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unterminated tag") + start;
        let tag = &rest[start + 1..end];
        rest = &rest[end + 1..];
        if tag.starts_with('?') || tag.starts_with('!') || tag.ends_with('/') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(
                stack.pop().as_deref(),
                Some(name.trim()),
                "mismatched </{name}>"
            );
        } else {
            let name = tag.split_whitespace().next().unwrap_or("");
            if stack.is_empty() {
                assert_eq!(name, "svg", "root element");
            }
            stack.push(name.to_string());
        }
    }
    assert!(stack.is_empty(), "unclosed: {stack:?}");
}

/// Pixel coordinates of every `<polyline>` whose attributes contain all of
/// `attrs` (e.g. the stroke colour and width of a series).
fn polylines_with(svg: &str, attrs: &[&str]) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polyline")
        .skip(1)
        .map(|el| el.split("/>").next().unwrap_or(""))
        .filter(|el| attrs.iter().all(|a| el.contains(a)))
        .map(|el| {
            let pts = el
                .split("points=\"")
                .nth(1)
                .unwrap_or("")
                .split('"')
                .next()
                .unwrap_or("");
            pts.split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect()
        })
        .collect()
}

/// Lines of the first series (first palette colour, 2 px; the legend
/// swatch is 3 px wide and is not included).
fn series_lines(svg: &str) -> Vec<Vec<(f64, f64)>> {
    polylines_with(svg, &["stroke=\"#0072B2\"", "stroke-width=\"2\""])
}

/// The frame around the plotting area: `(x0, x1)` pixel columns.
fn frame_x(svg: &str) -> (f64, f64) {
    let frame = polylines_with(svg, &["stroke=\"#555555\""])
        .into_iter()
        .find(|p| p.len() == 5)
        .expect("frame");
    (frame[0].0, frame[1].0)
}

fn ramp(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64).collect()
}

#[test]
fn svg_has_structure_names_and_labels() {
    let plot = LinePlot::new("Residual <QC>", "time (s)", "residual (nT)")
        .with_series(Series::line(
            "LS & ridge",
            ramp(50),
            ramp(50).iter().map(|v| v.sin()).collect(),
        ))
        .with_series(Series::points(
            "truth",
            ramp(50),
            ramp(50).iter().map(|v| v.cos()).collect(),
        ))
        .with_series(Series::step(
            "flag",
            ramp(50),
            ramp(50).iter().map(|v| (v / 10.0).floor()).collect(),
        ));
    let svg = plot.to_svg().unwrap();
    assert!(svg.starts_with("<svg"));
    assert_balanced(&svg);
    for text in [
        "Residual &lt;QC&gt;",
        "time (s)",
        "residual (nT)",
        "LS &amp; ridge",
        "truth",
        "flag",
    ] {
        assert!(svg.contains(text), "missing {text}");
    }
    // Text is set in the embedded face (CSS list with fallbacks).
    assert!(svg.contains("font-family=\"DejaVu Sans, Verdana, sans-serif\""));
    // Line + step → polylines, points → circles.
    assert_eq!(series_lines(&svg).len(), 1, "one unbroken line");
    assert_eq!(
        polylines_with(&svg, &["stroke=\"#009E73\"", "stroke-width=\"2\""]).len(),
        1,
        "step"
    );
    assert!(svg.matches("<circle").count() >= 50);
}

#[test]
fn nan_breaks_the_line() {
    let mut y: Vec<f64> = ramp(100).iter().map(|v| (v * 0.1).sin()).collect();
    let base = LinePlot::new("t", "x", "y").with_series(Series::line("", ramp(100), y.clone()));
    assert_eq!(series_lines(&base.to_svg().unwrap()).len(), 1);
    y[40] = f64::NAN;
    y[70] = f64::INFINITY;
    let gapped = LinePlot::new("t", "x", "y").with_series(Series::line("", ramp(100), y));
    let svg = gapped.to_svg().unwrap();
    assert_eq!(series_lines(&svg).len(), 3, "two gaps → three pieces");
    // A NaN in x is a gap too.
    let mut x = ramp(10);
    x[5] = f64::NAN;
    let svg = LinePlot::new("t", "x", "y")
        .with_series(Series::line("", x, ramp(10)))
        .to_svg()
        .unwrap();
    assert_eq!(series_lines(&svg).len(), 2);
}

#[test]
fn all_nan_is_no_data_error() {
    let plot =
        LinePlot::new("empty", "x", "y").with_series(Series::line("a", ramp(3), vec![f64::NAN; 3]));
    assert!(matches!(plot.to_svg(), Err(ReportError::NoData { .. })));
    assert!(matches!(
        LinePlot::new("none", "x", "y").to_svg(),
        Err(ReportError::NoData { .. })
    ));
}

#[test]
fn log_axes_drop_non_positive_values() {
    // DC bin 0 and a negative value on a log-log spectrum: drawn without them.
    let f = vec![0.0, 0.1, 1.0, 10.0, 100.0];
    let p = vec![5.0, 1e2, -1.0, 1e-2, 1e-4];
    let plot = LinePlot::new("PSD", "frequency (Hz)", "PSD (nT²/Hz)")
        .with_series(Series::line("psd", f, p))
        .log_log();
    let svg = plot.to_svg().unwrap();
    assert_balanced(&svg);
    // (0.1, 100) is isolated between the dropped DC bin and the negative
    // value → a dot; (10, 1e-2)–(100, 1e-4) → one polyline.
    assert_eq!(series_lines(&svg).len(), 1, "one piece");
    assert_eq!(svg.matches("<circle").count(), 1, "one isolated sample");
    // Decade labels in plain form for 0.1 … 100.
    for label in [
        "\n0.1\n</text>",
        "\n1\n</text>",
        "\n10\n</text>",
        "\n100\n</text>",
    ] {
        assert!(svg.contains(label), "missing tick label {label:?}");
    }
    // Everything non-positive → nothing to draw.
    let none =
        LinePlot::new("t", "x", "y").with_series(Series::line("", vec![1.0, 2.0], vec![0.0, -1.0]));
    let mut none = none;
    none.log_y = true;
    assert!(matches!(none.to_svg(), Err(ReportError::NoData { .. })));
    // A fixed log range must be positive.
    let mut bad = plot.clone();
    bad.x_range = Some((0.0, 10.0));
    assert!(matches!(
        bad.to_svg(),
        Err(ReportError::InvalidRange { axis: "x", .. })
    ));
}

#[test]
fn million_points_give_a_small_svg_that_keeps_the_peaks() {
    let n = 1_000_000;
    let x = ramp(n);
    let mut y: Vec<f64> = x.iter().map(|v| (v * 1e-4).sin()).collect();
    y[333_333] = 25.0;
    y[666_667] = -30.0;
    let plot = LinePlot::new("big", "sample", "value").with_series(Series::line(
        "s",
        x.clone(),
        y.clone(),
    ));
    let svg = plot.to_svg().unwrap();
    assert!(svg.len() < 120_000, "SVG is {} bytes", svg.len());
    // The same peaks drawn from a 5-point series land on the same pixels.
    let sparse = LinePlot::new("big", "sample", "value").with_series(Series::line(
        "s",
        vec![0.0, 333_333.0, 666_667.0, (n - 1) as f64],
        vec![y[0], 25.0, -30.0, y[n - 1]],
    ));
    let extremes = |svg: &str| {
        let pts: Vec<(f64, f64)> = series_lines(svg).into_iter().flatten().collect();
        let top = pts.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let bottom = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        (top, bottom)
    };
    assert_eq!(extremes(&svg), extremes(&sparse.to_svg().unwrap()));
}

#[test]
fn output_is_deterministic() {
    let make = || {
        LinePlot::new("d", "x", "y").with_series(Series::line(
            "a",
            ramp(2000),
            ramp(2000).iter().map(|v| (v * 0.01).sin()).collect(),
        ))
    };
    assert_eq!(make().to_svg().unwrap(), make().to_svg().unwrap());
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    make().to_png(&a, 640, 360).unwrap();
    make().to_png(&b, 640, 360).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn png_is_written_with_requested_size() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sub/folder/plot.png");
    LinePlot::new("p", "x", "y")
        .with_series(Series::line("a", ramp(10), ramp(10)))
        .to_png(&path, 640, 360)
        .unwrap();
    let png = std::fs::read(&path).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&png[16..24], &[0, 0, 2, 128, 0, 0, 1, 104]);
    let err = LinePlot::new("p", "x", "y")
        .with_series(Series::line("a", ramp(10), ramp(10)))
        .to_png(&path, 10, 10);
    assert!(matches!(
        err,
        Err(ReportError::InvalidSize {
            width: 10,
            height: 10
        })
    ));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let plot = LinePlot::new("p", "x", "y").with_series(Series::line("short", ramp(3), ramp(2)));
    assert!(matches!(
        plot.to_svg(),
        Err(ReportError::LengthMismatch {
            x_len: 3,
            y_len: 2,
            ..
        })
    ));
    let mut plot = LinePlot::new("p", "x", "y").with_series(Series::line("a", ramp(3), ramp(3)));
    plot.y_range = Some((1.0, 1.0));
    assert!(matches!(
        plot.to_svg(),
        Err(ReportError::InvalidRange { axis: "y", .. })
    ));
    let h = Heatmap::new("h", "x", "y", ramp(3), ramp(2), vec![0.0; 5], "v");
    assert!(matches!(
        h.to_svg(),
        Err(ReportError::ShapeMismatch {
            expected: 6,
            got: 5,
            ..
        })
    ));
    let h = Heatmap::new(
        "h",
        "x",
        "y",
        vec![0.0, 2.0, 1.0],
        ramp(2),
        vec![0.0; 6],
        "v",
    );
    assert!(matches!(
        h.to_svg(),
        Err(ReportError::InvalidGrid { axis: "x", .. })
    ));
}

#[test]
fn user_range_clips_lines() {
    let mut plot =
        LinePlot::new("zoom", "x", "y").with_series(Series::line("a", ramp(1000), ramp(1000)));
    plot.x_range = Some((100.0, 200.0));
    let svg = plot.to_svg().unwrap();
    let xs: Vec<f64> = series_lines(&svg)
        .into_iter()
        .flatten()
        .map(|p| p.0)
        .collect();
    // The zoomed line spans the plotting area from frame to frame, no more.
    let (f0, f1) = frame_x(&svg);
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (lo - f0).abs() <= 1.0 && (hi - f1).abs() <= 1.0,
        "{lo}..{hi} vs frame {f0}..{f1}"
    );
}

#[test]
fn heatmap_svg_inlines_one_png_per_raster() {
    let (nx, ny) = (40, 30);
    let values: Vec<f64> = (0..nx * ny)
        .map(|k| {
            if k == 7 {
                f64::NAN
            } else {
                ((k % nx) as f64 - 20.0) * ((k / nx) as f64)
            }
        })
        .collect();
    let mut h = Heatmap::new(
        "map",
        "easting (m)",
        "northing (m)",
        ramp(nx),
        ramp(ny),
        values,
        "anomaly (nT)",
    );
    h.colormap = Colormap::Diverging;
    h.equal_aspect = true;
    let svg = h.to_svg().unwrap();
    assert_balanced(&svg);
    assert_eq!(svg.matches("<image").count(), 2, "cells + colour bar");
    assert!(svg.contains("href=\"data:image/png;base64,iVBORw0KGgo"));
    for text in ["map", "easting (m)", "northing (m)", "anomaly (nT)"] {
        assert!(svg.contains(text), "missing {text}");
    }
    assert!(svg.len() < 40_000, "{} bytes", svg.len());
    // Equal aspect: the cell image is 40 × 30 units → width/height = 4/3.
    let el = svg.split("<image").nth(1).unwrap();
    let attr = |name: &str| -> f64 {
        el.split(&format!(" {name}=\""))
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let ratio = attr("width") / attr("height");
    assert!((ratio - 4.0 / 3.0).abs() < 0.01, "aspect {ratio}");
}

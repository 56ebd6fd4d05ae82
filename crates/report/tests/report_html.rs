//! Integration tests of the HTML report: snapshot, escaping, determinism,
//! self-containment and file writing.

use aeromag_report::{LinePlot, Report, Series, Table};

/// A hand-written figure keeps the snapshot small and independent of the
/// plot renderer.
const TINY_SVG: &str = "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"20\" height=\"10\"><rect width=\"20\" height=\"10\" fill=\"#0072b2\"/></svg>";

fn small_report() -> Report {
    let mut r = Report::new("Calibration flight 2024-05-17");
    r.paragraph("Compensation of the tail stinger magnetometer.");
    r.section("Figures of merit")
        .key_values(vec![
            ("FOM before (nT)".into(), "2.31".into()),
            ("FOM after (nT)".into(), "0.18".into()),
        ])
        .table(Table::new(
            vec![
                "method".into(),
                "rms (nT)".into(),
                "<script>alert(1)</script>".into(),
            ],
            vec![
                vec!["LS".into(), "0.071".into(), "a & b".into()],
                vec!["Kalman".into(), "—".into()],
            ],
            "Residuals",
        ));
    r.section("Figures of merit")
        .figure(TINY_SVG, "A <b>tiny</b> figure");
    r
}

#[test]
fn snapshot_of_small_report() {
    insta::assert_snapshot!(small_report().to_html());
}

#[test]
fn user_text_is_escaped_and_figures_are_inline() {
    let html = small_report().to_html();
    assert!(!html.contains("<script>"));
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(html.contains("a &amp; b"));
    assert!(html.contains("A &lt;b&gt;tiny&lt;/b&gt; figure"));
    // The SVG itself is inserted as markup, without its XML declaration.
    assert!(html.contains("<div class=\"plot\"><svg xmlns="));
    assert!(!html.contains("<?xml"));
}

#[test]
fn toc_links_unique_section_ids() {
    let html = small_report().to_html();
    assert!(html.contains("<a href=\"#figures-of-merit\">Figures of merit</a>"));
    assert!(html.contains("<a href=\"#figures-of-merit-2\">Figures of merit</a>"));
    assert!(html.contains("<section id=\"figures-of-merit-2\">"));
}

#[test]
fn html_is_deterministic_and_self_contained() {
    let plot = LinePlot::new("Residual", "time (s)", "residual (nT)").with_series(Series::line(
        "LS",
        (0..500).map(f64::from).collect(),
        (0..500).map(|i| f64::from(i).sin()).collect(),
    ));
    let build = || {
        let mut r = small_report();
        r.section("Plot").figure(plot.to_svg().unwrap(), "Residual");
        r.to_html()
    };
    let (a, b) = (build(), build());
    assert_eq!(a, b);
    // No external resources: nothing is fetched by src/href other than
    // in-page anchors and the SVG namespace URI.
    assert!(!a.contains("src="));
    assert!(!a.contains("<link"));
    assert!(!a.contains("url("));
    for href in a.split("href=\"").skip(1) {
        assert!(
            href.starts_with('#') || href.starts_with("data:"),
            "external href {href:.40}"
        );
    }
}

#[test]
fn write_html_creates_folders() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out/demo/index.html");
    small_report().write_html(&path).unwrap();
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        small_report().to_html()
    );
}

#[test]
fn write_html_reports_the_path_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    let err = small_report()
        .write_html(file.join("index.html"))
        .unwrap_err();
    assert!(err.to_string().contains("not-a-folder"), "{err}");
}

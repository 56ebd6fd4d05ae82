//! `aeromag inspect`: what a processor checks first in a flight file.

use crate::input::InputArgs;
use aeromag_core::error::{fixed, shown};
use aeromag_io::{Summary, summarize};

/// Summarise a flight file: columns found and mapped, rows, duration, sample
/// rate and its jitter, gaps, lines, missing values per column, and the range
/// of the field magnitude with a units plausibility check.
///
/// A grid file (`.tif`, `.asc`, `.nc`, `.grd`, `.gxf`: every format
/// `derive` reads) is summarised as a grid: nodes, cell, extent, coordinate
/// system, name and unit, the values' statistics and blanks.
///
/// Malformed files (empty, truncated rows, text in a number column, time
/// going backwards or repeated) stop with a message naming the file, line
/// and column, and exit code 2.
///
/// Example: `aeromag inspect --input flight.csv --columns mag=mag_1_uc`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let path = a.input.path();
    if let Ok(format) = aeromag::grid::format::GridFormat::from_path(path) {
        let grid = format.read(path)?;
        if a.json {
            println!("{}", serde_json::to_string_pretty(&grid_json(path, &grid))?);
        } else {
            print!("{}", render_grid(path, &grid));
        }
        return Ok(());
    }
    let table = a.input.load()?;
    let s = summarize(&table);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        print!("{}", render(&s));
    }
    Ok(())
}

/// A grid file's summary as JSON.
fn grid_json(path: &std::path::Path, g: &aeromag::grid::Grid) -> serde_json::Value {
    let geo = g.geometry;
    serde_json::json!({
        "file": path.display().to_string(),
        "nx": geo.nx,
        "ny": geo.ny,
        "cell_m": geo.cell,
        "x_m": [geo.x0, geo.x_max()],
        "y_m": [geo.y0, geo.y_max()],
        "epsg": g.crs.as_ref().map(|c| c.epsg()),
        "name": g.name,
        "unit": g.unit,
        "blank": geo.len() - g.stats().count,
        "stats": g.stats(),
    })
}

/// A grid file's human-readable summary.
fn render_grid(path: &std::path::Path, g: &aeromag::grid::Grid) -> String {
    use std::fmt::Write;
    let (geo, s) = (g.geometry, g.stats());
    let mut o = String::new();
    let _ = writeln!(o, "file     {}", path.display());
    let _ = writeln!(
        o,
        "grid     {} × {} nodes, cell {} m",
        geo.nx,
        geo.ny,
        shown(geo.cell)
    );
    let _ = writeln!(
        o,
        "extent   x {} … {} m, y {} … {} m (nodes)",
        shown(geo.x0),
        shown(geo.x_max()),
        shown(geo.y0),
        shown(geo.y_max())
    );
    let crs = g
        .crs
        .as_ref()
        .map_or("not recorded (metres assumed)".to_string(), |c| {
            format!("{} (EPSG {})", c.name(), c.epsg())
        });
    let _ = writeln!(o, "crs      {crs}");
    let unit = if g.unit.is_empty() {
        "no unit".to_string()
    } else {
        g.unit.clone()
    };
    let _ = writeln!(o, "values   {} ({unit})", g.name);
    let _ = writeln!(
        o,
        "         {} set, {} blank; mean {}, std {}, min {}, max {}",
        s.count,
        geo.len() - s.count,
        fmt_opt(Some(s.mean).filter(|v| v.is_finite())),
        fmt_opt(Some(s.std).filter(|v| v.is_finite())),
        fmt_opt(Some(s.min).filter(|v| v.is_finite())),
        fmt_opt(Some(s.max).filter(|v| v.is_finite()))
    );
    o
}

fn fmt_opt(v: Option<f64>) -> String {
    match v {
        Some(x) if x.abs() >= 1e5 || (x != 0.0 && x.abs() < 1e-3) => format!("{x:.4e}"),
        Some(x) => format!("{x:.4}"),
        None => "—".into(),
    }
}

/// The human-readable summary.
pub fn render(s: &Summary) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(o, "file     {}", s.file);
    let _ = writeln!(o, "rows     {}", s.rows);
    if let Some(t) = &s.time {
        let _ = writeln!(
            o,
            "time     {} … {} s  (duration {} s = {} h)",
            fixed(t.start_s, 3),
            fixed(t.end_s, 3),
            fixed(t.duration_s, 1),
            fixed(t.duration_s / 3600.0, 2)
        );
        let _ = writeln!(
            o,
            "sampling interval {} s, rate {} Hz, jitter std {:.2e} s (max {:.2e} s)",
            fixed(t.sample_interval_s, 6),
            fmt_opt(t.rate_hz),
            t.jitter_std_s,
            t.jitter_max_s
        );
        match (t.largest_gap_s, t.largest_gap_row) {
            (Some(g), Some(r)) => {
                let _ = writeln!(
                    o,
                    "gaps     {} longer than {} s; largest {} s before data row {}",
                    t.gaps,
                    fixed(t.gap_threshold_s, 3),
                    fixed(g, 3),
                    r + 1
                );
            }
            _ => {
                let _ = writeln!(
                    o,
                    "gaps     none longer than {} s",
                    fixed(t.gap_threshold_s, 3)
                );
            }
        }
    } else {
        // A `time` column with fewer than two finite times has no sampling.
        let time = s
            .columns
            .iter()
            .find(|c| c.name == "time" || c.canonical.as_deref() == Some("time"));
        let _ = match time.map(|c| (c.min, c.max)) {
            Some((Some(t0), Some(t1))) if t0 == t1 => writeln!(
                o,
                "time     {} s (one time only: no sampling interval)",
                fixed(t0, 3)
            ),
            Some(_) => writeln!(o, "time     no finite time: no sampling interval"),
            None => writeln!(
                o,
                "time     no `time` column (map one with --columns time=NAME)"
            ),
        };
    }
    if let Some(lines) = &s.lines {
        let shown: Vec<String> = lines
            .iter()
            .take(20)
            .map(|l| format!("{} ({} samples)", l.line, l.samples))
            .collect();
        let more = if lines.len() > 20 {
            format!(" … and {} more", lines.len() - 20)
        } else {
            String::new()
        };
        let _ = writeln!(o, "lines    {}: {}{}", lines.len(), shown.join(", "), more);
    }
    if let Some(r) = &s.mag_range_nt {
        let _ = writeln!(o, "mag      {} … {} nT", fixed(r.min, 1), fixed(r.max, 1));
    }
    if let Some(r) = &s.flux_magnitude_range_nt {
        let _ = writeln!(o, "|flux|   {} … {} nT", fixed(r.min, 1), fixed(r.max, 1));
    }
    if let Some(rows) = s.position_glitch_rows.as_ref().filter(|r| !r.is_empty()) {
        let shown: Vec<String> = rows.iter().take(10).map(|r| (r + 1).to_string()).collect();
        let more = if rows.len() > 10 {
            format!(" … and {} more", rows.len() - 10)
        } else {
            String::new()
        };
        let _ = writeln!(
            o,
            "position {} {} off the track (jumping away and back faster than {} m/s: GPS dropouts?): data {} {}{} [position-glitch]",
            rows.len(),
            if rows.len() == 1 { "row" } else { "rows" },
            aeromag_io::MAX_GROUND_SPEED_M_S,
            if rows.len() == 1 { "row" } else { "rows" },
            shown.join(", "),
            more
        );
    }
    if !s.mapping.is_empty() {
        let _ = writeln!(
            o,
            "mapped   {}",
            s.mapping
                .iter()
                .map(|m| {
                    let unit = aeromag_io::known_field(&m.canonical).map_or("", |k| k.unit);
                    format!("{}={} [{unit}]", m.canonical, m.file_column)
                })
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if !s.derived.is_empty() {
        let _ = writeln!(
            o,
            "derived  {}",
            s.derived
                .iter()
                .map(|d| {
                    let unit = aeromag_io::known_field(&d.canonical).map_or("", |k| k.unit);
                    format!("{}={} [{unit}]", d.canonical, d.describe())
                })
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if !s.not_read.is_empty() {
        let _ = writeln!(
            o,
            "not read {} (not vectors of the flight's length)",
            s.not_read
                .iter()
                .map(|n| format!("{}: {}", n.name, n.what))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        o,
        "\n{:<22} {:<10} {:<6} {:>9} {:>14} {:>14} {:>14}",
        "column", "canonical", "unit", "missing", "min", "max", "mean"
    );
    for c in &s.columns {
        let _ = writeln!(
            o,
            "{:<22} {:<10} {:<6} {:>9} {:>14} {:>14} {:>14}",
            c.name,
            c.canonical.as_deref().unwrap_or(""),
            c.unit.unwrap_or(""),
            c.missing_total,
            fmt_opt(c.min),
            fmt_opt(c.max),
            fmt_opt(c.mean)
        );
    }
    o
}

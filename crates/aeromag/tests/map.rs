//! From lines to the map on simulated surveys: gridding honours the line
//! data, micro-levelling removes line-to-line corrugation.

mod common;

use aeromag::Silent;
use aeromag::flight::Flight;
use aeromag::map::gridding::GridMethod;
use aeromag::map::{GridOptions, MicrolevelOptions, grid_flight, microlevel};
use aeromag::simulate::{ScenarioKind, simulate_flight};
use common::with_projected_positions;

fn survey(pattern: &str, seed: u64) -> Flight {
    simulate_flight(ScenarioKind::Survey, Some(pattern), Some(seed)).unwrap()
}

/// RMS of the grid sampled at the rows on lines minus the column there,
/// over the column's standard deviation.
fn misfit_at_data(flight: &Flight, g: &aeromag::map::SurveyGrid) -> f64 {
    let v = flight.require(&g.column).unwrap();
    let (mut e, mut n) = (0.0, 0usize);
    for (k, vk) in v.iter().enumerate() {
        if g.survey.on_line(k) {
            let s = g.grid.sample(g.survey.x[k], g.survey.y[k]);
            if s.is_finite() {
                e += (s - vk).powi(2);
                n += 1;
            }
        }
    }
    (e / n as f64).sqrt() / g.grid.stats().std
}

#[test]
fn both_methods_honour_consistent_line_data() {
    let flight = survey(
        "[pattern]\nline_count = 10\nline_length_m = 5000.0\ntie_count = 3\n",
        11,
    );
    for method in [GridMethod::MinCurvature, GridMethod::Bidirectional] {
        let opts = GridOptions {
            column: Some("true_anomaly".into()),
            cell_m: Some(50.0),
            method,
            ..GridOptions::default()
        };
        let g = grid_flight(&flight, &opts, &mut Silent).unwrap();
        let misfit = misfit_at_data(&flight, &g);
        eprintln!(
            "{method:?}: misfit at the data {misfit:.4} of the grid's std ({:.2} nT)",
            g.grid.stats().std
        );
        assert!(misfit < 0.03, "{method:?}: {misfit}");
        let lines = g.survey.lines.as_ref().unwrap();
        assert_eq!((lines.traverse_lines, lines.other_lines), (10, 3));
        assert!((lines.spacing_m - 500.0).abs() < 5.0);
        // Blank beyond one line spacing from the lines only.
        assert!(g.blanked_nodes < g.grid.geometry.len() / 4);
    }
}

/// A row whose latitude reads 0 (a GPS dropout) in a survey at 56° N is
/// left out with a `[position-glitch]` warning that names it: the grid has
/// the clean survey's nodes, and its values at the data are as good (the
/// grid was 6 200 km tall before, its solve running for minutes).
#[test]
fn a_position_glitch_is_left_out_with_a_warning() {
    let flight = survey(
        "[pattern]\nline_count = 6\nline_length_m = 4000.0\ntie_count = 2\n",
        12,
    );
    let opts = GridOptions {
        column: Some("true_anomaly".into()),
        cell_m: Some(100.0),
        ..GridOptions::default()
    };
    let clean = grid_flight(&flight, &opts, &mut Silent).unwrap();
    assert!(clean.survey.off_track.is_empty());
    let (glitched, row) = lat_glitch(&flight, 0.0);
    // Before gridding: with the glitch kept the solve would run for minutes.
    let projected = aeromag::map::ProjectedSurvey::of(&glitched, None, None).unwrap();
    assert_eq!(projected.off_track, [row]);
    let g = grid_flight(&glitched, &opts, &mut Silent).unwrap();
    assert_eq!(g.survey.off_track, [row]);
    assert_eq!(g.grid.geometry, clean.grid.geometry);
    let warned: Vec<&str> = g
        .notes
        .iter()
        .filter(|n| n.is_warning() && n.message.contains("[position-glitch]"))
        .map(|n| n.message.as_str())
        .collect();
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(
        warned[0].contains(&format!("data row {}", row + 1)) && warned[0].contains("lat 0,"),
        "{}",
        warned[0]
    );
    let (a, b) = (
        misfit_at_data(&flight, &clean),
        misfit_at_data(&glitched, &g),
    );
    assert!(b < 1.05 * a, "misfit {b} against {a} without the glitch");
}

/// A zone given far from the data names the longitude and the option
/// (it blamed the column `lat`).
#[test]
fn a_zone_far_from_the_data_names_lon_and_the_option() {
    let flight = survey(
        "[pattern]\nline_count = 6\nline_length_m = 4000.0\ntie_count = 2\n",
        12,
    );
    let far: aeromag_grid::projection::UtmZone = "1N".parse().unwrap();
    let e = aeromag::map::ProjectedSurvey::of(&flight, Some(far), None).unwrap_err();
    let m = e.to_string();
    assert!(e.is_bad_input(), "{m}");
    assert!(
        m.contains("column 'lon'") && m.contains("--utm-zone"),
        "{m}"
    );
}

/// The glitch warning names a position in exponent form when it would be
/// long: a latitude of 1e-320 (a corrupted cell) was written with 320
/// digits, five times in one `microlevel` warning.
#[test]
fn a_glitch_warning_names_a_tiny_latitude_shortly() {
    let flight = survey(
        "[pattern]\nline_count = 6\nline_length_m = 4000.0\ntie_count = 2\n",
        12,
    );
    let (glitched, row) = lat_glitch(&flight, 1e-320);
    let projected = aeromag::map::ProjectedSurvey::of(&glitched, None, None).unwrap();
    assert_eq!(projected.off_track, [row]);
    let w = projected.off_track_warning(&glitched).unwrap();
    assert!(w.contains("lat 1e-320, lon ") && w.len() < 400, "{w}");
}

#[test]
fn microlevelling_removes_line_to_line_offsets_from_a_smooth_field() {
    let flight = survey(
        "[pattern]\nline_count = 16\nline_length_m = 8000.0\ntie_count = 3\n",
        12,
    );
    let (lat, lon, line) = (
        flight.require("lat").unwrap().to_vec(),
        flight.require("lon").unwrap().to_vec(),
        flight.require("line").unwrap().to_vec(),
    );
    // A smooth regional field (wavelengths ≥ 10 km) and a level error per
    // survey line (ties have none), alternating in sign with a random part.
    let offset = |l: f64| {
        if (1000.0..2000.0).contains(&l) {
            let k = l - 1000.0;
            2.0 * (if k as i64 % 2 == 0 { 1.0 } else { -1.0 }) + 1.5 * (k * 2.3).sin()
        } else {
            0.0
        }
    };
    let smooth: Vec<f64> = lat
        .iter()
        .zip(&lon)
        .map(|(la, lo)| 40.0 * ((la - 56.0) * 60.0).sin() + 25.0 * ((lo - 38.0) * 30.0).cos())
        .collect();
    let noisy: Vec<f64> = smooth
        .iter()
        .zip(&line)
        .map(|(s, l)| s + offset(*l))
        .collect();
    let mut table = flight.into_table();
    table.add_column("smooth", smooth.clone()).unwrap();
    table.add_column("lev", noisy.clone()).unwrap();
    table
        .add_column("flat", vec![53_000.0; line.len()])
        .unwrap();
    let flight = Flight::from_table(table).unwrap();
    let m = microlevel(
        &flight,
        &MicrolevelOptions {
            column: Some("lev".into()),
            ..MicrolevelOptions::default()
        },
        &mut Silent,
    )
    .unwrap();
    // Per survey line, the mean error; the RMS of its line-to-line steps.
    let steps = |v: &[f64]| {
        let means: Vec<f64> = (1001..=1016)
            .map(|l| {
                let e: Vec<f64> = (0..v.len())
                    .filter(|&k| line[k] == l as f64)
                    .map(|k| v[k] - smooth[k])
                    .collect();
                e.iter().sum::<f64>() / e.len() as f64
            })
            .collect();
        (means.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / 15.0).sqrt()
    };
    let (before, after) = (steps(&noisy), steps(&m.values));
    eprintln!(
        "line-to-line steps {before:.3} → {after:.3} nT; correction RMS {:.3} nT, largest {:.3}",
        m.correction_rms_nt, m.correction_max_nt
    );
    assert!(after < before / 5.0, "{before} → {after}");
    // The ties carry no offset: the corrected lines agree with them better.
    let (x_before, x_after) = m.crossover_rms_nt.expect("crossovers");
    eprintln!("crossover differences {x_before:.3} → {x_after:.3} nT");
    assert!(x_after < x_before / 3.0, "{x_before} → {x_after}");
    assert_eq!(m.output_column(), "lev_mlev");
    // Off the lines nothing changes.
    assert!(
        (0..line.len())
            .filter(|&k| line[k] == 0.0)
            .all(|k| m.correction[k] == 0.0)
    );
    // A constant column's crossover differences do not rise: 0 before,
    // 2.3e-12 nT after (gridding round-off) was warned of as a rise "from
    // 0.000 to 0.000 nT".
    let flat = microlevel(
        &flight,
        &MicrolevelOptions {
            column: Some("flat".into()),
            ..MicrolevelOptions::default()
        },
        &mut Silent,
    )
    .unwrap();
    assert!(
        flat.notes.iter().all(|n| !n.message.contains("raises")),
        "{:?}",
        flat.notes
    );
}

/// `flight` with the latitude of the 201st row of its first line set to
/// `lat` (a GPS dropout), and that row.
fn lat_glitch(flight: &Flight, lat: f64) -> (Flight, usize) {
    let row = flight
        .require("line")
        .unwrap()
        .iter()
        .position(|&l| l != 0.0)
        .unwrap()
        + 200;
    let mut table = flight.table().clone();
    let mut column = table.column("lat").unwrap().to_vec();
    column[row] = lat;
    table.set_column("lat", column).unwrap();
    (Flight::from_table(table).unwrap(), row)
}

/// Found by fuzzing the survey chain: `grid --cell 0.5` on lines 500 m
/// apart ran past two minutes without a word (56 million nodes). A cell
/// finer than a fiftieth of the line spacing is warned of, `[fine-cell]`,
/// with the nodes it makes; the default cell and a tenth are not.
#[test]
fn a_cell_far_finer_than_the_lines_is_warned_of() {
    let flight = survey(
        "[pattern]\nline_count = 6\nline_length_m = 4000.0\ntie_count = 2\n",
        12,
    );
    let run = |cell_m: Option<f64>| {
        let opts = GridOptions {
            column: Some("true_anomaly".into()),
            cell_m,
            ..GridOptions::default()
        };
        let g = grid_flight(&flight, &opts, &mut Silent).unwrap();
        let warned: Vec<String> = g
            .notes
            .iter()
            .filter(|n| n.is_warning() && n.message.contains("[fine-cell]"))
            .map(|n| n.message.clone())
            .collect();
        (g, warned)
    };
    let (default, none) = run(None);
    assert!(none.is_empty(), "{none:?}");
    let spacing = default.survey.lines.as_ref().unwrap().spacing_m;
    assert!(run(Some(spacing / 10.0)).1.is_empty());
    let (fine, warned) = run(Some(0.019 * spacing));
    assert_eq!(warned.len(), 1, "{warned:?}");
    let g = fine.grid.geometry;
    assert!(
        warned[0].contains(&format!("{} × {} nodes", g.nx, g.ny)),
        "{}",
        warned[0]
    );
}

/// A survey whose positions are already projected (`X`, `Y`, no lat/lon)
/// grids as its latitude and longitude do: with their zone given, the
/// same grid to the bit and the same coordinate system; without, the same
/// values, no coordinate system and the warning `[no-crs]`. A GPS dropout
/// at 0, 0 is found and named by its X and Y; northings in degrees are
/// refused with a zone; a lever arm is refused.
#[test]
fn projected_positions_grid_as_latitude_and_longitude() {
    let flight = survey(
        "[pattern]\nline_count = 6\nline_length_m = 4000.0\ntie_count = 2\n",
        12,
    );
    let opts = GridOptions {
        column: Some("true_anomaly".into()),
        ..GridOptions::default()
    };
    let geodetic = grid_flight(&flight, &opts, &mut Silent).unwrap();
    let zone = geodetic.survey.zone.unwrap();
    let xy = with_projected_positions(&flight, &geodetic.survey.x, &geodetic.survey.y);
    let bits = |g: &aeromag::map::SurveyGrid| -> Vec<u64> {
        g.grid.values.iter().map(|v| v.to_bits()).collect()
    };
    let in_zone = grid_flight(
        &xy,
        &GridOptions {
            zone: Some(zone),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap();
    assert_eq!(in_zone.grid.geometry, geodetic.grid.geometry);
    assert_eq!(in_zone.grid.crs, geodetic.grid.crs);
    assert_eq!(bits(&in_zone), bits(&geodetic));
    assert_eq!(in_zone.survey.position_columns, ["X", "Y"]);
    assert_eq!(in_zone.survey.lines, geodetic.survey.lines);
    let plain = grid_flight(&xy, &opts, &mut Silent).unwrap();
    assert_eq!(plain.grid.crs, None);
    assert_eq!(bits(&plain), bits(&geodetic));
    let said = |g: &aeromag::map::SurveyGrid, what: &str| {
        g.notes
            .iter()
            .filter(|n| n.message.contains(what))
            .map(|n| (n.is_warning(), n.message.clone()))
            .collect::<Vec<_>>()
    };
    let no_crs = said(&plain, "[no-crs]");
    assert_eq!(no_crs.len(), 1, "{:?}", plain.notes);
    assert!(no_crs[0].0 && no_crs[0].1.contains("X and Y"), "{no_crs:?}");
    assert!(said(&in_zone, "[no-crs]").is_empty());
    assert_eq!(said(&plain, "projected columns X (easting)").len(), 1);
    // Named columns: no note of where the positions come from.
    let named = grid_flight(
        &xy,
        &GridOptions {
            projected: Some(aeromag::map::ProjectedColumns::new("x", "y")),
            zone: Some(zone),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap();
    assert_eq!(bits(&named), bits(&geodetic));
    assert!(said(&named, "projected columns").is_empty());

    // A dropout written as 0, 0.
    let row = flight
        .require("line")
        .unwrap()
        .iter()
        .position(|&l| l != 0.0)
        .unwrap()
        + 200;
    let (mut x, mut y) = (geodetic.survey.x.clone(), geodetic.survey.y.clone());
    (x[row], y[row]) = (0.0, 0.0);
    let g = grid_flight(
        &with_projected_positions(&flight, &x, &y),
        &opts,
        &mut Silent,
    )
    .unwrap();
    assert_eq!(g.survey.off_track, [row]);
    assert_eq!(g.grid.geometry, geodetic.grid.geometry);
    let glitch = said(&g, "[position-glitch]");
    assert!(
        glitch.len() == 1 && glitch[0].1.contains(&format!("data row {}", row + 1)),
        "{glitch:?}"
    );
    assert!(glitch[0].1.contains("X 0, Y 0"), "{glitch:?}");

    // Negative northings, or longitudes for eastings, with a zone: bad
    // input naming the column and the row.
    let lon = flight.require("lon").unwrap();
    let south: Vec<f64> = geodetic.survey.y.iter().map(|y| -y).collect();
    let e = grid_flight(
        &with_projected_positions(&flight, &geodetic.survey.x, &south),
        &GridOptions {
            zone: Some(zone),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap_err();
    assert!(e.is_bad_input(), "{e}");
    let message = e.to_string();
    assert!(
        message.contains("'Y'") && message.contains("not a UTM northing"),
        "{message}"
    );
    let e = grid_flight(
        &with_projected_positions(&flight, lon, &geodetic.survey.y),
        &GridOptions {
            zone: Some(zone),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap_err();
    assert!(e.to_string().contains("not a UTM easting"), "{e}");

    // Micro-levelled on the same working grid; the correction not checked
    // at the crossovers, which are found from lat/lon, and said so.
    let mopts = MicrolevelOptions {
        column: Some("true_anomaly".into()),
        ..MicrolevelOptions::default()
    };
    let on_lat_lon = microlevel(&flight, &mopts, &mut Silent).unwrap();
    let on_xy = microlevel(&xy, &mopts, &mut Silent).unwrap();
    assert_eq!(on_xy.correction, on_lat_lon.correction);
    assert_eq!(on_xy.crossover_rms_nt, None);
    assert!(on_lat_lon.crossover_rms_nt.is_some());
    let unchecked = |m: &aeromag::map::Microlevelled| {
        m.notes
            .iter()
            .any(|n| n.message.contains("not checked at the crossovers"))
    };
    assert!(unchecked(&on_xy) && !unchecked(&on_lat_lon));

    // The grid's unit is the column's: nT, m for the altitude.
    assert_eq!(plain.grid.unit, "nT");
    let alt = grid_flight(
        &xy,
        &GridOptions {
            column: Some("alt".into()),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap();
    assert_eq!(alt.grid.unit, "m");

    let e = grid_flight(
        &xy,
        &GridOptions {
            lever_arm_m: Some([0.0, 0.0, 1.0]),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("lever arm"),
        "{e}"
    );
}

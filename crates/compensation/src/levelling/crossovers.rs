//! Crossovers: the points where the tracks of two different lines (a survey
//! line and a tie line, typically) intersect (spec `compensation.md`,
//! "Survey altitude"; seed `000_…` §9, re-adjustment at crossovers).
//!
//! ## Geometry
//!
//! Positions are projected on a local plane, `(north, east)` in metres from
//! the first positioned row, with [`Geodetic::ned_offset_to`] (better than
//! 0.1 % over blocks of tens of km; both tracks are projected the same way,
//! so an intersection is found wherever one exists). Each line is a
//! polyline of its rows in time order: an *edge* joins two consecutive
//! positioned rows of the same label, also across rows without a position,
//! but never across a row of another label (turns carry label 0). An edge is
//! *usable* when it spans no gap (time step ≤ `max_gap_factor` × median step,
//! no unpositioned row inside) and both ends have a finite value and
//! derivative.
//!
//! ## Search, `O(N log N)`
//!
//! Edges are bucketed in a square grid (cell = 4 × the median edge
//! length); long edges are registered in every cell of their pieces of at
//! most one cell. The `(cell, edge)` list is sorted, and in each cell every
//! pair of edges of different labels is tested for a proper intersection
//! `P0 + s(P1 − P0) = Q0 + u(Q1 − Q0)`, `s, u ∈ [0, 1]` (with a 10⁻⁹
//! tolerance against round-off; a crossing exactly at a vertex, found on
//! both adjacent edges, is kept once). A pair registered in several cells is
//! reported only by the cell that contains its intersection
//! point. Cost: `O(N log N)` for the sort plus `O(Σ_cells n_c²)`, i.e. linear
//! for tracks that do not run on top of one another.
//!
//! ## At each crossover
//!
//! For both sides (`a` the smaller label) the time, value, derivative and
//! altitude are interpolated linearly along the edge at the intersection.
//! Crossings are skipped and counted when an edge is not usable (a gap or a
//! missing value) or when the tracks cross at less than
//! `min_crossing_angle_deg`.

use super::tracks::{SurveyTracks, TrackConfig, bad};
use crate::error::Result;
use crate::tolles_lawson::segments::median_step;
use aeromag_core::frames::Geodetic;
use serde::{Deserialize, Serialize};

/// One side (one line's pass) of a crossover.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrossoverSide {
    /// Line label.
    pub label: i64,
    /// Row index of the start of the edge that crosses.
    pub row: usize,
    /// Fraction along the edge (0 at `row`, 1 at the next positioned row).
    pub fraction: f64,
    /// Interpolated time, s.
    pub time_s: f64,
    /// Interpolated value, nT.
    pub value_nt: f64,
    /// Interpolated along-track derivative `Ḃ`, nT/s.
    pub derivative_nt_per_s: f64,
    /// Interpolated altitude, m (NaN if unknown).
    pub alt_m: f64,
    /// Interpolated profile operator `S = F⁻¹[|κ_s| B̂]` of this line, nT/m
    /// ([`super::vertical_gradient`]); NaN if not computed.
    #[serde(default = "nan")]
    pub profile_gradient_nt_per_m: f64,
}

fn nan() -> f64 {
    f64::NAN
}

/// A crossover of two lines.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Crossover {
    /// The side with the smaller label.
    pub a: CrossoverSide,
    /// The side with the larger label.
    pub b: CrossoverSide,
    /// Position north of the local origin, m.
    pub north_m: f64,
    /// Position east of the local origin, m.
    pub east_m: f64,
    /// Crossing angle, deg (0–90).
    pub angle_deg: f64,
}

impl Crossover {
    /// The crossover difference `d = m_a − m_b`, nT.
    pub fn difference_nt(&self) -> f64 {
        self.a.value_nt - self.b.value_nt
    }
}

/// The crossovers of a survey and what was skipped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossoverSet {
    /// Usable crossovers, sorted by (label a, label b, time a).
    pub crossovers: Vec<Crossover>,
    /// Crossings on an edge that spans a gap.
    pub skipped_gap: usize,
    /// Crossings on an edge with a missing value or derivative.
    pub skipped_missing: usize,
    /// Crossings at less than the minimum angle.
    pub skipped_shallow: usize,
    /// The local origin `(lat, lon)`, deg, of `north_m`, `east_m`.
    pub origin_deg: (f64, f64),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum EdgeState {
    Usable,
    Gap,
    Missing,
}

#[derive(Debug, Clone, Copy)]
struct Edge {
    i: usize,
    j: usize,
    label: i64,
    p0: [f64; 2],
    p1: [f64; 2],
    state: EdgeState,
}

/// Find the crossovers of `tracks` (module docs). `derivative` is the
/// along-track derivative of `tracks.sensed` or `tracks.value` (nT/s, one per row, normally
/// from [`super::track_derivative`]); `profile_gradient`, if given, the
/// profile operator of [`super::profile_gradient`] (nT/m, one per row),
/// interpolated like the other channels (NaN sides where it is missing).
pub fn find_crossovers(
    tracks: &SurveyTracks,
    derivative: &[f64],
    profile_gradient: Option<&[f64]>,
    cfg: &TrackConfig,
) -> Result<CrossoverSet> {
    tracks.validate()?;
    cfg.validate()?;
    if derivative.len() != tracks.len() {
        return Err(bad(format!(
            "derivative has {} rows, the tracks {}",
            derivative.len(),
            tracks.len()
        )));
    }
    if let Some(g) = profile_gradient
        && g.len() != tracks.len()
    {
        return Err(bad(format!(
            "profile gradient has {} rows, the tracks {}",
            g.len(),
            tracks.len()
        )));
    }
    let positioned = |i: usize| {
        tracks.time[i].is_finite() && tracks.lat[i].is_finite() && tracks.lon[i].is_finite()
    };
    let origin = (0..tracks.len())
        .find(|&i| positioned(i))
        .map(|i| Geodetic::new(tracks.lat[i], tracks.lon[i], 0.0));
    let Some(origin) = origin else {
        return Ok(CrossoverSet {
            crossovers: Vec::new(),
            skipped_gap: 0,
            skipped_missing: 0,
            skipped_shallow: 0,
            origin_deg: (f64::NAN, f64::NAN),
        });
    };
    let xy = |i: usize| {
        let [n, e, _] = origin.ned_offset_to(&Geodetic::new(tracks.lat[i], tracks.lon[i], 0.0));
        [n, e]
    };

    // Edges: consecutive positioned rows of one label, never across another label.
    let max_gap = {
        let dt = median_step(tracks.time);
        if dt > 0.0 {
            dt * cfg.max_gap_factor
        } else {
            f64::INFINITY
        }
    };
    let has_data = |i: usize| tracks.value[i].is_finite() && derivative[i].is_finite();
    let mut edges: Vec<Edge> = Vec::new();
    let mut prev: Option<(usize, i64, [f64; 2])> = None;
    for i in 0..tracks.len() {
        let l = tracks.line[i];
        if l.is_finite() && tracks.label(i).is_none() {
            prev = None; // a turn or transit ends the run
            continue;
        }
        let Some(label) = tracks.label(i) else {
            continue;
        };
        if !positioned(i) {
            continue;
        }
        let p = xy(i);
        if let Some((j, lj, pj)) = prev
            && lj == label
        {
            let dt = tracks.time[i] - tracks.time[j];
            let state = if i != j + 1 || !(dt > 0.0 && dt <= max_gap) {
                EdgeState::Gap
            } else if !(has_data(i) && has_data(j)) {
                EdgeState::Missing
            } else {
                EdgeState::Usable
            };
            edges.push(Edge {
                i: j,
                j: i,
                label,
                p0: pj,
                p1: p,
                state,
            });
        }
        prev = Some((i, label, p));
    }

    let mut set = CrossoverSet {
        crossovers: Vec::new(),
        skipped_gap: 0,
        skipped_missing: 0,
        skipped_shallow: 0,
        origin_deg: (origin.lat_deg, origin.lon_deg),
    };
    if edges.len() < 2 {
        return Ok(set);
    }

    // Grid: cell = 4 × the median edge length.
    let mut lengths: Vec<f64> = edges
        .iter()
        .map(|e| dist(e.p0, e.p1))
        .filter(|&d| d > 0.0)
        .collect();
    let cell = if lengths.is_empty() {
        1.0
    } else {
        let m = lengths.len() / 2;
        (4.0 * *lengths.select_nth_unstable_by(m, |a, b| a.total_cmp(b)).1).max(1e-3)
    };
    let key = |v: f64| (v / cell).floor() as i64;
    let mut entries: Vec<(i64, i64, u32)> = Vec::with_capacity(edges.len() * 2);
    for (id, e) in edges.iter().enumerate() {
        let pieces = (dist(e.p0, e.p1) / cell).ceil().max(1.0) as usize;
        let eps = 1e-6 * cell;
        for k in 0..pieces {
            let (f0, f1) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
            let a = lerp2(e.p0, e.p1, f0);
            let b = lerp2(e.p0, e.p1, f1);
            for cx in key(a[0].min(b[0]) - eps)..=key(a[0].max(b[0]) + eps) {
                for cy in key(a[1].min(b[1]) - eps)..=key(a[1].max(b[1]) + eps) {
                    entries.push((cx, cy, id as u32));
                }
            }
        }
    }
    entries.sort_unstable();
    entries.dedup();

    let min_cos = cfg.min_crossing_angle_deg.to_radians().cos();
    // Every crossing found, with the reason it cannot be used (None: usable).
    let mut found: Vec<(Crossover, Option<Skip>)> = Vec::new();
    let mut start = 0;
    while start < entries.len() {
        let (cx, cy, _) = entries[start];
        let mut end = start + 1;
        while end < entries.len() && entries[end].0 == cx && entries[end].1 == cy {
            end += 1;
        }
        for p in start..end {
            for q in p + 1..end {
                let (e, f) = (&edges[entries[p].2 as usize], &edges[entries[q].2 as usize]);
                if e.label == f.label || !cfg.pairing.crosses(e.label, f.label) {
                    continue;
                }
                let Some((s, u)) = intersect(e, f) else {
                    continue;
                };
                let at = lerp2(e.p0, e.p1, s);
                if key(at[0]) != cx || key(at[1]) != cy {
                    continue; // reported by the cell that holds the point
                }
                let (de, df) = (sub(e.p1, e.p0), sub(f.p1, f.p0));
                let cos =
                    (de[0] * df[0] + de[1] * df[1]).abs() / (dist(e.p0, e.p1) * dist(f.p0, f.p1));
                let skip = if e.state == EdgeState::Gap || f.state == EdgeState::Gap {
                    Some(Skip::Gap)
                } else if e.state == EdgeState::Missing || f.state == EdgeState::Missing {
                    Some(Skip::Missing)
                } else if cos > min_cos {
                    Some(Skip::Shallow)
                } else {
                    None
                };
                let (sa, sb) = (
                    side(tracks, derivative, profile_gradient, e, s),
                    side(tracks, derivative, profile_gradient, f, u),
                );
                let (a, b) = if e.label < f.label {
                    (sa, sb)
                } else {
                    (sb, sa)
                };
                let angle_deg = cos.min(1.0).acos().to_degrees();
                found.push((
                    Crossover {
                        a,
                        b,
                        north_m: at[0],
                        east_m: at[1],
                        angle_deg,
                    },
                    skip,
                ));
            }
        }
        start = end;
    }
    found.sort_by(|(x, _), (y, _)| {
        (x.a.label, x.b.label)
            .cmp(&(y.a.label, y.b.label))
            .then(x.a.time_s.total_cmp(&y.a.time_s))
    });
    // A crossing at a shared vertex is found on both adjacent edges: keep one
    // (a usable one if there is).
    let same_point = 1e-6 * cell;
    found.dedup_by(|later, kept| {
        let same = (later.0.a.label, later.0.b.label) == (kept.0.a.label, kept.0.b.label)
            && (later.0.north_m - kept.0.north_m).abs() <= same_point
            && (later.0.east_m - kept.0.east_m).abs() <= same_point;
        if same && kept.1.is_some() && later.1.is_none() {
            std::mem::swap(later, kept);
        }
        same
    });
    for (x, skip) in found {
        match skip {
            None => set.crossovers.push(x),
            Some(Skip::Gap) => set.skipped_gap += 1,
            Some(Skip::Missing) => set.skipped_missing += 1,
            Some(Skip::Shallow) => set.skipped_shallow += 1,
        }
    }
    Ok(set)
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Skip {
    Gap,
    Missing,
    Shallow,
}

/// The parameters `(s, u)` of a proper intersection of two edges,
/// `s, u ∈ [0, 1]`; `None` for parallel or disjoint edges.
fn intersect(e: &Edge, f: &Edge) -> Option<(f64, f64)> {
    let r = sub(e.p1, e.p0);
    let q = sub(f.p1, f.p0);
    let w = sub(f.p0, e.p0);
    let den = r[0] * q[1] - r[1] * q[0];
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    let s = (w[0] * q[1] - w[1] * q[0]) / den;
    let u = (w[0] * r[1] - w[1] * r[0]) / den;
    // A tolerance of 1e-9 so that a crossing exactly at a vertex is not lost
    // to round-off; the duplicate it may create is removed by the caller.
    let inside = |v: f64| (-1e-9..1.0 + 1e-9).contains(&v);
    (inside(s) && inside(u)).then_some((s, u))
}

fn side(
    tracks: &SurveyTracks,
    derivative: &[f64],
    profile_gradient: Option<&[f64]>,
    e: &Edge,
    s: f64,
) -> CrossoverSide {
    let lerp = |x: &[f64]| x[e.i] + s * (x[e.j] - x[e.i]);
    CrossoverSide {
        label: e.label,
        row: e.i,
        fraction: s,
        time_s: lerp(tracks.time),
        value_nt: lerp(tracks.value),
        derivative_nt_per_s: lerp(derivative),
        alt_m: lerp(tracks.alt),
        profile_gradient_nt_per_m: profile_gradient.map_or(f64::NAN, lerp),
    }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn lerp2(a: [f64; 2], b: [f64; 2], f: f64) -> [f64; 2] {
    [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::levelling::{Pairing, track_derivative};

    /// A synthetic block: `nl` north-going lines (labels 1…) `spacing` m
    /// apart and `nt` east-going ties (labels 101…), sampled every `step` m
    /// at 1 sample/s, separated by turn rows (label 0). Origin 50°N 10°E.
    /// The value is a linear field `f(n, e) = 0.01 n − 0.02 e`.
    pub(crate) struct Block {
        pub t: Vec<f64>,
        pub lat: Vec<f64>,
        pub lon: Vec<f64>,
        pub alt: Vec<f64>,
        pub line: Vec<f64>,
        pub v: Vec<f64>,
    }

    pub(crate) fn block(nl: usize, nt: usize, spacing: f64, step: f64) -> Block {
        let o = Geodetic::new(50.0, 10.0, 0.0);
        let mut b = Block {
            t: vec![],
            lat: vec![],
            lon: vec![],
            alt: vec![],
            line: vec![],
            v: vec![],
        };
        let len_l = spacing * (nt as f64 + 1.0);
        let len_t = spacing * (nl as f64 + 1.0);
        let mut time = 0.0;
        let mut push = |b: &mut Block, n: f64, e: f64, label: f64| {
            let g = o.offset_by(n, e, 100.0);
            b.t.push(time);
            b.lat.push(g.lat_deg);
            b.lon.push(g.lon_deg);
            b.alt.push(100.0 + 0.001 * time);
            b.line.push(label);
            b.v.push(0.01 * n - 0.02 * e);
            time += 1.0;
        };
        for l in 0..nl {
            let e = spacing * (l as f64 + 0.5) + 0.37;
            let steps = (len_l / step) as usize;
            for k in 0..=steps {
                push(&mut b, k as f64 * step + 0.11, e, (l + 1) as f64);
            }
            push(&mut b, 0.0, 0.0, 0.0);
        }
        for tl in 0..nt {
            let n = spacing * (tl as f64 + 0.5) + 0.23;
            let steps = (len_t / step) as usize;
            for k in 0..=steps {
                push(&mut b, n, len_t - k as f64 * step - 0.13, (101 + tl) as f64);
            }
            push(&mut b, 0.0, 0.0, 0.0);
        }
        b
    }

    impl Block {
        pub(crate) fn tracks(&self) -> SurveyTracks<'_> {
            SurveyTracks {
                time: &self.t,
                lat: &self.lat,
                lon: &self.lon,
                alt: &self.alt,
                line: &self.line,
                value: &self.v,
                sensed: None,
            }
        }
    }

    #[test]
    fn pairing_line_with_tie_skips_crossings_of_two_lines_or_two_ties() {
        let b = block(7, 4, 200.0, 9.0);
        let count = |pairing: Pairing| {
            let cfg = TrackConfig {
                pairing,
                ..TrackConfig::default()
            };
            let d = track_derivative(&b.tracks(), &cfg).unwrap();
            find_crossovers(&b.tracks(), &d, None, &cfg)
                .unwrap()
                .crossovers
                .len()
        };
        let ties = (101..=104).collect::<Vec<i64>>();
        assert_eq!(count(Pairing::LineWithTie { tie_ids: ties }), 28);
        // Declared all lines (or all ties): no line meets a tie.
        assert_eq!(count(Pairing::LineWithTie { tie_ids: vec![] }), 0);
        let all = (1..=7).chain(101..=104).collect::<Vec<i64>>();
        assert_eq!(count(Pairing::LineWithTie { tie_ids: all }), 0);
        // Lines 1 and 2 declared ties (101–104 then count as lines): only
        // their 8 crossings with 101–104 remain.
        assert_eq!(
            count(Pairing::LineWithTie {
                tie_ids: vec![1, 2]
            }),
            8
        );
    }

    #[test]
    fn finds_every_crossing_once_with_exact_interpolation() {
        let b = block(7, 4, 200.0, 9.0);
        let cfg = TrackConfig::default();
        let d = track_derivative(&b.tracks(), &cfg).unwrap();
        let set = find_crossovers(&b.tracks(), &d, None, &cfg).unwrap();
        assert_eq!(set.crossovers.len(), 28);
        assert_eq!(
            (set.skipped_gap, set.skipped_missing, set.skipped_shallow),
            (0, 0, 0)
        );
        for (k, c) in set.crossovers.iter().enumerate() {
            let (l, tl) = (k / 4, k % 4);
            assert_eq!((c.a.label, c.b.label), (l as i64 + 1, 101 + tl as i64));
            // Position of the grid node relative to the first row (n 0.11, e 100.37).
            assert!((c.east_m - 200.0 * l as f64).abs() < 0.05, "{c:?}");
            assert!(
                (c.north_m - (200.0 * (tl as f64 + 0.5) + 0.12)).abs() < 0.05,
                "{c:?}"
            );
            assert!((c.angle_deg - 90.0).abs() < 0.1);
            // A linear field: both sides agree to the projection error.
            assert!(c.difference_nt().abs() < 2e-3, "{}", c.difference_nt());
            // Lines go north at 9 m/s: dv/dt = 0.09; ties go west: +0.18.
            assert!((c.a.derivative_nt_per_s - 0.09).abs() < 1e-3);
            assert!((c.b.derivative_nt_per_s - 0.18).abs() < 1e-3);
            assert!(c.a.time_s < c.b.time_s);
            assert!((c.a.alt_m - (100.0 + 0.001 * c.a.time_s)).abs() < 1e-9);
        }
    }

    #[test]
    fn gaps_missing_values_and_shallow_crossings_are_counted_not_used() {
        let mut b = block(3, 2, 200.0, 10.0);
        let cfg = TrackConfig::default();
        // The crossing of line 1 (e ≈ 100) with tie 101 (n ≈ 100): tie rows
        // run west from e = 800; remove the positions of 3 rows around e = 100.
        let tie_rows: Vec<usize> = (0..b.t.len()).filter(|&i| b.line[i] == 101.0).collect();
        let o = Geodetic::new(50.0, 10.0, 0.0);
        let east: Vec<f64> = (0..b.t.len())
            .map(|i| o.ned_offset_to(&Geodetic::new(b.lat[i], b.lon[i], 0.0))[1])
            .collect();
        let near = |i: usize, e: f64| (east[i] - e).abs() < 15.0;
        for &i in &tie_rows {
            if near(i, 100.37) {
                b.lat[i] = f64::NAN;
            }
        }
        // A missing value on tie 102 near line 3 (e ≈ 500).
        for i in 0..b.t.len() {
            if b.line[i] == 102.0 && near(i, 500.37) {
                b.v[i] = f64::NAN;
            }
        }
        let d = track_derivative(&b.tracks(), &cfg).unwrap();
        let set = find_crossovers(&b.tracks(), &d, None, &cfg).unwrap();
        assert_eq!(set.skipped_gap, 1);
        assert_eq!(set.skipped_missing, 1);
        assert_eq!(set.crossovers.len(), 4);
    }

    #[test]
    fn parallel_lines_and_turns_do_not_cross() {
        let b = block(5, 0, 100.0, 5.0);
        let d = track_derivative(&b.tracks(), &TrackConfig::default()).unwrap();
        // The turn rows (label 0, at the origin) must not form edges.
        let set = find_crossovers(&b.tracks(), &d, None, &TrackConfig::default()).unwrap();
        assert!(set.crossovers.is_empty());
        assert_eq!(
            set.skipped_gap + set.skipped_missing + set.skipped_shallow,
            0
        );
    }

    #[test]
    fn a_diagonal_zigzag_crosses_a_line_where_expected() {
        // Line 1 runs north along e = 0; line 2 zigzags across it three times
        // with long (multi-cell) edges.
        let o = Geodetic::new(-30.0, 140.0, 0.0);
        let mut rows: Vec<(f64, f64, f64)> = (0..200).map(|k| (k as f64 * 5.0, 0.0, 1.0)).collect();
        rows.push((0.0, 0.0, 0.0));
        for (n, e) in [
            (0.0, -300.0),
            (250.0, 300.0),
            (500.0, -300.0),
            (750.0, 300.0),
        ] {
            rows.push((n, e, 2.0));
        }
        let g: Vec<Geodetic> = rows
            .iter()
            .map(|&(n, e, _)| o.offset_by(n, e, 0.0))
            .collect();
        let t: Vec<f64> = (0..rows.len()).map(|k| k as f64).collect();
        let lat: Vec<f64> = g.iter().map(|p| p.lat_deg).collect();
        let lon: Vec<f64> = g.iter().map(|p| p.lon_deg).collect();
        let line: Vec<f64> = rows.iter().map(|r| r.2).collect();
        let v: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let alt = vec![f64::NAN; rows.len()];
        let tr = SurveyTracks {
            time: &t,
            lat: &lat,
            lon: &lon,
            alt: &alt,
            line: &line,
            value: &v,
            sensed: None,
        };
        // Time steps of line 2 equal those of line 1: no gap.
        let d = vec![0.0; rows.len()];
        let set = find_crossovers(&tr, &d, None, &TrackConfig::default()).unwrap();
        assert_eq!(set.crossovers.len(), 3);
        for (c, n) in set.crossovers.iter().zip([125.0, 375.0, 625.0]) {
            assert!((c.north_m - n).abs() < 0.1 && c.east_m.abs() < 0.1, "{c:?}");
            assert!((c.a.value_nt - n).abs() < 0.1);
            assert!((c.b.value_nt - n).abs() < 0.1);
            assert!(c.a.alt_m.is_nan());
            // The zigzag legs run at atan(600/250) = 67.4° to the line.
            assert!((c.angle_deg - (600.0f64 / 250.0).atan().to_degrees()).abs() < 0.01);
        }
        let steep = TrackConfig {
            min_crossing_angle_deg: 70.0,
            ..TrackConfig::default()
        };
        let set = find_crossovers(&tr, &d, None, &steep).unwrap();
        assert_eq!((set.crossovers.len(), set.skipped_shallow), (0, 3));
    }
}

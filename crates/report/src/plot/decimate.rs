//! Decimation of long series for drawing.
//!
//! A plot `W` pixels wide cannot show more than `W` distinct x positions, but
//! a polyline with 10⁶ vertices makes a multi-megabyte SVG. For lines we use
//! min/max decimation per pixel column: the x axis is cut into `W` columns;
//! each maximal run of *consecutive* vertices that fall into the same column
//! is replaced by its first vertex, its minimum-y vertex, its maximum-y vertex
//! and its last vertex, in their original order. The drawn polyline then
//! covers exactly the same pixels of every column (same vertical extent, same
//! entry and exit points), so spikes survive, while the vertex count drops to
//! at most `4·W` for monotonic x. Because only consecutive vertices are
//! merged, the rule stays correct for non-monotonic x (e.g. a flight track).
//!
//! For point markers the same idea is a per-pixel de-duplication: of all
//! markers whose centres fall into the same pixel only the first is kept.

use std::collections::HashSet;

/// Vertex count at or below which a polyline is drawn exactly, per column.
const EXACT_PER_COLUMN: usize = 4;

fn cell(v: f64, lo: f64, hi: f64, n: usize) -> i64 {
    ((v - lo) / (hi - lo) * n as f64).floor() as i64
}

/// Min/max-per-column decimation of a polyline whose x view is `x_view`
/// (axis units) drawn over `columns` pixel columns. Polylines with at most
/// `4·columns` vertices are returned unchanged.
pub(crate) fn decimate_line(
    points: &[(f64, f64)],
    x_view: (f64, f64),
    columns: usize,
) -> Vec<(f64, f64)> {
    let columns = columns.max(1);
    if points.len() <= EXACT_PER_COLUMN * columns {
        return points.to_vec();
    }
    let (lo, hi) = x_view;
    let mut out = Vec::with_capacity(EXACT_PER_COLUMN * columns);
    let mut start = 0;
    while start < points.len() {
        let col = cell(points[start].0, lo, hi, columns);
        let mut end = start + 1;
        while end < points.len() && cell(points[end].0, lo, hi, columns) == col {
            end += 1;
        }
        let run = &points[start..end];
        if run.len() <= EXACT_PER_COLUMN {
            out.extend_from_slice(run);
        } else {
            let (mut imin, mut imax) = (0, 0);
            for (i, p) in run.iter().enumerate() {
                if p.1 < run[imin].1 {
                    imin = i;
                }
                if p.1 > run[imax].1 {
                    imax = i;
                }
            }
            let mut keep = [0, imin, imax, run.len() - 1];
            keep.sort_unstable();
            let mut last = usize::MAX;
            for i in keep {
                if i != last {
                    out.push(run[i]);
                    last = i;
                }
            }
        }
        start = end;
    }
    out
}

/// Per-pixel de-duplication of point markers over a `columns × rows` pixel
/// grid spanning `x_view × y_view` (axis units). Sets with at most
/// `4·columns` points are returned unchanged.
pub(crate) fn decimate_points(
    points: &[(f64, f64)],
    x_view: (f64, f64),
    y_view: (f64, f64),
    columns: usize,
    rows: usize,
) -> Vec<(f64, f64)> {
    if points.len() <= EXACT_PER_COLUMN * columns.max(1) {
        return points.to_vec();
    }
    let mut seen = HashSet::with_capacity(points.len().min(columns * rows));
    points
        .iter()
        .copied()
        .filter(|&(x, y)| {
            seen.insert((
                cell(x, x_view.0, x_view.1, columns),
                cell(y, y_view.0, y_view.1, rows),
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per column: (min y, max y) of a polyline's vertices.
    fn column_extremes(points: &[(f64, f64)], lo: f64, hi: f64, n: usize) -> Vec<(f64, f64)> {
        let mut ext = vec![(f64::INFINITY, f64::NEG_INFINITY); n + 1];
        for &(x, y) in points {
            let c = cell(x, lo, hi, n).clamp(0, n as i64) as usize;
            ext[c] = (ext[c].0.min(y), ext[c].1.max(y));
        }
        ext
    }

    #[test]
    fn million_points_keep_every_column_extreme() {
        let n = 1_000_000;
        let cols = 800;
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let x = i as f64;
                // Smooth signal, pseudo-random noise and two isolated spikes.
                let noise = ((i as u64).wrapping_mul(2654435761) % 1000) as f64 / 1000.0 - 0.5;
                let spike = match i {
                    123_457 => 50.0,
                    876_543 => -70.0,
                    _ => 0.0,
                };
                (x, (x * 1e-5).sin() + 0.1 * noise + spike)
            })
            .collect();
        let dec = decimate_line(&pts, (0.0, (n - 1) as f64), cols);
        assert!(dec.len() <= 4 * (cols + 1), "{} vertices", dec.len());
        assert!(dec.contains(&pts[123_457]) && dec.contains(&pts[876_543]));
        let full = column_extremes(&pts, 0.0, (n - 1) as f64, cols);
        let kept = column_extremes(&dec, 0.0, (n - 1) as f64, cols);
        assert_eq!(full, kept);
        assert_eq!(dec.first(), pts.first());
        assert_eq!(dec.last(), pts.last());
        // Order is preserved (x increasing here).
        assert!(dec.windows(2).all(|w| w[0].0 < w[1].0));
    }

    proptest::proptest! {
        /// For any polyline (including non-monotonic x) the decimated one
        /// has the same per-column y extremes, the same end points, and at
        /// most 4 vertices per run of one column.
        #[test]
        fn extremes_survive_any_polyline(
            pts in proptest::collection::vec((0f64..100.0, -1e3f64..1e3), 0..3000),
            cols in 1usize..200,
        ) {
            let dec = decimate_line(&pts, (0.0, 100.0), cols);
            proptest::prop_assert_eq!(
                column_extremes(&pts, 0.0, 100.0, cols),
                column_extremes(&dec, 0.0, 100.0, cols)
            );
            proptest::prop_assert_eq!(dec.first(), pts.first());
            proptest::prop_assert_eq!(dec.last(), pts.last());
            // Kept vertices are a subsequence of the input.
            let mut it = pts.iter();
            proptest::prop_assert!(dec.iter().all(|d| it.any(|p| p == d)));
        }
    }

    #[test]
    fn short_lines_are_untouched() {
        let pts: Vec<(f64, f64)> = (0..100).map(|i| (i as f64, (i * i) as f64)).collect();
        assert_eq!(decimate_line(&pts, (0.0, 99.0), 800), pts);
    }

    #[test]
    fn points_are_deduplicated_per_pixel() {
        // 10 000 points on a 10 x 10 pixel grid: at most 100 survive, and
        // every occupied pixel keeps one marker.
        let pts: Vec<(f64, f64)> = (0..10_000)
            .map(|i| ((i % 100) as f64 / 100.0, (i / 100) as f64 / 100.0))
            .collect();
        let dec = decimate_points(&pts, (0.0, 1.0), (0.0, 1.0), 10, 10);
        assert_eq!(dec.len(), 100);
    }
}

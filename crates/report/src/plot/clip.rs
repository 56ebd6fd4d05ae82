//! Clipping of polylines to the view rectangle (Liang–Barsky).
//!
//! A segment `P(t) = P0 + t·(P1 − P0)`, `t ∈ [0, 1]`, is inside the rectangle
//! `[x0, x1] × [y0, y1]` for `t ∈ [t_in, t_out]`, where each of the four
//! boundaries `p_k·t ≤ q_k` (`p = (−dx, dx, −dy, dy)`,
//! `q = (Px − x0, x1 − Px, Py − y0, y1 − Py)`) raises `t_in` (when `p_k < 0`)
//! or lowers `t_out` (when `p_k > 0`) to `q_k/p_k` (Liang & Barsky, "A new
//! concept and method for line clipping", ACM TOG 3(1), 1984).
//!
//! Plotters does not clip series to the plotting area, so lines that leave a
//! user-given view would be drawn over the axes; clipping here also keeps
//! off-view samples out of the SVG.

/// The view rectangle in axis units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rect {
    /// Left edge.
    pub x0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y0: f64,
    /// Top edge.
    pub y1: f64,
}

impl Rect {
    /// Whether the point is inside or on the boundary.
    pub fn contains(&self, (x, y): (f64, f64)) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    /// The visible parameter interval `[t_in, t_out]` of the segment `a → b`,
    /// `None` when the segment misses the rectangle.
    fn clip_segment(&self, a: (f64, f64), b: (f64, f64)) -> Option<(f64, f64)> {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let mut t_in = 0.0f64;
        let mut t_out = 1.0f64;
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None; // parallel to and outside this boundary
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t_in = t_in.max(t);
                } else {
                    t_out = t_out.min(t);
                }
            }
        }
        (t_in <= t_out).then_some((t_in, t_out))
    }
}

fn lerp(a: (f64, f64), b: (f64, f64), t: f64) -> (f64, f64) {
    (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
}

/// Splits a polyline into the pieces that lie inside `rect`.
///
/// A single-point polyline is kept when the point is inside. Pieces are in
/// the original order; a piece starts where the line enters the rectangle
/// and ends where it leaves.
pub(crate) fn clip_polyline(points: &[(f64, f64)], rect: &Rect) -> Vec<Vec<(f64, f64)>> {
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    if points.len() == 1 {
        if rect.contains(points[0]) {
            pieces.push(points.to_vec());
        }
        return pieces;
    }
    let mut current: Vec<(f64, f64)> = Vec::new();
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        match rect.clip_segment(a, b) {
            Some((t_in, t_out)) => {
                if current.is_empty() || t_in > 0.0 {
                    if !current.is_empty() {
                        pieces.push(std::mem::take(&mut current));
                    }
                    current.push(lerp(a, b, t_in));
                }
                current.push(if t_out < 1.0 { lerp(a, b, t_out) } else { b });
                if t_out < 1.0 {
                    pieces.push(std::mem::take(&mut current));
                }
            }
            None => {
                if !current.is_empty() {
                    pieces.push(std::mem::take(&mut current));
                }
            }
        }
    }
    if !current.is_empty() {
        pieces.push(current);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: Rect = Rect {
        x0: 0.0,
        x1: 10.0,
        y0: 0.0,
        y1: 10.0,
    };

    #[test]
    fn inside_polyline_is_unchanged() {
        let p = vec![(1.0, 1.0), (5.0, 9.0), (9.0, 2.0)];
        assert_eq!(clip_polyline(&p, &R), vec![p]);
    }

    #[test]
    fn crossing_polyline_is_cut_at_the_boundary() {
        // Goes out through the top (y = 10 at x = 5) and back in at x = 7.
        let p = vec![(0.0, 0.0), (6.0, 12.0), (8.0, 6.0)];
        let pieces = clip_polyline(&p, &R);
        assert_eq!(pieces.len(), 2);
        assert_eq!(pieces[0], vec![(0.0, 0.0), (5.0, 10.0)]);
        let q = &pieces[1];
        assert!((q[0].0 - 6.0 - 2.0 / 3.0).abs() < 1e-12 && (q[0].1 - 10.0).abs() < 1e-12);
        assert_eq!(q[1], (8.0, 6.0));
    }

    #[test]
    fn outside_segments_vanish() {
        let p = vec![(-5.0, -5.0), (-1.0, 20.0), (20.0, 20.0)];
        assert!(clip_polyline(&p, &R).is_empty());
        assert!(clip_polyline(&[(11.0, 1.0)], &R).is_empty());
        assert_eq!(clip_polyline(&[(1.0, 1.0)], &R).len(), 1);
    }
}

//! The data to grid, and their means per grid node (the `blockmean` step
//! that GMT's `surface` expects before it).

use crate::error::{GridError, Result};
use crate::grid::GridGeometry;

/// Scattered data: easting and northing (m, projected) and value, of equal
/// length. Points with a non-finite value or coordinate are skipped (and
/// counted).
#[derive(Debug, Clone, Copy)]
pub struct Points<'a> {
    /// Easting, m.
    pub x: &'a [f64],
    /// Northing, m.
    pub y: &'a [f64],
    /// Value (e.g. nT).
    pub z: &'a [f64],
}

impl<'a> Points<'a> {
    /// The points, after checking that the three series have one length.
    pub fn new(x: &'a [f64], y: &'a [f64], z: &'a [f64]) -> Result<Self> {
        for (what, s) in [("northing", y), ("value", z)] {
            if s.len() != x.len() {
                return Err(GridError::LengthMismatch {
                    what,
                    got: s.len(),
                    expected: x.len(),
                });
            }
        }
        Ok(Self { x, y, z })
    }

    /// Number of points (finite or not).
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True without points.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The extent `(x_min, x_max, y_min, y_max)` of the finite points, m
    /// (`None` without any).
    pub fn extent(&self) -> Option<(f64, f64, f64, f64)> {
        let mut e = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        let mut any = false;
        for k in 0..self.len() {
            let (x, y, z) = (self.x[k], self.y[k], self.z[k]);
            if x.is_finite() && y.is_finite() && z.is_finite() {
                any = true;
                e = (e.0.min(x), e.1.max(x), e.2.min(y), e.3.max(y));
            }
        }
        any.then_some(e)
    }
}

/// The mean position (in node units: `u = (x − x0)/cell`) and value of
/// the points nearest each node that has any, as GMT's `blockmean`.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockMeans {
    /// One entry per node with data: `(node index, u, v, value, count)`.
    pub blocks: Vec<Block>,
    /// Finite points used.
    pub used: usize,
    /// Points skipped for a non-finite value or coordinate.
    pub non_finite: usize,
    /// Finite points more than half a cell outside the grid.
    pub outside: usize,
}

/// The mean of the points of one node ([`BlockMeans`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    /// Column of the node.
    pub i: usize,
    /// Row of the node.
    pub j: usize,
    /// Mean `u = (x − x0)/cell` of its points.
    pub u: f64,
    /// Mean `v = (y − y0)/cell` of its points.
    pub v: f64,
    /// Mean value.
    pub z: f64,
    /// Number of points.
    pub count: usize,
}

impl BlockMeans {
    /// Assign each finite point to its nearest node of `g` and average per
    /// node. A point exactly halfway between two nodes goes to the one with
    /// the even index (counted from the west and the south), as GMT
    /// `blockmean` does, so both see the same block means on data laid out
    /// on round coordinates. Blocks come out in node order (south row
    /// first), so the result does not depend on the points' order beyond
    /// round-off of the sums (which are taken in the points' order:
    /// deterministic).
    pub fn of(points: Points, g: &GridGeometry) -> Self {
        let mut sums: Vec<(f64, f64, f64, usize)> = vec![(0.0, 0.0, 0.0, 0); g.len()];
        let (mut used, mut non_finite, mut outside) = (0, 0, 0);
        for k in 0..points.len() {
            let (x, y, z) = (points.x[k], points.y[k], points.z[k]);
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                non_finite += 1;
                continue;
            }
            let (u, v) = g.to_node(x, y);
            let (iu, iv) = (u.round_ties_even(), v.round_ties_even());
            if iu < 0.0 || iv < 0.0 || iu >= g.nx as f64 || iv >= g.ny as f64 {
                outside += 1;
                continue;
            }
            let s = &mut sums[g.index(iu as usize, iv as usize)];
            s.0 += u;
            s.1 += v;
            s.2 += z;
            s.3 += 1;
            used += 1;
        }
        let blocks = sums
            .iter()
            .enumerate()
            .filter(|(_, s)| s.3 > 0)
            .map(|(k, s)| {
                let n = s.3 as f64;
                Block {
                    i: k % g.nx,
                    j: k / g.nx,
                    u: s.0 / n,
                    v: s.1 / n,
                    z: s.2 / n,
                    count: s.3,
                }
            })
            .collect();
        Self {
            blocks,
            used,
            non_finite,
            outside,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points halfway between nodes go where GMT 6.4 `blockmean` puts them:
    /// `printf "8 12 1\n" | gmt blockmean -R3/43/7/37 -I10 -C` gives the
    /// node (3, 7); 18 22 → (23, 27); 28 32 → (23, 27); 38 12 → (43, 7).
    #[test]
    fn halfway_points_go_to_the_even_node_as_in_gmt_blockmean() {
        let g = GridGeometry {
            x0: 3.0,
            y0: 7.0,
            cell: 10.0,
            nx: 5,
            ny: 4,
        };
        let (x, y) = ([8.0, 18.0, 28.0, 38.0], [12.0, 22.0, 32.0, 12.0]);
        let z = [1.0, 2.0, 4.0, 8.0];
        let m = BlockMeans::of(Points::new(&x, &y, &z).unwrap(), &g);
        let nodes: Vec<(f64, f64, f64)> =
            m.blocks.iter().map(|b| (g.x(b.i), g.y(b.j), b.z)).collect();
        assert_eq!(
            nodes,
            [(3.0, 7.0, 1.0), (43.0, 7.0, 8.0), (23.0, 27.0, 3.0)],
            "{m:?}"
        );
    }
}

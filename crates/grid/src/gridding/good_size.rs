//! A slightly larger grid on which the multigrid solve of minimum-curvature
//! gridding runs faster, as GMT `surface` chooses it (its manual, `-Q` and
//! the note on the internal region: without `-Qr` it solves on a slightly
//! larger region whose dimensions have more common factors and crops the
//! result back to the requested one).
//!
//! The work of a solve on `n_x × n_y` intervals is estimated from the grid
//! sequence the common factors allow: with `g = gcd(n_x, n_y)` and its
//! prime factors `p₁ ≤ … ≤ p_k`, the coarsest grid has `n_x/g × n_y/g`
//! intervals (if either is below 3, the largest factor is moved into it),
//! costs its node count times its longer side (sweeps to converge grow with
//! the side), and every refinement by the next largest factor `p` costs the
//! refined node count times `p`. Candidate sizes are the numbers
//! `2^a·3^b·5^c` (`a ≥ 1`) from `n` to `2n` intervals in each direction; the
//! one with the largest saving wins (the first in order of increasing
//! powers of 2, 3, 5 in `x`, then in `y`, on a tie), if any saves work. The
//! extra intervals go half (rounded down) to the west or south side, the
//! rest to the east or north.
//!
//! Matching GMT's choice matters beyond speed: the edge conditions hold at
//! the edges of the grid that is solved, so two implementations agree near
//! the requested edges only if they solve on the same grid. Measured
//! against GMT 6.4 (`blockmean` + `surface -T0.25`, same points) on the
//! uncompensated lines of `aeromag simulate survey --seed 8` (mis-ties up to
//! 44 nT at crossings; 36 054 points, 50 m cells): 1.50 % of the grid's
//! standard deviation apart when solved on the requested 212 × 203
//! intervals, 0.73 % on GMT's 216 × 216 (both stop at 500 sweeps on the
//! final grid there, unconverged). Converged to 2·10⁻⁷ nT per sweep, the
//! two agree to 0.33 % (largest node difference 4.0 nT, at a crossing with
//! a 44 nT mis-tie), and GMT's default result is 1.29 % from its own
//! converged one: at the default limit the comparison with GMT measures
//! mostly how far each stops from the solution. Other surveys of the same
//! kind (seeds 9, 10; cells 50 and 25 m): 0.39–0.69 %; seed 8 at 25 m
//! 1.10 %; the demo's compensated, unlevelled lines 0.68–0.69 %.

/// Intervals added on each side of a grid (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Enlargement {
    /// Added to the west, intervals.
    pub west: usize,
    /// Added to the east.
    pub east: usize,
    /// Added to the south.
    pub south: usize,
    /// Added to the north.
    pub north: usize,
}

/// The enlargement of a grid of `nx × ny` intervals that saves the most
/// estimated work, or `None` when no candidate saves any (module docs).
pub fn enlargement(nx: usize, ny: usize) -> Option<Enlargement> {
    if nx == 0 || ny == 0 {
        return None;
    }
    let own = solve_work(nx, ny);
    let (cx, cy) = (smooth_sizes(nx), smooth_sizes(ny));
    let mut best: Option<(usize, usize, f64)> = None;
    for &x in &cx {
        for &y in &cy {
            let saving = own / solve_work(x, y);
            if saving > 1.0 && best.is_none_or(|b| saving > b.2) {
                best = Some((x, y, saving));
            }
        }
    }
    best.map(|(x, y, _)| {
        let (mx, my) = (x - nx, y - ny);
        Enlargement {
            west: mx / 2,
            east: mx - mx / 2,
            south: my / 2,
            north: my - my / 2,
        }
    })
}

/// The numbers `2^a·3^b·5^c` (`a ≥ 1`) in `[n, 2n]`, in the order of the
/// nested loops over the powers of 2, then 3, then 5.
fn smooth_sizes(n: usize) -> Vec<usize> {
    let top = 2 * n;
    let mut out = Vec::new();
    let mut p2 = 2;
    while p2 <= top {
        let mut p3 = 1;
        while p3 <= top {
            let mut p5 = 1;
            while p5 <= top {
                let v = p2 * p3 * p5;
                if (n..=top).contains(&v) {
                    out.push(v);
                }
                p5 *= 5;
            }
            p3 *= 3;
        }
        p2 *= 2;
    }
    out
}

/// Prime factors of `n`, ascending, with multiplicity.
fn prime_factors(mut n: usize) -> Vec<usize> {
    let mut out = Vec::new();
    let mut d = 2;
    while d * d <= n {
        while n.is_multiple_of(d) {
            out.push(d);
            n /= d;
        }
        d += 1;
    }
    if n > 1 {
        out.push(n);
    }
    out
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// The grids a solve on `nx × ny` intervals runs through, as node spacings
/// in final cells, coarsest first and ending at 1: GMT's sequence, which
/// starts at the greatest common divisor of the two and divides by its
/// prime factors, largest first, the coarsest keeping at least 4 nodes a
/// side.
pub(super) fn strides(nx: usize, ny: usize) -> Vec<usize> {
    let mut stride = gcd(nx, ny).max(1);
    let mut factors = prime_factors(stride);
    while nx / stride < 3 || ny / stride < 3 {
        match factors.pop() {
            Some(p) => stride /= p,
            None => break,
        }
    }
    let mut out = vec![stride];
    while let Some(p) = factors.pop() {
        stride /= p;
        out.push(stride);
    }
    out
}

/// Estimated work of a solve on `nx × ny` intervals (module docs).
fn solve_work(nx: usize, ny: usize) -> f64 {
    let g = gcd(nx, ny);
    let mut factors = if g > 1 { prime_factors(g) } else { Vec::new() };
    let (mut cx, mut cy) = (nx / g, ny / g);
    if g > 1
        && (cx < 3 || cy < 3)
        && let Some(p) = factors.pop()
    {
        cx *= p;
        cy *= p;
    }
    let mut work = cx as f64 * cy as f64 * cx.max(cy) as f64;
    while let Some(p) = factors.pop() {
        cx *= p;
        cy *= p;
        work += cx as f64 * cy as f64 * p as f64;
    }
    work
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gmt_s_choices_are_reproduced() {
        // GMT 6.4 `surface -V` on this machine: "go from 212 x 203 to
        // optimal 216 x 216", region grown by 2 / 2 / 6 / 7 cells.
        assert_eq!(
            enlargement(212, 203),
            Some(Enlargement {
                west: 2,
                east: 2,
                south: 6,
                north: 7
            })
        );
        // The others GMT 6.4 reported (-R given → -R it used).
        let grown = |nx, ny| {
            let e = enlargement(nx, ny).unwrap();
            [e.west, e.east, e.south, e.north]
        };
        assert_eq!(grown(7, 12), [0, 1, 0, 0]); // 0/7/0/12 → 0/8/0/12
        assert_eq!(grown(300, 97), [0, 0, 1, 2]); // → 0/300/-1/99
        assert_eq!(grown(1398, 801), [21, 21, 31, 32]); // → -21/1419/-31/833
        // Sizes with many common factors stay (GMT printed nothing).
        assert_eq!(enlargement(160, 160), None);
        assert_eq!(enlargement(1400, 800), None);
    }

    #[test]
    fn sizes_and_factors() {
        assert_eq!(prime_factors(360), vec![2, 2, 2, 3, 3, 5]);
        assert_eq!(smooth_sizes(7), vec![10, 12, 8]);
    }
}

//! Grids derived in the wavenumber domain: the first vertical derivative
//! and upward continuation of a potential field, and the decorrugation
//! filter of micro-levelling.
//!
//! For a potential field on a horizontal plane, continuation by a height
//! `h` (m, upward) multiplies the 2-D spectrum by `e^{−|k| h}` and the
//! vertical derivative (z down, nT/m) by `|k|`, with `|k|` the radial
//! wavenumber in rad/m (Blakely 1995, *Potential theory in gravity and
//! magnetic applications*, §12.1). The grid is first made complete (blank
//! nodes filled by the harmonic interpolation of their neighbours), then
//! extended to twice its size by mirroring it about its east and north
//! edges, so that the periodic extension the FFT assumes is continuous and
//! no edge step leaks into the spectrum; after the inverse FFT the original
//! nodes are kept and the blank ones blanked again.

use crate::error::{GridError, Result};
use crate::grid::{Grid, GridGeometry};
use aeromag_core::error::shown;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

/// A wavenumber-domain operation ([`apply`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spectral {
    /// First vertical derivative (z down), unit per metre: `× |k|`.
    VerticalDerivative,
    /// Upward continuation by this height, m: `× e^{−|k| h}`.
    UpwardContinuation(f64),
    /// The line-parallel corrugation of a grid of line data (Minty 1991,
    /// *Simple micro-levelling for aeromagnetic data*, Exploration
    /// Geophysics 22, 591–592): a high-pass Butterworth filter of the
    /// radial wavenumber, `1/(1 + (k_c/|k|)^{2n})` with the cut-off
    /// `k_c = 2π / cutoff_wavelength_m`, times the directional cosine
    /// filter `|cos φ|^p`, φ the angle between the wavenumber vector and
    /// the across-line direction (stripes along the lines vary across
    /// them). What passes is what micro-levelling removes.
    Corrugation(Corrugation),
}

/// Settings of [`Spectral::Corrugation`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corrugation {
    /// Direction of the flight lines, degrees clockwise from grid north.
    pub line_direction_deg: f64,
    /// Cut-off wavelength of the high-pass, m (Minty: about four line
    /// spacings).
    pub cutoff_wavelength_m: f64,
    /// Order `n` of the Butterworth filter (default 8).
    pub order: u32,
    /// Power `p` of the directional cosine (default 2).
    pub cosine_power: f64,
}

impl Spectral {
    /// The filter's response at the wavenumber `(kx, ky)`, rad/m.
    fn response(&self, kx: f64, ky: f64) -> f64 {
        let k = (kx * kx + ky * ky).sqrt();
        match *self {
            Spectral::VerticalDerivative => k,
            Spectral::UpwardContinuation(h) => (-k * h).exp(),
            Spectral::Corrugation(c) => {
                if k == 0.0 {
                    return 0.0;
                }
                let th = c.line_direction_deg.to_radians();
                // Across-line unit vector (east, north).
                let cos_phi = (kx * th.cos() - ky * th.sin()).abs() / k;
                let kc = 2.0 * std::f64::consts::PI / c.cutoff_wavelength_m;
                cos_phi.powf(c.cosine_power) / (1.0 + (kc / k).powi(2 * c.order as i32))
            }
        }
    }
}

/// The continuation heights that are meaningful for a grid of `geometry`,
/// m: from 10⁻⁸ cell (the filter `e^{−|k| h}` at the highest wavenumber,
/// `|k| ≤ π√2/cell`, then differs from 1 by less than float32's
/// precision, 6·10⁻⁸: a lower height changes no value) to 10 times the
/// grid's extent `max(nx, ny) · cell` (the longest wavelength of the
/// mirrored grid is twice the extent, so every varying component is then
/// damped by `e^{−10π}` ≈ 2·10⁻¹⁴: only the mean is left).
pub fn height_range(geometry: &GridGeometry) -> (f64, f64) {
    let extent = geometry.nx.max(geometry.ny) as f64 * geometry.cell;
    (1e-8 * geometry.cell, 10.0 * extent)
}

/// `op` applied to `grid` (module docs). The result has the grid's
/// geometry and blanks; a vertical derivative's unit is the grid's per
/// metre. Errors: a grid with fewer than 2 × 2 nodes or without any value,
/// a continuation height outside [`height_range`] ([`GridError::Height`]).
pub fn apply(grid: &Grid, op: Spectral) -> Result<Grid> {
    let g = grid.geometry;
    if g.nx < 2 || g.ny < 2 {
        return Err(GridError::Unusable(format!(
            "a {} × {} grid is too small to filter",
            g.nx, g.ny
        )));
    }
    match op {
        Spectral::UpwardContinuation(h) => {
            let (min, max) = height_range(&g);
            if !(min..=max).contains(&h) {
                return Err(GridError::Height { value: h, min, max });
            }
        }
        Spectral::Corrugation(c) => {
            crate::error::positive("cut-off wavelength", c.cutoff_wavelength_m)?;
            if !(c.line_direction_deg.is_finite()
                && c.cosine_power.is_finite()
                && c.cosine_power >= 0.0
                && c.order >= 1)
            {
                return Err(GridError::OutOfRange {
                    name: "corrugation filter",
                    value: c.cosine_power,
                    expected: "a finite line direction, a cosine power ≥ 0 and an order ≥ 1",
                });
            }
        }
        _ => {}
    }
    let Spectrum {
        mut a,
        mx,
        my,
        dkx,
        dky,
        mut planner,
    } = Spectrum::of(grid)?;
    for j in 0..my {
        let ky = Spectrum::wavenumber(j, my, dky);
        for i in 0..mx {
            let kx = Spectrum::wavenumber(i, mx, dkx);
            a[j * mx + i] *= op.response(kx, ky);
        }
    }
    fft2(&mut a, mx, my, &mut planner, true);
    let scale = 1.0 / (mx * my) as f64;
    let values: Vec<f64> = (0..g.len())
        .map(|k| {
            if grid.values[k].is_nan() {
                f64::NAN
            } else {
                a[(k / g.nx) * mx + k % g.nx].re * scale
            }
        })
        .collect();
    // Not expected for values within MAX_VALUE and a cell within MIN_CELL–
    // MAX_CELL, but a grid built in memory has no such bounds.
    if values
        .iter()
        .zip(&grid.values)
        .any(|(v, x)| !v.is_finite() && !x.is_nan())
    {
        let s = grid.stats();
        return Err(GridError::Unusable(format!(
            "the result is not finite: values from {} to {} at a {} m cell are too large to filter",
            shown(s.min),
            shown(s.max),
            shown(g.cell)
        )));
    }
    let (name, unit) = match op {
        Spectral::VerticalDerivative => (
            format!("{} vertical derivative", grid.name),
            format!("{}/m", grid.unit),
        ),
        Spectral::UpwardContinuation(h) => (
            format!("{} continued up {} m", grid.name, shown(h)),
            grid.unit.clone(),
        ),
        Spectral::Corrugation(_) => (format!("{} corrugation", grid.name), grid.unit.clone()),
    };
    Ok(Grid {
        values,
        name,
        unit,
        ..grid.clone()
    })
}

/// The 2-D spectrum of a grid made complete and mirrored (module docs).
struct Spectrum {
    /// Spectrum, row-major `mx × my` (unnormalised FFT).
    a: Vec<Complex64>,
    mx: usize,
    my: usize,
    /// Wavenumber steps, rad/m.
    dkx: f64,
    dky: f64,
    planner: FftPlanner<f64>,
}

impl Spectrum {
    fn of(grid: &Grid) -> Result<Self> {
        let g = grid.geometry;
        if g.nx < 2 || g.ny < 2 {
            return Err(GridError::Unusable(format!(
                "a {} × {} grid is too small to filter",
                g.nx, g.ny
            )));
        }
        let filled = fill_blanks(grid)?;
        // Mirror to 2nx × 2ny: x' = 2nx − 1 − x beyond the east edge.
        let (mx, my) = (2 * g.nx, 2 * g.ny);
        let mut a = vec![Complex64::new(0.0, 0.0); mx * my];
        for j in 0..my {
            let sj = if j < g.ny { j } else { my - 1 - j };
            for i in 0..mx {
                let si = if i < g.nx { i } else { mx - 1 - i };
                a[j * mx + i] = Complex64::new(filled[sj * g.nx + si], 0.0);
            }
        }
        let mut planner = FftPlanner::<f64>::new();
        fft2(&mut a, mx, my, &mut planner, false);
        Ok(Self {
            a,
            mx,
            my,
            dkx: 2.0 * std::f64::consts::PI / (mx as f64 * g.cell),
            dky: 2.0 * std::f64::consts::PI / (my as f64 * g.cell),
            planner,
        })
    }

    /// The signed wavenumber of FFT bin `m` of `n` with step `dk`.
    fn wavenumber(m: usize, n: usize, dk: f64) -> f64 {
        if m <= n / 2 {
            m as f64 * dk
        } else {
            (m as f64 - n as f64) * dk
        }
    }
}

/// The power of a grid's line-parallel corrugation (for judging
/// compensation and levelling on a map): the mean square of the grid's
/// spectral components whose wavefronts run along the lines, i.e. the
/// along-line wavelength is longer than 4 line spacings and the
/// across-line wavelength between 0.8 and 2.5 line spacings (heading
/// stripes alternate from line to line, a wavelength of 2 spacings; a
/// single line's level error spreads over 1–2 spacings), in the grid's
/// unit squared (Parseval: the variance those components carry).
pub fn corrugation_power(grid: &Grid, line_direction_deg: f64, line_spacing_m: f64) -> Result<f64> {
    crate::error::positive("line spacing", line_spacing_m)?;
    if !line_direction_deg.is_finite() {
        return Err(GridError::OutOfRange {
            name: "line direction",
            value: line_direction_deg,
            expected: "a finite angle",
        });
    }
    let sp = Spectrum::of(grid)?;
    let th = line_direction_deg.to_radians();
    let two_pi = 2.0 * std::f64::consts::PI;
    let (k_lo, k_hi) = (
        two_pi / (2.5 * line_spacing_m),
        two_pi / (0.8 * line_spacing_m),
    );
    let k_along_max = two_pi / (4.0 * line_spacing_m);
    let n = (sp.mx * sp.my) as f64;
    let mut power = 0.0;
    for j in 0..sp.my {
        let ky = Spectrum::wavenumber(j, sp.my, sp.dky);
        for i in 0..sp.mx {
            let kx = Spectrum::wavenumber(i, sp.mx, sp.dkx);
            let across = (kx * th.cos() - ky * th.sin()).abs();
            let along = (kx * th.sin() + ky * th.cos()).abs();
            if along <= k_along_max && (k_lo..=k_hi).contains(&across) {
                power += sp.a[j * sp.mx + i].norm_sqr();
            }
        }
    }
    Ok(power / (n * n))
}

/// In-place 2-D FFT of a row-major `nx × ny` array (unnormalised).
fn fft2(a: &mut [Complex64], nx: usize, ny: usize, planner: &mut FftPlanner<f64>, inverse: bool) {
    let (row, col) = if inverse {
        (planner.plan_fft_inverse(nx), planner.plan_fft_inverse(ny))
    } else {
        (planner.plan_fft_forward(nx), planner.plan_fft_forward(ny))
    };
    row.process(a);
    let mut column = vec![Complex64::new(0.0, 0.0); ny];
    for i in 0..nx {
        for j in 0..ny {
            column[j] = a[j * nx + i];
        }
        col.process(&mut column);
        for j in 0..ny {
            a[j * nx + i] = column[j];
        }
    }
}

/// The grid's values with every blank node replaced by the harmonic
/// interpolation of the others (Gauss–Seidel on the blank nodes only,
/// started from the mean; the values already there are kept). An
/// all-blank grid is an error.
pub fn fill_blanks(grid: &Grid) -> Result<Vec<f64>> {
    let g = grid.geometry;
    let stats = grid.stats();
    if stats.count == 0 {
        return Err(GridError::Unusable("the grid has no value".into()));
    }
    let mut v: Vec<f64> = grid
        .values
        .iter()
        .map(|&x| if x.is_nan() { stats.mean } else { x })
        .collect();
    let blank: Vec<usize> = (0..g.len()).filter(|&k| grid.values[k].is_nan()).collect();
    if blank.is_empty() {
        return Ok(v);
    }
    let limit = 1e-6 * stats.std.max(f64::MIN_POSITIVE);
    for _ in 0..10_000 {
        let mut change: f64 = 0.0;
        for &k in &blank {
            let (i, j) = (k % g.nx, k / g.nx);
            let (mut s, mut n) = (0.0, 0.0);
            if i > 0 {
                s += v[k - 1];
                n += 1.0;
            }
            if i + 1 < g.nx {
                s += v[k + 1];
                n += 1.0;
            }
            if j > 0 {
                s += v[k - g.nx];
                n += 1.0;
            }
            if j + 1 < g.ny {
                s += v[k + g.nx];
                n += 1.0;
            }
            let new = s / n;
            change = change.max((new - v[k]).abs());
            v[k] = new;
        }
        if change < limit {
            break;
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridGeometry;

    /// The vertical field of a point pole at depth `d` below the plane
    /// (decays as 1/r³): `d / (r² + d²)^{3/2}` (scaled to nT).
    fn pole(x: f64, y: f64, d: f64) -> f64 {
        1e9 * d / (x * x + y * y + d * d).powf(1.5)
    }

    fn grid_of(f: impl Fn(f64, f64) -> f64) -> Grid {
        let geometry =
            GridGeometry::covering(-12_000.0, 12_000.0, -10_000.0, 10_000.0, 100.0).unwrap();
        let mut g = Grid::blank(geometry, "T", "nT");
        for j in 0..geometry.ny {
            for i in 0..geometry.nx {
                g.values[geometry.index(i, j)] = f(geometry.x(i), geometry.y(j));
            }
        }
        g
    }

    /// RMS of `a − f` over the central part (|x|, |y| ≤ 4 km), relative to
    /// the RMS of `f` there.
    fn central_error(a: &Grid, f: impl Fn(f64, f64) -> f64) -> f64 {
        let g = a.geometry;
        let (mut e, mut s) = (0.0, 0.0);
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (x, y) = (g.x(i), g.y(j));
                if x.abs() <= 4000.0 && y.abs() <= 4000.0 {
                    e += (a.get(i, j) - f(x, y)).powi(2);
                    s += f(x, y).powi(2);
                }
            }
        }
        (e / s).sqrt()
    }

    #[test]
    fn vertical_derivative_and_continuation_of_a_pole_match_the_analytic_fields() {
        let d = 800.0;
        let g = grid_of(|x, y| pole(x, y, d));
        let up = apply(&g, Spectral::UpwardContinuation(300.0)).unwrap();
        let e_up = central_error(&up, |x, y| pole(x, y, d + 300.0));
        let dz = apply(&g, Spectral::VerticalDerivative).unwrap();
        // ∂/∂z (z down) of d (r² + d²)^{−3/2} = 3d²/(r²+d²)^{5/2} − 1/(r²+d²)^{3/2}.
        let fvd = |x: f64, y: f64| {
            let q = x * x + y * y + d * d;
            1e9 * (3.0 * d * d / q.powf(2.5) - 1.0 / q.powf(1.5))
        };
        let e_dz = central_error(&dz, fvd);
        eprintln!("relative RMS errors: upward {e_up:.2e}, vertical derivative {e_dz:.2e}");
        assert!(e_up < 3e-3, "{e_up}");
        assert!(e_dz < 1e-2, "{e_dz}");
        assert_eq!(dz.unit, "nT/m");
    }

    #[test]
    fn the_corrugation_filter_keeps_line_stripes_and_removes_the_field() {
        // North–south lines 400 m apart, each with its own level error, on
        // top of a smooth anomaly.
        let level = |x: f64| 3.0 * (((x / 400.0).round() * 1.7).sin());
        let field = |x: f64, y: f64| pole(x, y, 1500.0);
        let g = grid_of(|x, y| field(x, y) + level(x));
        let c = Corrugation {
            line_direction_deg: 0.0,
            cutoff_wavelength_m: 1600.0,
            order: 8,
            cosine_power: 2.0,
        };
        let corr = apply(&g, Spectral::Corrugation(c)).unwrap();
        let err = central_error(&corr, |x, _| level(x) - 0.0);
        eprintln!("corrugation recovered to {err:.3} of its RMS");
        assert!(err < 0.35, "{err}");
        // Lines east–west: the same stripes are not along the lines and pass
        // far less.
        let across = apply(
            &g,
            Spectral::Corrugation(Corrugation {
                line_direction_deg: 90.0,
                ..c
            }),
        )
        .unwrap();
        let kept = |a: &Grid| a.values.iter().map(|v| v * v).sum::<f64>();
        assert!(kept(&across) < 0.05 * kept(&corr));
    }

    #[test]
    fn corrugation_power_sees_alternating_line_levels_not_the_field() {
        let stripes = |x: f64| {
            if ((x / 400.0).round() as i64) % 2 == 0 {
                1.0
            } else {
                -1.0
            }
        };
        let field = grid_of(|x, y| pole(x, y, 1500.0));
        let striped = grid_of(|x, y| pole(x, y, 1500.0) + stripes(x));
        let (p0, p1) = (
            corrugation_power(&field, 0.0, 400.0).unwrap(),
            corrugation_power(&striped, 0.0, 400.0).unwrap(),
        );
        eprintln!("corrugation power: field {p0:.3e}, with ±1 nT stripes {p1:.3e}");
        // ±1 nT square stripes carry 1 nT² of variance, mostly at 2 spacings.
        assert!(p1 > 0.6 && p1 < 1.0, "{p1}");
        assert!(p0 < 0.01 * p1, "{p0}");
        // Stripes across the lines are not corrugation along them.
        assert!(corrugation_power(&striped, 90.0, 400.0).unwrap() < 0.05 * p1);
    }

    #[test]
    fn blanks_are_filled_for_the_transform_and_blanked_again() {
        let mut g = grid_of(|x, y| pole(x, y, 800.0));
        let geometry = g.geometry;
        for j in 0..20 {
            for i in 0..30 {
                g.values[geometry.index(i, j)] = f64::NAN;
            }
        }
        let up = apply(&g, Spectral::UpwardContinuation(100.0)).unwrap();
        assert!(up.get(3, 3).is_nan());
        assert!(up.values.iter().filter(|v| v.is_nan()).count() == 600);
        let filled = fill_blanks(&g).unwrap();
        assert!(filled.iter().all(|v| v.is_finite()));
        assert!(apply(&g, Spectral::UpwardContinuation(-1.0)).is_err());
        let all_blank = Grid::blank(geometry, "x", "nT");
        assert!(apply(&all_blank, Spectral::VerticalDerivative).is_err());
    }

    #[test]
    fn continuation_heights_outside_the_meaningful_range_are_refused() {
        let g = grid_of(|x, y| pole(x, y, 800.0));
        // 241 × 201 nodes at 100 m: heights from 1 µm to 241 km.
        assert_eq!(height_range(&g.geometry), (1e-6, 241_000.0));
        for h in [
            1e308,
            5e-324,
            0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            241_001.0,
            9e-7,
        ] {
            let e = apply(&g, Spectral::UpwardContinuation(h)).unwrap_err();
            assert!(e.is_bad_input());
            let m = e.to_string();
            assert!(matches!(e, GridError::Height { .. }), "{h}: {m}");
            assert!(
                m.len() < 250 && m.contains("between 0.000001 and 241000 m"),
                "{m}"
            );
        }
        let up = apply(&g, Spectral::UpwardContinuation(241_000.0)).unwrap();
        assert_eq!(up.name, "T continued up 241000 m");
        assert!(up.values.iter().all(|v| v.is_finite()));
        assert!(apply(&g, Spectral::UpwardContinuation(1e-6)).is_ok());
    }

    #[test]
    fn a_product_that_overflows_is_an_error_not_infinities() {
        // Values no file may hold (grids read from files are within
        // float32), built in memory.
        let mut g = grid_of(|_, _| 1.0);
        g.values[0] = 1.7e308;
        g.values[1] = -1.7e308;
        for op in [
            Spectral::VerticalDerivative,
            Spectral::UpwardContinuation(100.0),
        ] {
            let Err(e) = apply(&g, op) else {
                panic!("{op:?}: no error");
            };
            let m = e.to_string();
            assert!(
                m.contains("not finite") && m.contains("-1.7e308") && m.len() < 150,
                "{m}"
            );
        }
    }
}

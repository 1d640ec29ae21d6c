//! Δχ² surfaces in the plane of two free parameters (the paper's f–σ0 and f–A_b planes): χ² on a grid
//! around the best fit, with the other free parameter re-minimised at each grid point, so that the
//! Δχ² = 2.30 contour is the two-parameter 1σ region of the paper (sections 4.3 and 4.5).
//!
//! The grid follows the principal axes of the Δχ² ellipse at the best fit (the Hessian of the profile χ²
//! by central differences, in units of the 1σ half-widths): in a degenerate plane such as f–A_b of the
//! halo monopole (correlation ≈ −0.999) the contour is a thin tilted ellipse that a grid along the
//! parameters resolves only with hundreds of points per axis.

use super::minimise::{steps, Residuals, Window};
use super::{check, FitResult, FitSettings, MultipoleData, MultipoleModel, Parameter, Params};
use crate::error::{Error, Result};

/// The Δχ² levels of the 68.3% and 95.4% joint regions of two parameters (Δχ² = −2 ln(1 − p) for two
/// degrees of freedom; the values of the Δχ² table of Press et al., Numerical Recipes, §15.6).
pub const CONTOUR_LEVELS: [f64; 2] = [2.30, 6.17];

/// The grid of a Δχ² surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContourGrid {
    /// The first parameter.
    pub x: Parameter,
    /// The second parameter.
    pub y: Parameter,
    /// Grid points per axis (3 to 401), spaced evenly.
    pub points: usize,
    /// Half-width of each axis in units of the Δχ² = 2.30 semi-axis along it (2.5 holds the 6.17
    /// contour of a Gaussian surface, 1.64 times the 2.30 one); for a grid along the parameters, in
    /// units of their 1σ half-widths.
    pub span: f64,
}

impl ContourGrid {
    /// The grid of the parameters `x`, `y` (two different ones of `free`), `points` per axis (3 to
    /// 401) and half-width `span` (finite, > 0).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for parameters that are equal or not free, [`Error::InvalidParameter`]
    /// for `points` or `span` out of range.
    pub fn new(
        x: Parameter,
        y: Parameter,
        points: usize,
        span: f64,
        free: &[Parameter],
    ) -> Result<Self> {
        if x == y || !free.contains(&x) || !free.contains(&y) {
            let names: Vec<&str> = free.iter().map(|p| p.name()).collect();
            return Err(Error::InvalidChoice {
                what: format!("contour {x},{y}"),
                reason: format!(
                    "expected two different free parameters, of {}",
                    names.join(",")
                ),
            });
        }
        if !(3..=401).contains(&points) {
            return Err(Error::InvalidParameter {
                name: "contour points per axis",
                value: points as f64,
                reason: "must be between 3 and 401",
            });
        }
        if !(span.is_finite() && span > 0.0) {
            return Err(Error::InvalidParameter {
                name: "contour span",
                value: span,
                reason: "must be finite and positive",
            });
        }
        Ok(Self { x, y, points, span })
    }
}

impl Default for ContourGrid {
    fn default() -> Self {
        Self {
            x: Parameter::F,
            y: Parameter::Sigma0,
            points: 41,
            span: 2.5,
        }
    }
}

/// Δχ² on a grid of two parameters at one k_max. Grid point (i, j) is `centre + u_i axes[0] + u_j
/// axes[1]`, u evenly spaced over [−span, span].
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    /// k_max [h/Mpc] of the fit window.
    pub k_max: f64,
    /// The first parameter.
    pub x: Parameter,
    /// The second parameter.
    pub y: Parameter,
    /// χ² at the best fit (the [`FitResult`]'s).
    pub chi2_min: f64,
    /// The best fit (x, y), the centre of the grid.
    pub centre: (f64, f64),
    /// The two step directions (Δx, Δy) of the grid per unit of u: the principal semi-axes of the
    /// Δχ² = 2.30 ellipse, or the 1σ half-widths along x and y if the Hessian is not positive definite.
    pub axes: [(f64, f64); 2],
    /// Whether `axes` are the ellipse's (else along x and y).
    pub principal: bool,
    /// `points[i][j]`: (x, y) of grid point (i, j).
    pub points: Vec<Vec<(f64, f64)>>,
    /// `chi2[i][j]`: the profile χ² at `points[i][j]`, the other free parameters re-minimised.
    pub chi2: Vec<Vec<f64>>,
    /// `at[i][j]`: the parameters where that minimum is reached.
    pub at: Vec<Vec<Params>>,
}

/// The half-width of the 1σ interval of `p` in `result` (5% of its value, at least 0.005, if the
/// interval is not finite).
fn half_width(p: Parameter, result: &FitResult) -> f64 {
    result
        .intervals
        .iter()
        .find(|i| i.0 == p)
        .map(|&(_, lo, hi)| 0.5 * (hi - lo))
        .filter(|h| h.is_finite() && *h > 0.0)
        .unwrap_or(0.05 * result.best.get(p).abs().max(0.1))
}

/// The principal semi-axes of the Δχ² = 2.30 ellipse of `profile` (χ² of (x, y) around `centre`), in
/// (Δx, Δy), from its Hessian by central differences with steps of half the 1σ half-widths `w`;
/// `None` if that Hessian is not positive definite.
fn principal_axes(
    profile: &dyn Fn(f64, f64) -> f64,
    centre: (f64, f64),
    w: (f64, f64),
) -> Option<[(f64, f64); 2]> {
    // In units of w: X = Δx/w_x, Y = Δy/w_y, steps h = 1/2.
    let h = 0.5;
    let at = |a: f64, b: f64| profile(centre.0 + a * w.0, centre.1 + b * w.1);
    let f0 = at(0.0, 0.0);
    let hxx = (at(h, 0.0) - 2.0 * f0 + at(-h, 0.0)) / (h * h);
    let hyy = (at(0.0, h) - 2.0 * f0 + at(0.0, -h)) / (h * h);
    let hxy = (at(h, h) - at(h, -h) - at(-h, h) + at(-h, -h)) / (4.0 * h * h);
    let (mean, diff) = (0.5 * (hxx + hyy), 0.5 * (hxx - hyy));
    let root = (diff * diff + hxy * hxy).sqrt();
    let (l1, l2) = (mean + root, mean - root);
    if !(l1.is_finite() && l2.is_finite() && l2 > 0.0) {
        return None;
    }
    // Unit eigenvectors of [[hxx, hxy], [hxy, hyy]]: angle θ with tan 2θ = 2 hxy/(hxx − hyy).
    let theta = 0.5 * (2.0 * hxy).atan2(hxx - hyy);
    let (c, s) = (theta.cos(), theta.sin());
    // Δχ² = ½ λ r² = 2.30 along an eigenvector at r = √(4.6/λ).
    let r = |l: f64| (2.0 * CONTOUR_LEVELS[0] / l).sqrt();
    let (r1, r2) = (r(l1), r(l2));
    Some([(c * r1 * w.0, s * r1 * w.1), (-s * r2 * w.0, c * r2 * w.1)])
}

/// The Δχ² surface of `grid.x` and `grid.y` around the best fit `result` of `settings` (as returned by
/// [`super::fit`] for the same model and data): at each grid point the two parameters are held and the
/// other free parameter, if any, is re-minimised (1-D Brent within 20 starting steps of its best-fit
/// value, as for the intervals of [`super::fit`]). The grid runs along the principal axes of the
/// Δχ² ellipse over ±`span` times its 2.30 semi-axes (module docs), or along x and y over ±`span`
/// times their 1σ half-widths where the Hessian is not positive definite. χ² is even in σ0, so grid
/// points with σ0 < 0 mirror those at |σ0|.
///
/// # Errors
/// [`Error::InvalidParameter`] if x = y, either is not free, the grid has fewer than 3 or more than 401
/// points per axis or a span that is not finite and positive; as [`super::fit`].
pub fn contour(
    model: &MultipoleModel,
    data: &MultipoleData,
    settings: &FitSettings,
    result: &FitResult,
    grid: &ContourGrid,
) -> Result<Contour> {
    let free = &settings.free;
    check(model, data, free)?;
    if grid.x == grid.y || !free.contains(&grid.x) || !free.contains(&grid.y) {
        return Err(Error::InvalidParameter {
            name: "contour parameters (number free among the two)",
            value: [grid.x, grid.y].iter().filter(|p| free.contains(p)).count() as f64,
            reason: "must be two different free parameters",
        });
    }
    if !(3..=401).contains(&grid.points) {
        return Err(Error::InvalidParameter {
            name: "contour grid points per axis",
            value: grid.points as f64,
            reason: "must be between 3 and 401",
        });
    }
    if !(grid.span.is_finite() && grid.span > 0.0) {
        return Err(Error::InvalidParameter {
            name: "contour span (in 1-sigma half-widths)",
            value: grid.span,
            reason: "must be finite and positive",
        });
    }
    let residuals = Residuals::new(model, data, settings.k_min, result.k_max, free.len())?;
    let window = Window {
        residuals: &residuals,
        base: settings.start,
        free: free.clone(),
    };
    let x0: Vec<f64> = free.iter().map(|&p| settings.start.get(p)).collect();
    let steps = steps(free, &x0);
    let profile =
        |x: f64, y: f64| window.profile(&[(grid.x, x), (grid.y, y)], &result.best, &steps);
    let centre = (result.best.get(grid.x), result.best.get(grid.y));
    let w = (half_width(grid.x, result), half_width(grid.y, result));
    let (axes, principal) = match principal_axes(&|x, y| profile(x, y).0, centre, w) {
        Some(axes) => (axes, true),
        None => ([(w.0, 0.0), (0.0, w.1)], false),
    };
    let n = grid.points;
    let u: Vec<f64> = (0..n)
        .map(|i| grid.span * (2.0 * i as f64 / (n - 1) as f64 - 1.0))
        .collect();
    let (mut points, mut chi2, mut at) = (Vec::new(), Vec::new(), Vec::new());
    for &a in &u {
        let row: Vec<(f64, f64)> = u
            .iter()
            .map(|&b| {
                (
                    centre.0 + a * axes[0].0 + b * axes[1].0,
                    centre.1 + a * axes[0].1 + b * axes[1].1,
                )
            })
            .collect();
        let (c, p): (Vec<f64>, Vec<Params>) = row.iter().map(|&(x, y)| profile(x, y)).unzip();
        points.push(row);
        chi2.push(c);
        at.push(p);
    }
    Ok(Contour {
        k_max: result.k_max,
        x: grid.x,
        y: grid.y,
        chi2_min: result.chi2,
        centre,
        axes,
        principal,
        points,
        chi2,
        at,
    })
}

#[cfg(test)]
mod tests {
    use super::super::{chi2, fit};
    use super::*;
    use crate::linear::LinearSpectrum;
    use crate::precision::Precision;
    use crate::real::{real_space, RealModel};
    use crate::rsd::{Fog, RsdModel};
    use crate::store::TableStore;

    /// Linear Kaiser with FoG `fog` (growth factor 1) for ℓ = 0, 2, 4 on `k`, bias 2 before A_b; data:
    /// the model at (f, σ0, A_b) = (0.48, 4, 1) moved by ±0.7σ (alternating), 1% errors of P0.
    fn setup(k: &[f64], fog: Fog) -> (MultipoleModel, MultipoleData) {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let real = real_space(
            RealModel::Linear,
            &p,
            k,
            &Precision::fast(),
            &TableStore::in_memory(),
        )
        .unwrap();
        let model = MultipoleModel::new(
            &real,
            None,
            RsdModel::Kaiser,
            fog,
            1.0,
            vec![2.0; k.len()],
            &[0, 2, 4],
        )
        .unwrap();
        let truth = Params {
            f: 0.48,
            sigma0: 4.0,
            amplitude: 1.0,
            cs2: 0.0,
        };
        let m = model.multipoles(&truth);
        let sigma: Vec<f64> = m[0].iter().map(|p| 0.01 * p).collect();
        let values: Vec<Vec<f64>> = m
            .iter()
            .enumerate()
            .map(|(j, ml)| {
                ml.iter()
                    .zip(&sigma)
                    .enumerate()
                    .map(|(i, (v, s))| v + if (i + j) % 2 == 0 { 0.7 } else { -0.7 } * s)
                    .collect()
            })
            .collect();
        let data =
            MultipoleData::from_arrays(k.to_vec(), &[0, 2, 4], values, vec![sigma; 3], "mock")
                .unwrap();
        (model, data)
    }

    /// χ² summed here from the model's multipoles, independently of the fit's windows.
    fn direct_chi2(model: &MultipoleModel, data: &MultipoleData, p: &Params, k_max: f64) -> f64 {
        let m = model.multipoles(p);
        let mut sum = 0.0;
        for (j, mj) in m.iter().enumerate() {
            for i in (0..data.k.len()).filter(|&i| data.k[i] <= k_max) {
                sum += ((data.values[j][i] - mj[i]) / data.sigma[j][i]).powi(2);
            }
        }
        sum
    }

    #[test]
    fn two_parameter_surfaces_are_direct_chi2_and_their_levels_are_the_intervals() {
        let k = crate::linear::LogGrid::new(0.01, 0.2, 25).unwrap().points();
        let (model, data) = setup(&k, Fog::None);
        let settings = FitSettings {
            free: vec![Parameter::F, Parameter::Amplitude],
            start: Params {
                f: 0.5,
                sigma0: 0.0,
                amplitude: 1.05,
                cs2: 0.0,
            },
            k_min: 0.0,
        };
        let r = &fit(&model, &data, &settings, &[0.15]).unwrap()[0];
        let grid = ContourGrid {
            x: Parameter::F,
            y: Parameter::Amplitude,
            points: 61,
            span: 2.0,
        };
        let c = contour(&model, &data, &settings, r, &grid).unwrap();
        assert!(c.principal);
        // No other free parameter: every grid value is χ² at that point, summed independently.
        for (i, row) in c.points.iter().enumerate() {
            for (j, &(x, y)) in row.iter().enumerate() {
                let p = Params {
                    f: x,
                    amplitude: y,
                    cs2: 0.0,
                    ..settings.start
                };
                let want = direct_chi2(&model, &data, &p, 0.15);
                assert!(
                    (c.chi2[i][j] - want).abs() < 1e-9 * want,
                    "{} {want}",
                    c.chi2[i][j]
                );
                assert_eq!(chi2(&model, &data, &p, 0.0, 0.15).unwrap(), c.chi2[i][j]);
            }
        }
        // The Δχ² = 2.30 contour (crossings on the grid's edges, linearly interpolated) reaches exactly
        // the fit's 1σ interval of f, found by bisection on the profile, at its two ends.
        let (lo, hi) = x_extent(&c, CONTOUR_LEVELS[0]);
        let (_, f_lo, f_hi) = r.intervals[0];
        let width = f_hi - f_lo;
        assert!(
            (lo - f_lo).abs() < 0.01 * width,
            "[{lo}, {hi}] vs [{f_lo}, {f_hi}]"
        );
        assert!(
            (hi - f_hi).abs() < 0.01 * width,
            "[{lo}, {hi}] vs [{f_lo}, {f_hi}]"
        );
        // The grid holds the 6.17 contour: its border is above it, its centre at the minimum.
        let n = c.points.len() - 1;
        let border = (0..=n).flat_map(|i| [c.chi2[i][0], c.chi2[i][n], c.chi2[0][i], c.chi2[n][i]]);
        assert!(border.fold(f64::INFINITY, f64::min) - c.chi2_min > CONTOUR_LEVELS[1]);
        assert!((c.chi2[n / 2][n / 2] - c.chi2_min).abs() < 1e-6);
    }

    /// The least and largest x where Δχ² crosses `level` on an edge of the grid, linearly interpolated.
    fn x_extent(c: &Contour, level: f64) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let n = c.points.len();
        let d = |i: usize, j: usize| c.chi2[i][j] - c.chi2_min - level;
        for i in 0..n {
            for j in 0..n {
                for (i2, j2) in [(i + 1, j), (i, j + 1)] {
                    if i2 < n && j2 < n && d(i, j) * d(i2, j2) < 0.0 {
                        let t = d(i, j) / (d(i, j) - d(i2, j2));
                        let x = c.points[i][j].0 + t * (c.points[i2][j2].0 - c.points[i][j].0);
                        (lo, hi) = (lo.min(x), hi.max(x));
                    }
                }
            }
        }
        (lo, hi)
    }

    #[test]
    fn three_parameter_surfaces_minimise_the_third_as_a_fine_scan_does() {
        let k = crate::linear::LogGrid::new(0.01, 0.25, 25)
            .unwrap()
            .points();
        let (model, data) = setup(&k, Fog::Lorentzian);
        let settings = FitSettings {
            free: vec![Parameter::F, Parameter::Sigma0, Parameter::Amplitude],
            start: Params {
                f: 0.5,
                sigma0: 3.5,
                amplitude: 1.05,
                cs2: 0.0,
            },
            k_min: 0.0,
        };
        let r = &fit(&model, &data, &settings, &[0.25]).unwrap()[0];
        let grid = ContourGrid {
            x: Parameter::F,
            y: Parameter::Amplitude,
            points: 5,
            span: 2.5,
        };
        let c = contour(&model, &data, &settings, r, &grid).unwrap();
        for (i, row) in c.points.iter().enumerate() {
            for (j, &(x, y)) in row.iter().enumerate() {
                // σ0 on a fine scan of [0, 10] Mpc/h (χ² is even in σ0), then a finer one around the
                // best node: its minimum can only be above the true one, by ~1e-6 here.
                let at = |s: f64| {
                    let p = Params {
                        f: x,
                        sigma0: s,
                        amplitude: y,
                        cs2: 0.0,
                    };
                    direct_chi2(&model, &data, &p, 0.25)
                };
                let coarse = (0..=2000)
                    .map(|n| 0.005 * n as f64)
                    .min_by(|a, b| at(*a).total_cmp(&at(*b)))
                    .unwrap();
                let scan = (-1000..=1000)
                    .map(|n| at((coarse + 1e-5 * n as f64).abs()))
                    .fold(f64::INFINITY, f64::min);
                let got = c.chi2[i][j];
                assert!(
                    got <= scan + 1e-6 * scan && got > scan - 1e-3,
                    "{got} vs scan {scan}"
                );
                assert!(
                    (c.at[i][j].sigma0.abs() - coarse).abs() < 0.05,
                    "{:?} {coarse}",
                    c.at[i][j]
                );
            }
        }
        let centre = c.chi2[2][2] - c.chi2_min;
        assert!(centre.abs() < 1e-5, "Δχ² at the best fit: {centre}");
    }

    #[test]
    fn bad_contour_requests_are_refused() {
        let k = crate::linear::LogGrid::new(0.01, 0.2, 10).unwrap().points();
        let (model, data) = setup(&k, Fog::None);
        let settings = FitSettings {
            free: vec![Parameter::F, Parameter::Amplitude],
            start: Params {
                f: 0.5,
                sigma0: 0.0,
                amplitude: 1.0,
                cs2: 0.0,
            },
            k_min: 0.0,
        };
        let r = &fit(&model, &data, &settings, &[0.2]).unwrap()[0];
        for (x, y, points, span) in [
            (Parameter::F, Parameter::F, 11, 2.0),
            (Parameter::F, Parameter::Sigma0, 11, 2.0),
            (Parameter::F, Parameter::Amplitude, 2, 2.0),
            (Parameter::F, Parameter::Amplitude, 11, f64::NAN),
        ] {
            let grid = ContourGrid { x, y, points, span };
            assert!(
                contour(&model, &data, &settings, r, &grid).is_err(),
                "{grid:?}"
            );
        }
        let t = crate::jobs::contour_table(
            &[contour(
                &model,
                &data,
                &settings,
                r,
                &ContourGrid {
                    x: Parameter::F,
                    y: Parameter::Amplitude,
                    points: 3,
                    span: 1.0,
                },
            )
            .unwrap()],
            &settings.free,
            vec![],
        );
        assert_eq!(
            t.names(),
            ["k_max", "i", "j", "f", "ab", "chi2", "delta_chi2"]
        );
        assert_eq!(t.rows(), 9);
    }
}

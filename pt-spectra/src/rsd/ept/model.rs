//! The ept model at fixed parameters on the terms' grid, evaluated at grid points or interpolated in
//! ln k ([`super::EptPlan`]'s multipoles).

use super::{EptParams, EptTerms};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::rsd::ap::spline::{self, UniformSpline};
use crate::rsd::MAX_MU_POWER;
use std::borrow::Cow;
use std::sync::OnceLock;

/// Polynomials in μ² (coefficient n of μ^{2n}) with coefficient errors.
type Poly = ([f64; MAX_MU_POWER + 1], [f64; MAX_MU_POWER + 1]);

/// The μ² coefficients of N then those of W at one grid point: what the interpolant in ln k is
/// applied to (samples, or their cubic B-spline coefficients, [`crate::rsd::ap::spline`]).
type Columns = [f64; 2 * (MAX_MU_POWER + 1)];

/// The model at fixed parameters on the terms' grid: P = N(μ²) + e^{−k²Σ²(1 + f(2+f)μ²)} W(μ²).
/// Between grid points, N and W are interpolated in ln k by the cubic B-spline of
/// [`crate::rsd::ap::spline`]: its coefficients are made on first use, once per model, and every
/// path (values, errors, f-derivatives, tangents, AP derivatives) applies the same weights to them.
pub(super) struct Model<'a> {
    grid: &'a [f64],
    spline: &'a UniformSpline,
    /// ln of the first grid point and the grid's step in ln k (log-uniform).
    ln_k0: f64,
    ln_step: f64,
    parts: Vec<(Poly, Poly)>,
    /// The spline coefficients of the parts' values and of their errors.
    coefficients: OnceLock<Vec<Columns>>,
    error_coefficients: OnceLock<Vec<Columns>>,
    sigma2: f64,
    f: f64,
}

/// The columns of (N, W) pairs.
fn columns<'b>(parts: impl Iterator<Item = (&'b [f64; 5], &'b [f64; 5])>) -> Vec<Columns> {
    parts
        .map(|(n, w)| std::array::from_fn(|q| if q < 5 { n[q] } else { w[q - 5] }))
        .collect()
}

impl EptTerms {
    /// The model with the errors of its polynomials.
    pub(super) fn model(&self, params: &EptParams) -> Model<'_> {
        self.model_with(params, true)
    }

    /// The model without the errors of its polynomials (zero; the multipoles' values).
    pub(super) fn model_values(&self, params: &EptParams) -> Model<'_> {
        self.model_with(params, false)
    }

    fn model_with(&self, params: &EptParams, errors: bool) -> Model<'_> {
        let v = &params.values;
        let [b1, _, _, _, f] = params.monomial_params();
        let z1 = [b1 * b1, 2.0 * b1 * f, f * f];
        let (alpha, [sn, sn2, sn4]) = ([v[4], v[5], v[6], v[7]], [v[8], v[9], v[10]]);
        let s2 = self.nw.as_ref().map_or(0.0, |(_, s)| s.value);
        // The terms of the full and no-wiggle spectra are in the same order.
        let coefficients = self.full.coefficients(params.monomial_params());
        let values_only = |t: &crate::loops::redshift::RedshiftTerms| {
            (!errors).then(|| t.loop_values_all(&coefficients))
        };
        let (full_values, nw_values) = (
            values_only(&self.full),
            self.nw.as_ref().and_then(|(t, _)| values_only(t)),
        );
        let parts = (0..self.grid.len())
            .map(|i| {
                let k = self.grid[i];
                let k2 = k * k;
                let p = self.full.p_lin[i];
                let with = |t: &crate::loops::redshift::RedshiftTerms,
                            values: &Option<Vec<[f64; 5]>>| match values
                {
                    Some(v) => (v[i], [0.0; 5]),
                    None => t.loop_polynomial_with(i, &coefficients),
                };
                let (lv, le) = with(&self.full, &full_values);
                let mut n: Poly = (lv, le);
                let mut w: Poly = ([0.0; 5], [0.0; 5]);
                let (p_nw, p_w) = match &self.nw {
                    Some((t, _)) => {
                        let (nv, ne) = with(t, &nw_values);
                        n = (nv, ne);
                        for j in 0..5 {
                            w.0[j] = lv[j] - nv[j];
                            w.1[j] = le[j] + ne[j];
                        }
                        (t.p_lin[i], p - t.p_lin[i])
                    }
                    None => (p, 0.0),
                };
                // Z₁² P_nw, the counterterms and the stochastic terms.
                for (j, z) in z1.iter().enumerate() {
                    n.0[j] += z * p_nw;
                }
                for (j, a) in alpha.iter().enumerate() {
                    n.0[j] += a * k2 * p_nw;
                    w.0[j] += a * k2 * p_w;
                }
                n.0[0] += sn;
                n.0[1] += sn2 * k2;
                n.0[2] += sn4 * k2 * k2;
                // (1 + k²Σ²[1 + f(2+f)μ²]) Z₁² P_w.
                let (c0, c1) = (1.0 + k2 * s2, k2 * s2 * f * (2.0 + f));
                for (j, z) in z1.iter().enumerate() {
                    w.0[j] += c0 * z * p_w;
                    w.0[j + 1] += c1 * z * p_w;
                }
                (n, w)
            })
            .collect();
        let g = &self.grid;
        Model {
            grid: g,
            spline: &self.spline,
            ln_k0: g[0].ln(),
            ln_step: (g[g.len() - 1] / g[0]).ln() / (g.len() - 1) as f64,
            parts,
            coefficients: OnceLock::new(),
            error_coefficients: OnceLock::new(),
            sigma2: s2,
            f: params.f(),
        }
    }
}

/// ∂/∂f of a model's μ² polynomials (values) at every grid point, (N, W) as in [`Model`], with the
/// damping held: the loop part through its monomials' f-derivatives ([`crate::loops::redshift::RedshiftTerms::coefficients_df`]),
/// Z₁² = (b₁ + fμ²)² and the resummation's (1 + k²Σ²[1 + f(2 + f)μ²]) Z₁² P_w by the product rule.
pub(super) type PartsDf = Vec<([f64; 5], [f64; 5])>;

impl EptTerms {
    /// The f-derivative of the model of `params` ([`PartsDf`]).
    pub(super) fn parts_df(&self, params: &EptParams) -> PartsDf {
        let [b1, _, _, _, f] = params.monomial_params();
        let (z1, dz1) = ([b1 * b1, 2.0 * b1 * f, f * f], [0.0, 2.0 * b1, 2.0 * f]);
        let s2 = self.nw.as_ref().map_or(0.0, |(_, s)| s.value);
        let dc = self.full.coefficients_df(params.monomial_params());
        let full = self.full.loop_values_all(&dc);
        let nw = self.nw.as_ref().map(|(t, _)| (t, t.loop_values_all(&dc)));
        (0..self.grid.len())
            .map(|i| {
                let k2 = self.grid[i] * self.grid[i];
                let p = self.full.p_lin[i];
                let (mut dn, mut dw) = (full[i], [0.0; 5]);
                let (p_nw, p_w) = match &nw {
                    Some((t, values)) => {
                        dn = values[i];
                        for j in 0..5 {
                            dw[j] = full[i][j] - values[i][j];
                        }
                        (t.p_lin[i], p - t.p_lin[i])
                    }
                    None => (p, 0.0),
                };
                for j in 0..3 {
                    dn[j] += dz1[j] * p_nw;
                }
                let (c0, c1, dc1) = (
                    1.0 + k2 * s2,
                    k2 * s2 * f * (2.0 + f),
                    k2 * s2 * (2.0 + 2.0 * f),
                );
                for j in 0..3 {
                    dw[j] += c0 * dz1[j] * p_w;
                    dw[j + 1] += (dc1 * z1[j] + c1 * dz1[j]) * p_w;
                }
                (dn, dw)
            })
            .collect()
    }
}

/// The change of the BAO damping e^{−k'²Σ²[1 + f(2 + f)μ'²]} that comes with a tangent of
/// [`project_many`]: its f-derivative, or its Σ²-derivative times dΣ² (a direction of the linear
/// spectrum, [`super::tangent`]).
#[derive(Debug, Clone, Copy)]
pub(super) enum DampingTangent {
    /// ∂/∂f.
    F,
    /// dΣ² ∂/∂Σ².
    Sigma2(f64),
}

impl EptTerms {
    /// ∂/∂Σ² of the model's μ² polynomials at fixed terms and parameters (the resummation's
    /// (1 + k²Σ²[1 + f(2 + f)μ²]) Z₁² P_w), times `d_sigma2`, added to `parts` ([`PartsDf`]).
    pub(super) fn add_parts_dsigma2(&self, params: &EptParams, d_sigma2: f64, parts: &mut PartsDf) {
        let Some((t, _)) = &self.nw else {
            return;
        };
        let [b1, _, _, _, f] = params.monomial_params();
        let z1 = [b1 * b1, 2.0 * b1 * f, f * f];
        for (i, (_, dw)) in parts.iter_mut().enumerate() {
            let k2 = self.grid[i] * self.grid[i];
            let p_w = self.full.p_lin[i] - t.p_lin[i];
            let (c0, c1) = (k2 * d_sigma2, k2 * d_sigma2 * f * (2.0 + f));
            for j in 0..3 {
                dw[j] += c0 * z1[j] * p_w;
                dw[j + 1] += c1 * z1[j] * p_w;
            }
        }
    }
}

/// The multipoles of several models of one f and Σ² (those of one terms' set) at the output `k_out`:
/// `nodes` per μ node (ln(k'/k), (k'/k)², μ'), `weights[m][j]` the weight of the j-th ℓ at μ node
/// m; `on_grid`: k_out is the models' grid and undistorted (each k its own grid point), else
/// P(k', μ') is interpolated (the cubic B-spline in ln k of [`Model`]). Per k, the projection is
/// made once as weights on the μ² coefficients of the grid points its stencils reach (on the
/// samples on the grid, else on their spline coefficients), then applied to each model:
/// `out[s][j][i]`. With `df` (models of the same f and Σ² with their [`PartsDf`]), also the
/// f-derivatives of their multipoles: those of the polynomials, projected, and that of the damping
/// e^{−k'²Σ²[1 + f(2 + f)μ'²]}; or, with [`DampingTangent::Sigma2`], their tangents along a direction
/// of the linear spectrum (the polynomials' changes, and the damping's through dΣ²).
pub(super) fn project_many(
    models: &[Model<'_>],
    df: &[(&Model<'_>, PartsDf, DampingTangent)],
    k_out: &[f64],
    nodes: &[(f64, f64, f64)],
    weights: &[Vec<f64>],
    on_grid: bool,
) -> Result<Multipoles> {
    let Some(first) = models.first().or(df.first().map(|d| d.0)) else {
        return Ok((Vec::new(), Vec::new()));
    };
    let n_ell = weights.first().map_or(0, Vec::len);
    let mut out = vec![vec![vec![0.0; k_out.len()]; n_ell]; models.len()];
    let mut out_df = vec![vec![vec![0.0; k_out.len()]; n_ell]; df.len()];
    // The weights of one output k, [ℓ][grid point − lo][N's five μ² powers, then W's] (`wv`), so that
    // a set's multipole is one contiguous dot product with its columns from `lo`; and of W in the
    // damping's f- and Σ²-derivatives (`wf`, `ws`: N's half zero), applied to the values' columns.
    const WIDTH: usize = 2 * (MAX_MU_POWER + 1);
    let (mut wv, mut wf, mut ws) = (Vec::new(), Vec::new(), Vec::new());
    let mut stencils = Vec::with_capacity(nodes.len());
    // what the weights apply to: the samples on the grid, else their spline coefficients (the
    // f-derivatives' and tangents' as the values')
    let model_columns: Vec<Cow<'_, [Columns]>> =
        models.iter().map(|m| m.columns(on_grid)).collect();
    let df_columns: Vec<(Vec<Columns>, Cow<'_, [Columns]>)> = df
        .iter()
        .map(|(m, d, _)| {
            let mut c = columns(d.iter().map(|(n, w)| (n, w)));
            if !on_grid {
                m.spline.prefilter(&mut c);
            }
            (c, m.columns(on_grid))
        })
        .collect();
    for (i, &k) in k_out.iter().enumerate() {
        let (ln_k, k2) = (k.ln(), k * k);
        stencils.clear();
        let (mut lo, mut hi) = (usize::MAX, 0);
        for &(ln_ratio, ratio2, mt) in nodes {
            let (b, l, width) = if on_grid {
                (i, [1.0, 0.0, 0.0, 0.0], 1)
            } else {
                let (b, t) = first.stencil_ln(ln_k + ln_ratio)?;
                (b, spline::weights(t), 4)
            };
            let m2 = mt * mt;
            let x = k2 * ratio2 * first.sigma2;
            let damping = (-x * (1.0 + first.f * (2.0 + first.f) * m2)).exp();
            let damping_df = -x * (2.0 + 2.0 * first.f) * m2 * damping;
            let damping_ds = -k2 * ratio2 * (1.0 + first.f * (2.0 + first.f) * m2) * damping;
            stencils.push((b, l, width, m2, damping, [damping_df, damping_ds]));
            lo = lo.min(b);
            hi = hi.max(b + width);
        }
        let span = hi - lo;
        let block = span * WIDTH;
        wv.clear();
        wv.resize(n_ell * block, 0.0);
        for o in [&mut wf, &mut ws] {
            o.clear();
            o.resize(if df.is_empty() { 0 } else { n_ell * block }, 0.0);
        }
        for (&(b, l, width, m2, damping, [damping_df, damping_ds]), c) in
            stencils.iter().zip(weights)
        {
            let mut powers = [1.0; 5];
            for q in 1..5 {
                powers[q] = powers[q - 1] * m2;
            }
            for (j, lj) in l.iter().enumerate().take(width) {
                for (e, ce) in c.iter().enumerate() {
                    let base = e * block + (b + j - lo) * WIDTH;
                    let (wn, ww) = (ce * lj, ce * lj * damping);
                    let w = &mut wv[base..base + WIDTH];
                    for q in 0..5 {
                        w[q] += wn * powers[q];
                        w[5 + q] += ww * powers[q];
                    }
                    if !df.is_empty() {
                        let (a_f, a_s) = (ce * lj * damping_df, ce * lj * damping_ds);
                        for q in 0..5 {
                            wf[base + 5 + q] += a_f * powers[q];
                            ws[base + 5 + q] += a_s * powers[q];
                        }
                    }
                }
            }
        }
        let range = lo * WIDTH..hi * WIDTH;
        for (cols, o) in model_columns.iter().zip(out.iter_mut()) {
            let c = &cols.as_flattened()[range.clone()];
            for (oe, w) in o.iter_mut().zip(wv.chunks_exact(block)) {
                oe[i] = crate::simd::dot(w, c);
            }
        }
        for (((_, _, tangent), (d, cols)), o) in df.iter().zip(&df_columns).zip(out_df.iter_mut()) {
            let (od, scale) = match *tangent {
                DampingTangent::F => (&wf, 1.0),
                DampingTangent::Sigma2(ds) => (&ws, ds),
            };
            let (d, c) = (
                &d.as_flattened()[range.clone()],
                &cols.as_flattened()[range.clone()],
            );
            for ((oe, w), wd) in o
                .iter_mut()
                .zip(wv.chunks_exact(block))
                .zip(od.chunks_exact(block))
            {
                oe[i] = crate::simd::dot(w, d) + scale * crate::simd::dot(wd, c);
            }
        }
    }
    Ok((out, out_df))
}

/// The polynomial in μ² of the five coefficients of `c` from `offset` (N: 0, W: 5) at μ² = `m2`.
#[inline(always)]
fn horner(c: &Columns, offset: usize, m2: f64) -> f64 {
    (0..5).rev().fold(0.0, |a, q| a * m2 + c[offset + q])
}

/// Multipoles of several sets, `[s][j][i]`, and the f-derivatives of others.
pub(super) type Multipoles = (Vec<Vec<Vec<f64>>>, Vec<Vec<Vec<f64>>>);

/// The exact derivatives of the multipoles of every model of `models` (one growth rate f, one
/// Σ²: the sets of one spectrum and f) with respect to α∥ and α⊥ at (`apar`, `aperp`): `nodes` and
/// `weights` (the volume factor included) as [`project_many`]'s at that distortion, the stencils and
/// the damping made once for all models. With A = μ²/α∥², B = (1 − μ²)/α⊥², k'² = k²(A + B) and
/// μ'² = A/(A + B), so ∂ln k'/∂α∥ = −μ'²/α∥, ∂ln k'/∂α⊥ = −(1 − μ'²)/α⊥, ∂μ'²/∂α∥ = −2μ'²(1 − μ'²)/α∥
/// = −(α⊥/α∥) ∂μ'²/∂α⊥, and the volume 1/(α∥α⊥²) gives −1/α∥, −2/α⊥ times the value. P(k', μ') is
/// the cubic B-spline in ln k' of the μ² polynomials ([`Model`]) with the BAO damping: its
/// derivative is that of the spline (the weights' derivatives on the same coefficients, continuous
/// across cell edges) and of the damping.
pub(super) fn ap_derivatives_many(
    models: &[Model<'_>],
    k_out: &[f64],
    nodes: &[(f64, f64, f64)],
    weights: &[Vec<f64>],
    (apar, aperp): (f64, f64),
) -> Result<Vec<[Vec<Vec<f64>>; 2]>> {
    let Some(first) = models.first() else {
        return Ok(Vec::new());
    };
    let n_ell = weights.first().map_or(0, Vec::len);
    let mut out = vec![
        [
            vec![vec![0.0; k_out.len()]; n_ell],
            vec![vec![0.0; k_out.len()]; n_ell],
        ];
        models.len()
    ];
    let coefficients: Vec<&[Columns]> = models.iter().map(|m| m.coefficients()).collect();
    let horner_d = |c: &Columns, o: usize, m2: f64| {
        (1..5).rev().fold(0.0, |a, q| a * m2 + q as f64 * c[o + q])
    };
    let growth = first.f * (2.0 + first.f);
    for (i, &k) in k_out.iter().enumerate() {
        let (ln_k, k2) = (k.ln(), k * k);
        for (&(ln_ratio, ratio2, mt), c) in nodes.iter().zip(weights) {
            let (b, t) = first.stencil_ln(ln_k + ln_ratio)?;
            let l = spline::weights(t);
            let dl = spline::weights_derivative(t).map(|d| d / first.ln_step);
            let m2 = mt * mt;
            let x = k2 * ratio2 * first.sigma2;
            let damping = (-x * (1.0 + growth * m2)).exp();
            let d_lnk = -2.0 * x * (1.0 + growth * m2) * damping;
            let d_m2 = -x * growth * damping;
            let dm2 = 2.0 * m2 * (1.0 - m2);
            for (cols, o) in coefficients.iter().zip(out.iter_mut()) {
                // P, ∂P/∂ln k', ∂P/∂μ'²
                let (mut p, mut p_lnk, mut p_m2) = (0.0, 0.0, 0.0);
                for j in 0..4 {
                    let c = &cols[b + j];
                    let (nv, wv) = (horner(c, 0, m2), horner(c, 5, m2));
                    p += l[j] * (nv + damping * wv);
                    p_lnk += dl[j] * (nv + damping * wv) + l[j] * d_lnk * wv;
                    p_m2 += l[j] * (horner_d(c, 0, m2) + damping * horner_d(c, 5, m2) + d_m2 * wv);
                }
                let derivatives = [
                    -p_lnk * m2 / apar - p_m2 * dm2 / apar - p / apar,
                    -p_lnk * (1.0 - m2) / aperp + p_m2 * dm2 / aperp - 2.0 * p / aperp,
                ];
                for (o, d) in o.iter_mut().zip(derivatives) {
                    for (oe, ce) in o.iter_mut().zip(c) {
                        oe[i] += ce * d;
                    }
                }
            }
        }
    }
    Ok(out)
}

impl Model<'_> {
    /// The μ² polynomials (N, W) with their errors at every grid point.
    pub(super) fn parts(&self) -> &[(Poly, Poly)] {
        &self.parts
    }

    /// The cubic B-spline coefficients in ln k of the values of N and W, made on first use.
    fn coefficients(&self) -> &[Columns] {
        self.coefficients.get_or_init(|| {
            let mut c = columns(self.parts.iter().map(|(n, w)| (&n.0, &w.0)));
            self.spline.prefilter(&mut c);
            c
        })
    }

    /// The spline coefficients of the errors of N and W (the grid's error estimates carried to k
    /// as the values are; used in absolute value).
    fn error_coefficients(&self) -> &[Columns] {
        self.error_coefficients.get_or_init(|| {
            let mut c = columns(self.parts.iter().map(|(n, w)| (&n.1, &w.1)));
            self.spline.prefilter(&mut c);
            c
        })
    }

    /// What [`project_many`]'s weights apply to: the values of N and W at the grid points
    /// (`on_grid`), else their spline coefficients.
    fn columns(&self, on_grid: bool) -> Cow<'_, [Columns]> {
        if on_grid {
            Cow::Owned(columns(self.parts.iter().map(|(n, w)| (&n.0, &w.0))))
        } else {
            Cow::Borrowed(self.coefficients())
        }
    }

    /// P(k, μ) at grid index `i` (k = grid[i]).
    pub(super) fn at(&self, i: usize, k: f64, mu: f64) -> Estimate {
        let (n, w) = &self.parts[i];
        self.combine(n, w, k, mu)
    }

    /// The value only of [`Self::at`].
    pub(super) fn value_at(&self, i: usize, k: f64, mu: f64) -> f64 {
        let (n, w) = &self.parts[i];
        let m2 = mu * mu;
        let horner = |c: &[f64; 5]| c.iter().rev().fold(0.0, |a, c| a * m2 + c);
        let damping = (-k * k * self.sigma2 * (1.0 + self.f * (2.0 + self.f) * m2)).exp();
        horner(&n.0) + damping * horner(&w.0)
    }

    fn combine(&self, n: &Poly, w: &Poly, k: f64, mu: f64) -> Estimate {
        let m2 = mu * mu;
        let horner = |c: &[f64; 5]| c.iter().rev().fold(0.0, |a, c| a * m2 + c);
        let damping = (-k * k * self.sigma2 * (1.0 + self.f * (2.0 + self.f) * m2)).exp();
        Estimate::new(
            horner(&n.0) + damping * horner(&w.0),
            horner(&n.1) + damping * horner(&w.1),
        )
    }

    /// P(k, μ) at any k inside the grid: the polynomials interpolated in ln k (the cubic B-spline;
    /// their errors by the same weights on the absolute spline coefficients of the errors).
    pub(super) fn interpolated(&self, k: f64, mu: f64) -> Result<Estimate> {
        let (b, t) = self.stencil_ln(k.ln())?;
        let l = spline::weights(t);
        let (values, errors) = (self.coefficients(), self.error_coefficients());
        let mut n: Poly = ([0.0; 5], [0.0; 5]);
        let mut w: Poly = ([0.0; 5], [0.0; 5]);
        for (j, lj) in l.iter().enumerate() {
            let (v, e) = (&values[b + j], &errors[b + j]);
            for c in 0..5 {
                n.0[c] += lj * v[c];
                n.1[c] += lj * e[c].abs();
                w.0[c] += lj * v[5 + c];
                w.1[c] += lj * e[5 + c].abs();
            }
        }
        Ok(self.combine(&n, &w, k, mu))
    }

    /// N(μ²) and W(μ²) of [`Self::interpolated`]'s values at ln k (the AP projection has it per μ
    /// node without a logarithm per point), without the damping, which the projection makes for all
    /// k of a μ node at once ([`Self::damping_exponent`]).
    pub(super) fn interpolated_parts_ln(&self, ln_k: f64, mu: f64) -> Result<(f64, f64)> {
        let (b, t) = self.stencil_ln(ln_k)?;
        let l = spline::weights(t);
        let values = self.coefficients();
        let m2 = mu * mu;
        let (mut n, mut w) = (0.0, 0.0);
        for (j, lj) in l.iter().enumerate() {
            let c = &values[b + j];
            n += lj * horner(c, 0, m2);
            w += lj * horner(c, 5, m2);
        }
        Ok((n, w))
    }

    /// The damping's exponent per unit k² at μ: P = N + e^{k² × this} W.
    pub(super) fn damping_exponent(&self, mu: f64) -> f64 {
        -self.sigma2 * (1.0 + self.f * (2.0 + self.f) * mu * mu)
    }

    /// The cell of ln k on the grid: the first of the four spline coefficients it reads and the
    /// position t ∈ [0, 1] in it ([`UniformSpline::cell`]).
    fn stencil_ln(&self, ln_k: f64) -> Result<(usize, f64)> {
        let g = self.grid;
        self.spline
            .cell((ln_k - self.ln_k0) / self.ln_step)
            .ok_or_else(|| Error::OutOfRange {
                what: "the true spectrum of the Alcock-Paczynski projection".into(),
                k: ln_k.exp(),
                min: g[1],
                max: g[g.len() - 2],
            })
    }
}

//! The emulator's computation for one cosmology at one redshift, at its nodes x_i = k_i r_d, over a
//! [`Real`] type: `f64` for [`LinearEmulator::spectra`], [`crate::cosmology::background::CosmoDual`]
//! for the derivatives with respect to the sampled parameters ([`LinearEmulator::tracer_tangent`]).
//!
//! Everything that depends on the parameters is computed over `T`: the prior coordinates, the
//! Legendre features and the principal-component coefficients, the weight of the massless head, r_d,
//! the tilt (n_s − 1) ln(k h/k_pivot) with ln k = ln x − ln r_d, ln A_s and 2 ln(D_md/Ω_m). The
//! stored means, components and polynomial coefficients are constants, so the maps from the features
//! to the coefficients and from the coefficients to the node values are linear: they run lane by lane
//! ([`Lanes`]) in plain `f64` code, the components summed in f64 ([`simd::combine_rows_f32`]) so that
//! the node values are smooth functions of the parameters (finite differences of them converge).

use super::format::{self, HeadOf};
use super::{drag_horizon, LinearEmulator, PriorPoint, COORDINATES, RATIO_TAPER};
use crate::cosmology::background::Background;
use crate::cosmology::{Amplitude, Cosmology, Neutrinos};
use crate::dual::{Lanes, Real};
use crate::error::{Error, Result};
use crate::simd;

/// The emulated quantities of one cosmology at one redshift, at the nodes x_i = k_i r_d (fixed x_i:
/// k_i = x_i/r_d moves with r_d).
pub(super) struct Nodes<T> {
    /// The redshift, clamped to the emulator's range.
    pub z: f64,
    /// ln r_d, r_d the drag horizon in Mpc/h ([`drag_horizon`]; 0 for a file without rescaling).
    pub ln_r_d: T,
    /// k_i in h/Mpc (values), uniform in ln k.
    pub k: Vec<f64>,
    /// The spacing of the nodes in ln k.
    pub step: f64,
    /// The factors of the σ8 integral at the nodes (`super::sigma8_weights`).
    pub sigma8_weights: Vec<(f64, f64)>,
    /// ln P_cb(k_i) with P_cb in (Mpc/h)³.
    pub ln_p_cb: Vec<T>,
    /// ln(P_m/P_cb)(k_i): exactly 0 without massive neutrinos.
    pub ln_ratio: Vec<T>,
    /// f_cb(k_i) = d ln D_cb/d ln a.
    pub f_cb: Vec<T>,
    /// ln A_s (given, or set by σ8).
    pub ln_a_s: T,
    /// Σm_ν in eV.
    pub m_nu: f64,
}

/// A point's polynomial coefficients: those of the two base targets, and of each head's.
type PointCoefficients<T> = ([Vec<T>; 2], Vec<[Vec<T>; 2]>);

impl LinearEmulator {
    /// The emulated quantities of `cosmology` at `z` at the nodes, over `T`; `b` is `cosmology`'s
    /// parameters over `T` ([`Cosmology::background`] for values, [`Cosmology::seeded`] for values
    /// with derivatives). A cosmology normalised by σ8 gets its A_s from the values (no derivative:
    /// [`Cosmology::seeded`] refuses it).
    ///
    /// # Errors
    /// As [`spectra`](Self::spectra).
    pub(super) fn nodes<T: Lanes>(
        &self,
        cosmology: &Cosmology,
        b: &Background<T>,
        z: f64,
    ) -> Result<Nodes<T>> {
        let point = PriorPoint::of_background(b)?;
        let u = self.coordinates(&point)?;
        let m_nu = point.values[3];
        let head = self.head(cosmology.neutrinos, m_nu.value())?;
        // The massless head: CAMB's massless spectrum over the base's at Σm_ν = 0 (the edge of the
        // training box; CAMB's massless run is not the limit of its massive runs). Tapered in below
        // RATIO_TAPER, as the ratio's offset is tapered out, so P_cb and P_m are continuous in Σm_ν;
        // nothing changes from RATIO_TAPER up.
        let taper = if m_nu.value() < RATIO_TAPER {
            -(m_nu / RATIO_TAPER) + 1.0
        } else {
            T::cst(0.0)
        };
        let mut heads: Vec<(&format::Head, T)> =
            head.map(|h| (h, T::cst(1.0))).into_iter().collect();
        if taper.value() > 0.0 {
            heads.extend(self.head_of(HeadOf::Massless).map(|h| (h, taper)));
        }
        let (z0, z1) = self.z_range();
        if !(z >= z0 - 1e-12 && z <= z1 + 1e-12) {
            return Err(Error::InvalidParameter {
                name: "z",
                value: z,
                reason: "outside the linear-spectrum emulator's redshift range [0, 3]",
            });
        }
        let [ob, om, h, ..] = point.values;
        let n_s = point.values[7];
        let ln_r_d = if self.file.rescale {
            drag_horizon(ob, om, h, m_nu).ln()
        } else {
            T::cst(0.0)
        };
        let (lx0, lx1) = self.file.ln_x;
        let n_x = self.file.n_x;
        let step = (lx1 - lx0) / (n_x - 1) as f64;
        let ln_k: Vec<T> = (0..n_x)
            .map(|i| T::cst(lx0 + step * i as f64) - ln_r_d)
            .collect();
        // k_i = k_0 q^i (a geometric progression: no exponential per node)
        let ratio = step.exp();
        let k: Vec<f64> = std::iter::successors(Some(ln_k[0].value().exp()), |k| Some(k * ratio))
            .take(n_x)
            .collect();
        let z = z.clamp(z0, z1);
        let sigma8_weights = super::sigma8_weights(&k);
        // the second target, ln(P_m/P_cb), only with massive neutrinos (below, `ln_ratio` is zero
        // without them, its derivative in Σm_ν at 0 included)
        let with_ratio = m_nu.value() > 0.0;
        let point_coefficients = self.point_coefficients(&u, &heads, with_ratio);
        // the derivative in s only where f_cb is made (at z); σ8's shape at z = 0 and the massless
        // ratio need the values alone
        let shape_at = |z: f64, derivative: bool| {
            self.shape(&point_coefficients, &heads, z, derivative, with_ratio)
        };
        // The emulated ln(P_m/P_cb), continuous as Σm_ν → 0: P_m = P_cb exactly without massive
        // neutrinos (the emulated ratio is then its own error, and the neutrino head is 0 too: the
        // settings differ only in how the mass is shared); below RATIO_TAPER the ratio's value at
        // Σm_ν = 0 (its polynomial's offset, 7e-4 to 1.2e-3) is removed in proportion, so that P_m
        // meets P_cb at 0 instead of jumping by the offset at 0⁺.
        // the coefficients of the same point with Σm_ν = 0, if the taper applies (the massless head
        // adds nothing to the ratio)
        let massless = if m_nu.value() > 0.0 && taper.value() > 0.0 {
            let mut p = point;
            p.values[3] = T::cst(0.0);
            Some(self.point_coefficients(&self.coordinates(&p)?, &heads, true))
        } else {
            None
        };
        let ln_ratio = |shape: &Shape<T>, z: f64| -> Vec<T> {
            if m_nu.value() <= 0.0 {
                return vec![T::cst(0.0); shape.ratio.len()];
            }
            match &massless {
                Some(c) => (shape
                    .ratio
                    .iter()
                    .zip(&self.shape(c, &heads, z, false, true).ratio))
                .map(|(&r, &o)| r - taper * o)
                .collect(),
                None => shape.ratio.clone(),
            }
        };
        let shape = shape_at(z, true);
        // ln P_cb = G_cb + 2 ln(D_md/Ω_m) + ln A_s + (n_s − 1) ln(k h/k_pivot)
        let growth = |z: f64| {
            let (d_md, f) = b.growth_md_and_rate(z);
            ((d_md / om).ln() * 2.0, f)
        };
        let (growth_z, f_md) = growth(z);
        let ln_h_pivot = (h / point.k_pivot).ln();
        let tilt: Vec<T> = ln_k
            .iter()
            .map(|&lk| (n_s - 1.0) * (lk + ln_h_pivot))
            .collect();
        let ln_a_s = match point.ln_a_s {
            Some(ln_a_s) => ln_a_s,
            None => {
                let today = shape_at(z0, false);
                let today_ratio = ln_ratio(&today, z0);
                let growth_0 = growth(z0).0;
                let mut p_today: Vec<f64> = (0..n_x)
                    .map(|i| (today.cb[i] + growth_0 + today_ratio[i] + tilt[i]).value())
                    .collect();
                crate::simd::exp_in_place(&mut p_today);
                let sigma8_unit = super::sigma8(&sigma8_weights, step, |i| p_today[i]);
                let Amplitude::Sigma8(target) = cosmology.amplitude else {
                    unreachable!("ln A_s is None only for a σ8 amplitude")
                };
                T::cst(2.0 * (target / sigma8_unit).ln())
            }
        };
        let ln_p_cb: Vec<T> = (0..n_x)
            .map(|i| shape.cb[i] + growth_z + ln_a_s + tilt[i])
            .collect();
        Ok(Nodes {
            z,
            ln_r_d,
            k,
            step,
            sigma8_weights,
            ln_p_cb,
            ln_ratio: ln_ratio(&shape, z),
            f_cb: shape.d_cb_ds.iter().map(|&d| f_md - d * 0.5).collect(),
            ln_a_s,
            m_nu: m_nu.value(),
        })
    }

    /// The prior coordinates of `point` (the file's box, stated prior and early dark-energy bound).
    fn coordinates<T: Real>(&self, point: &PriorPoint<T>) -> Result<[T; COORDINATES]> {
        point.coordinates(
            &self.file.prior,
            &self.file.stated,
            self.file.a_early,
            self.file.q_max,
            self.file.q_bound,
        )
    }

    /// The polynomial coefficients of the targets and of the `heads`' at coordinates `u` (the second
    /// target's left empty unless `with_ratio`).
    fn point_coefficients<T: Lanes>(
        &self,
        u: &[T; COORDINATES],
        heads: &[(&format::Head, T)],
        with_ratio: bool,
    ) -> PointCoefficients<T> {
        let targets = if with_ratio { 2 } else { 1 };
        (
            coefficients(
                &self.file.exponents,
                &self.file.targets,
                u,
                self.max_degree,
                targets,
            ),
            heads
                .iter()
                .map(|(h, _)| coefficients(&h.exponents, &h.targets, u, self.max_degree, targets))
                .collect(),
        )
    }

    /// The targets at redshift `z` of a point's coefficients ([`Self::point_coefficients`]), each
    /// head added with its weight.
    fn shape<T: Lanes>(
        &self,
        (c, head_c): &PointCoefficients<T>,
        heads: &[(&format::Head, T)],
        z: f64,
        derivative: bool,
        with_ratio: bool,
    ) -> Shape<T> {
        let targets = if with_ratio { 2 } else { 1 };
        let mut shape = self.at_redshift(&self.file.targets, c, z, derivative, targets);
        for ((h, weight), hc) in heads.iter().zip(head_c) {
            shape.add(
                &self.at_redshift(&h.targets, hc, z, derivative, targets),
                *weight,
            );
        }
        shape
    }

    /// The neutrino head of the setting `setting` at Σm_ν = `m_nu` eV (`None`: three degenerate
    /// species, or massless).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a setting the file does not emulate.
    fn head(&self, setting: Neutrinos, m_nu: f64) -> Result<Option<&format::Head>> {
        if setting == Neutrinos::ThreeDegenerate || m_nu == 0.0 {
            return Ok(None);
        }
        match self.head_of(HeadOf::Setting(setting)) {
            Some(h) => Ok(Some(h)),
            None => Err(Error::InvalidChoice {
                what: format!("neutrinos: {}", setting.describe()),
                reason: format!(
                    "the linear-spectrum emulator ({}) emulates {} only: if that is what you mean, say \
                     so (CAMB num_massive_neutrinos = 3 with neutrino_hierarchy = degenerate; CLASS \
                     three equal m_ncdm, or N_ncdm = 1 with deg_ncdm = 3; the key `neutrinos = three \
                     degenerate`; the cobaya theory's option `neutrinos: three degenerate`), else give \
                     a linear spectrum (--linear FILE)",
                    self.origin,
                    self.neutrino_settings()
                        .iter()
                        .map(|s| s.describe())
                        .collect::<Vec<_>>()
                        .join("; ")
                ),
            }),
        }
    }

    /// The first `targets_used` targets (the others zero) at redshift `z` (four-node Lagrange interpolation in s = ln(1 + z)), and, with
    /// `derivative`, ∂(first target)/∂s (else zeros): per lane, the components weighted by the
    /// coefficients' lane, plus the mean on the value lane. Without the derivative a node of weight
    /// exactly 0 is skipped (at a redshift node, e.g. z = 0, three of the four: the values are the
    /// same, it adds 0 × its row).
    fn at_redshift<T: Lanes>(
        &self,
        targets: &[format::Target; 2],
        coefficients: &[Vec<T>; 2],
        z: f64,
        derivative: bool,
        targets_used: usize,
    ) -> Shape<T> {
        let nodes: Vec<f64> = self.file.z_nodes.iter().map(|z| z.ln_1p()).collect();
        let s = z.ln_1p();
        let interval = nodes.partition_point(|&v| v <= s).saturating_sub(1);
        let first = interval.saturating_sub(1).min(nodes.len() - 4);
        let window = &nodes[first..first + 4];
        let (w, dw) = lagrange(window, s);
        let n_x = self.file.n_x;
        let mut row = vec![0.0; n_x];
        let mut c_lane: Vec<f64> = Vec::new();
        // lanes[l] = [first target, second target, ∂(first target)/∂s] of lane l
        let lanes: Vec<[Vec<f64>; 3]> = (0..T::LANES)
            .map(|l| {
                let mut out = [vec![0.0; n_x], vec![0.0; n_x], vec![0.0; n_x]];
                let used = targets.iter().zip(coefficients).take(targets_used);
                for (t, (target, c)) in used.enumerate() {
                    c_lane.clear();
                    c_lane.extend(c.iter().map(|c| c.lane(l)));
                    let stride = target.mean.len();
                    for j in 0..4 {
                        if !derivative && w[j] == 0.0 {
                            continue;
                        }
                        let node = first + j;
                        let rows = &target.components[node * n_x..];
                        simd::combine_rows_f32(&mut row, &c_lane, rows, stride);
                        if l == 0 {
                            let mean = &target.mean[node * n_x..(node + 1) * n_x];
                            row.iter_mut().zip(mean).for_each(|(r, m)| *r += m);
                        }
                        for (o, &r) in out[t].iter_mut().zip(&row) {
                            *o += w[j] * r;
                        }
                        if t == 0 && derivative {
                            for (o, &r) in out[2].iter_mut().zip(&row) {
                                *o += dw[j] * r;
                            }
                        }
                    }
                }
                out
            })
            .collect();
        let gather = |t: usize| -> Vec<T> {
            (0..n_x)
                .map(|i| T::from_lanes(|l| lanes[l][t][i]))
                .collect()
        };
        Shape {
            cb: gather(0),
            ratio: gather(1),
            d_cb_ds: gather(2),
        }
    }
}

/// The targets at one redshift.
struct Shape<T> {
    cb: Vec<T>,
    ratio: Vec<T>,
    d_cb_ds: Vec<T>,
}

impl<T: Real> Shape<T> {
    /// Adds `weight` times a head's correction of ln P_cb to ln P_cb and of ln P_m − ln P_cb to
    /// ln(P_m/P_cb) (0 for the massless head, whose two targets are equal).
    fn add(&mut self, head: &Shape<T>, weight: T) {
        for i in 0..self.cb.len() {
            self.cb[i] += weight * head.cb[i];
            self.ratio[i] += weight * (head.ratio[i] - head.cb[i]);
            self.d_cb_ds[i] += weight * head.d_cb_ds[i];
        }
    }
}

/// The principal-component coefficients of two targets with polynomial terms `exponents` at the unit
/// point `u` (Legendre polynomials to `max_degree`): the features over `T`, then per lane the
/// features' lane times the stored coefficients; targets from `targets_used` on are left empty.
fn coefficients<T: Lanes>(
    exponents: &[[u8; COORDINATES]],
    targets: &[format::Target; 2],
    u: &[T; COORDINATES],
    max_degree: usize,
    targets_used: usize,
) -> [Vec<T>; 2] {
    let legendre: Vec<Vec<T>> = u.iter().map(|&x| legendre(x, max_degree)).collect();
    let features: Vec<T> = exponents
        .iter()
        .map(|e| {
            e.iter()
                .enumerate()
                .map(|(d, &n)| legendre[d][usize::from(n)])
                .fold(T::cst(1.0), |a, b| a * b)
        })
        .collect();
    [0, 1].map(|t| {
        if t >= targets_used {
            return Vec::new();
        }
        let t = &targets[t];
        let lanes: Vec<Vec<f64>> = (0..T::LANES)
            .map(|l| {
                let mut c = vec![0.0; t.n_pc];
                for (row, f) in t.coefficients.chunks_exact(t.n_pc).zip(&features) {
                    let f = f.lane(l);
                    for (cj, r) in c.iter_mut().zip(row) {
                        *cj += f * r;
                    }
                }
                c
            })
            .collect();
        (0..t.n_pc)
            .map(|j| T::from_lanes(|l| lanes[l][j]))
            .collect()
    })
}

/// Legendre polynomials P_0..P_n at x.
fn legendre<T: Real>(x: T, n: usize) -> Vec<T> {
    let mut p = vec![T::cst(1.0), x];
    for m in 1..n {
        let m_f = m as f64;
        p.push((x * (2.0 * m_f + 1.0) * p[m] - p[m - 1] * m_f) / (m_f + 1.0));
    }
    p.truncate(n + 1);
    p
}

/// Lagrange weights of four nodes at s, and of the derivative.
pub(super) fn lagrange(nodes: &[f64], s: f64) -> ([f64; 4], [f64; 4]) {
    let mut w = [0.0; 4];
    let mut dw = [0.0; 4];
    for j in 0..4 {
        let others: Vec<usize> = (0..4).filter(|&m| m != j).collect();
        let denominator: f64 = others.iter().map(|&m| nodes[j] - nodes[m]).product();
        w[j] = others.iter().map(|&m| s - nodes[m]).product::<f64>() / denominator;
        dw[j] = others
            .iter()
            .map(|&skip| {
                others
                    .iter()
                    .filter(|&&m| m != skip)
                    .map(|&m| s - nodes[m])
                    .product::<f64>()
            })
            .sum::<f64>()
            / denominator;
    }
    (w, dw)
}

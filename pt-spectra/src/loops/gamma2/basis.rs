//! RegPT's vertex terms of a new spectrum through the basis: the inner integral Γ2_X of every outer
//! node is linear in P, so with P ≈ Σ_a c_a φ_a it is Σ_a c_a W_Xa with W_Xa = Σ_r w_Xr φ_a(r) made
//! once per plan ([`Gamma2Plan::on_basis`]): per node 2n numbers instead of the 2 × (radial nodes)
//! weights, and no radial spectrum. The outer P(q) P(|k − q|) stay the spectrum's own lattice samples.
//!
//! Error: the plan's |fine − coarse| (both layouts on the basis) plus the response to the projection
//! residual ε: each Γ2 moves by at most ε Σ_r |w_r| P(r), taken as 2ε R S with S = Σ_r |w_r| P̄(r) for
//! the basis's mean spectrum P̄ (stored per node) and R the spectrum's mean ratio to it over the
//! lattice (the factor 2 covers the spread of shapes in the basis's span).

use super::{estimates, Gamma2Plan, Gamma2Terms, Nodes, PAIRS};
use crate::linear::LinearSpectrum;
use crate::loops::basis::{LinearBasis, Projection};
use crate::loops::lattice::Lattice;
use crate::loops::Estimate;
use crate::simd::dot32;
use rayon::prelude::*;

/// The Γ2 of every outer node of a [`Gamma2Plan`] as linear forms on a [`LinearBasis`].
#[derive(Debug, Clone)]
pub struct Gamma2Basis {
    n: usize,
    fine: NodeForms,
    coarse: NodeForms,
    /// 1/P̄ on the lattice divided by its length: R = Σ_j P_j this_j.
    inverse_mean: Vec<f64>,
}

/// Per outer node of one layout: W_F then W_G (n each), and S_F, S_G.
#[derive(Debug, Clone)]
struct NodeForms {
    forms: Vec<f32>,
    scales: Vec<[f64; 2]>,
}

impl NodeForms {
    fn new(nodes: &Nodes, lattice: &Lattice, basis: &LinearBasis, mean: &[f64]) -> Self {
        let n = basis.len();
        let radial = nodes.radial.len();
        // φ_a at the radial nodes (row r) and P̄ there.
        let mut phi = vec![0.0; radial * n];
        for (row, &(ln_r, _)) in phi.chunks_exact_mut(n).zip(&nodes.radial) {
            basis.at_ln(ln_r, row);
        }
        let mean_r: Vec<f64> = nodes
            .radial
            .iter()
            .map(|&(ln_r, _)| lattice.interpolate(mean, (ln_r - lattice.x0) / lattice.step))
            .collect();
        let per_node: Vec<(Vec<f32>, [f64; 2])> = (0..nodes.outer.len())
            .into_par_iter()
            .map(|j| {
                let w = &nodes.weights[2 * j * radial..2 * (j + 1) * radial];
                let mut forms = vec![0.0f64; 2 * n];
                let mut scales = [0.0; 2];
                for (x, wx) in w.chunks_exact(radial).enumerate() {
                    for ((&wr, row), pr) in wx.iter().zip(phi.chunks_exact(n)).zip(&mean_r) {
                        let wr = f64::from(wr);
                        forms[x * n..(x + 1) * n]
                            .iter_mut()
                            .zip(row)
                            .for_each(|(f, p)| *f += wr * p);
                        scales[x] += wr.abs() * pr;
                    }
                }
                (forms.iter().map(|&v| v as f32).collect(), scales)
            })
            .collect();
        let mut forms = Vec::with_capacity(per_node.len() * 2 * n);
        let mut scales = Vec::with_capacity(per_node.len());
        for (f, s) in per_node {
            forms.extend(f);
            scales.push(s);
        }
        Self { forms, scales }
    }

    /// [P24, PΓ2] of the three pairs at k index `i`, and their projection errors for ε R = `eps_r`.
    fn evaluate(
        &self,
        nodes: &Nodes,
        i: usize,
        (lattice, samples): (&Lattice, &[f64]),
        c: &[f64],
        eps_r: f64,
    ) -> ([[f64; 3]; 2], [[f64; 3]; 2]) {
        let n = c.len();
        let (mut out, mut err) = ([[0.0; 3]; 2], [[0.0; 3]; 2]);
        // The nodes of one q follow each other (q-major layout): P(q) once per q.
        let mut p_q = (f64::NAN, 0.0);
        for j in nodes.k_start[i]..nodes.k_start[i + 1] {
            let o = &nodes.outer[j];
            let w = &self.forms[2 * j * n..2 * (j + 1) * n];
            let g = [dot32(&w[..n], c), dot32(&w[n..], c)];
            let dg = self.scales[j].map(|s| eps_r * s);
            if o.u_q != p_q.0 {
                p_q = (o.u_q, lattice.interpolate(samples, o.u_q));
            }
            let spectra = o.weight * p_q.1 * lattice.interpolate(samples, o.u_p);
            for (m, (x, y)) in PAIRS.into_iter().enumerate() {
                out[0][m] += spectra * (o.f2[x] * g[y] + g[x] * o.f2[y]);
                out[1][m] += spectra * g[x] * g[y];
                let s = spectra.abs();
                err[0][m] += s * (o.f2[x].abs() * dg[y] + dg[x] * o.f2[y].abs());
                err[1][m] += s * (g[x].abs() * dg[y] + dg[x] * g[y].abs() + dg[x] * dg[y]);
            }
        }
        (out, err)
    }
}

impl Gamma2Plan {
    /// The plan's inner integrals as linear forms on `basis` (~0.1 s), or `None` if the basis is
    /// sampled on another lattice than the plan's.
    pub fn on_basis(&self, basis: &LinearBasis) -> Option<Gamma2Basis> {
        if basis.lattice() != &self.lattice {
            return None;
        }
        let lattice = &self.lattice;
        let mean = basis.mean_samples();
        let inverse_mean = mean.iter().map(|m| 1.0 / (m * mean.len() as f64)).collect();
        Some(Gamma2Basis {
            n: basis.len(),
            fine: NodeForms::new(&self.fine, lattice, basis, &mean),
            coarse: NodeForms::new(&self.coarse, lattice, basis, &mean),
            inverse_mean,
        })
    }
}

impl Gamma2Basis {
    /// P24 and PΓ2 of `spectrum` (its own lattice samples for the outer spectra) with projection
    /// `projection` on the basis of [`Gamma2Plan::on_basis`], at the plan's k; `None` if the
    /// projection is on a basis of another size.
    pub fn evaluate(
        &self,
        plan: &Gamma2Plan,
        spectrum: &LinearSpectrum,
        projection: &Projection,
    ) -> Option<Gamma2Terms> {
        let c = &projection.coefficients;
        if c.len() != self.n {
            return None;
        }
        let lattice = &plan.lattice;
        let samples = &spectrum.eval_ln_many((0..lattice.len).map(|j| lattice.x(j)));
        let ratio: f64 = crate::simd::dot(samples, &self.inverse_mean);
        let eps_r = 2.0 * projection.residual * ratio.abs();
        let on = (lattice, samples.as_slice());
        let rows: Vec<[[Estimate; 3]; 2]> = (0..plan.len())
            .into_par_iter()
            .map(|i| {
                let (a, da) = self.fine.evaluate(&plan.fine, i, on, c, eps_r);
                let (b, _) = self.coarse.evaluate(&plan.coarse, i, on, c, eps_r);
                estimates(a, b, da)
            })
            .collect();
        Some(Gamma2Terms::from_rows(&rows, Some(projection.residual)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loops::basis::training::camb_basis;
    use crate::loops::basis::BASIS_SIZE;

    /// On spectra the basis was not trained on (two CAMB tables, two curved ones and a CLASS one) P24
    /// and PΓ2 from the linear forms equal the integrals of the spectrum itself to 5e-5 of their size
    /// (measured: ≤ 1.1e-5; curved ones 2e-4, measured 8.2e-5) and within the errors (there ≤ 5.2e-3
    /// of the value, mostly the quadrature's).
    #[test]
    fn terms_on_the_basis_agree_with_the_integrals_for_spectra_not_trained_on() {
        let k = [0.02, 0.1, 0.25];
        let plan = Gamma2Plan::new(&k, (1e-5, 1e3), 0.02);
        let basis = camb_basis(plan.lattice.clone(), BASIS_SIZE);
        let forms = plan.on_basis(&basis).expect("same lattice");
        let other = camb_basis(Lattice::new(1e-5, 1e3, 0.01), 4);
        assert!(plan.on_basis(&other).is_none(), "another lattice");
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        for name in [
            "linear_pk_camb_heldout_0.dat",
            "linear_pk_camb_heldout_1.dat",
            "linear_pk_camb_curved_wa_z0.5.dat",
            "linear_pk_camb_closed_z0.0.dat",
            "linear_pk_class_planck2018_z0.0_pk_lin.dat",
        ] {
            let p = LinearSpectrum::from_file(format!("{dir}{name}")).unwrap();
            let projection = basis.project_spectrum(&p, crate::loops::basis::MAX_RESIDUAL);
            // The curved ones project cut below the soft modes (loops::basis::soft), to which each
            // 1-loop vertex responds by ~Δ/σ_v² of itself: measured ≤ 8.2e-5.
            let bound = if projection.soft.is_some() {
                2e-4
            } else {
                5e-5
            };
            let direct = plan.evaluate(&p);
            let on_basis = forms.evaluate(&plan, &p, &projection).unwrap();
            assert_eq!(on_basis.basis_residual, Some(projection.residual));
            for (a, d) in [
                (&on_basis.p24, &direct.p24),
                (&on_basis.p_gamma2, &direct.p_gamma2),
            ] {
                for ((_, a), (_, d)) in a.iter().zip(d.iter()) {
                    for (i, (a, d)) in a.iter().zip(d).enumerate() {
                        let diff = (a.value - d.value).abs();
                        assert!(diff <= bound * d.value.abs(), "{name} {i}: {a:?} {d:?}");
                        assert!(diff <= a.error, "{name} {i}: {a:?} {d:?}");
                    }
                }
            }
        }
    }
}

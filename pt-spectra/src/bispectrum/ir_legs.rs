//! The spectra of the one-loop bispectrum's IR resummation ([`super::one_loop_ir`]): P_LO for the loops and
//! the tree level's legs P_NLO (a leaf of the one-loop modules, which all use it).

use super::one_loop::Vec3;
use super::resum::IrInputs;
use crate::error::Result;
use crate::ir::sigma2_total;
use crate::linear::LinearSpectrum;
use crate::vec3::{dot, norm};

/// P_LO(q) = P_nw(q) + e^{−q²Σ²}[P(q) − P_nw(q)] ([`super::one_loop_ir`]) on the nodes of `p`'s table.
///
/// # Errors
/// As [`LinearSpectrum::from_nodes`] (not reached for a valid `p`: P_LO lies between P and P_nw > 0).
pub fn leading_order_spectrum(p: &LinearSpectrum, ir: &IrInputs) -> Result<LinearSpectrum> {
    let (k, pk) = p.nodes();
    let values = k
        .iter()
        .zip(pk)
        .map(|(&k, &pk)| {
            let nw = ir.no_wiggle.eval(k);
            nw + (-k * k * ir.sigma2).exp() * (pk - nw)
        })
        .collect();
    LinearSpectrum::from_nodes(k.to_vec(), values)
}

/// The tree level's legs P_NLO(k_a) = P_nw + e^{−x_a}(1 + x_a)P_w, x_a = k_a²Σ²_tot(μ_a), at the sides `kv`
/// ([`super::one_loop_ir`]), in real space (`redshift` None: x_a = k_a²Σ²) or at (f, line of sight).
pub(super) fn tree_legs(
    p: &LinearSpectrum,
    ir: &IrInputs,
    kv: &[Vec3; 3],
    redshift: Option<(f64, Vec3)>,
) -> [f64; 3] {
    kv.map(|v| {
        let k = norm(v);
        let (f, mu) = match redshift {
            None => (0.0, 0.0),
            Some((f, los)) => (f, dot(&v, &los) / k),
        };
        let x = k * k * sigma2_total(ir.sigma2, ir.delta_sigma2, f, mu);
        let (pk, nw) = (p.eval(k), ir.no_wiggle.eval(k));
        nw + (-x).exp() * (1.0 + x) * (pk - nw)
    })
}

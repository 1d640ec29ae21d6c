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
        next_to_leading(p.eval(k), ir.no_wiggle.eval(k), x)
    })
}

/// P_NLO = P_nw + e^{−x}(1 + x)(P − P_nw) of P and P_nw at a side, x = k²Σ²_tot(μ).
fn next_to_leading(pk: f64, nw: f64, x: f64) -> f64 {
    nw + (-x).exp() * (1.0 + x) * (pk - nw)
}

/// [`tree_legs`] in redshift space at growth rate `f` along each line of sight of `los`, the same numbers:
/// P and P_nw at the sides evaluated once for all lines of sight (the multipole tensors' tree level takes
/// 45 orientations of each triangle).
pub(super) fn tree_legs_along(
    p: &LinearSpectrum,
    ir: &IrInputs,
    kv: &[Vec3; 3],
    f: f64,
    los: &[Vec3],
) -> Vec<[f64; 3]> {
    let k = kv.map(norm);
    let (pk, nw) = (k.map(|k| p.eval(k)), k.map(|k| ir.no_wiggle.eval(k)));
    los.iter()
        .map(|n| {
            std::array::from_fn(|a| {
                let mu = dot(&kv[a], n) / k[a];
                let x = k[a] * k[a] * sigma2_total(ir.sigma2, ir.delta_sigma2, f, mu);
                next_to_leading(pk[a], nw[a], x)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The legs along many lines of sight are each line's [`tree_legs`] to the bit.
    #[test]
    fn legs_along_many_lines_of_sight_are_the_single_ones() {
        let p = LinearSpectrum::gm2012(0.5).unwrap();
        let split = crate::ir::WiggleSplit::new().unwrap();
        let ir = IrInputs::split(&p, &split, 1e-4).unwrap();
        let kv = super::super::one_loop::triangle_vectors([0.05, 0.07, 0.1]).unwrap();
        let los: Vec<Vec3> = (0..7)
            .map(|i| {
                let (mu, phi) = (-0.9 + 0.3 * f64::from(i), 0.7 * f64::from(i));
                let s = (1.0 - mu * mu).sqrt();
                [s * phi.cos(), s * phi.sin(), mu]
            })
            .collect();
        let many = tree_legs_along(&p, &ir, &kv, 0.7, &los);
        for (n, legs) in los.iter().zip(&many) {
            let one = tree_legs(&p, &ir, &kv, Some((0.7, *n)));
            assert_eq!(one.map(f64::to_bits), legs.map(f64::to_bits));
            assert!(legs.iter().all(|&l| l > 0.0));
        }
    }
}

//! The infrared (IR) resummation of the BAO in the one-loop galaxy bispectrum, at leading order: the
//! prescription of the one-loop EFT analyses (Ivanov & Sibiryakov 2018, arXiv:1804.05080; Philcox et al.
//! 2022, arXiv:2206.02800, whose one-loop templates are computed on the IR-resummed linear spectrum; the
//! power spectrum's P_nw + e^{−x}(1 + x)P_w + P_1loop(P_nw + e^{−x}P_w) of CLASS-PT). With the no-wiggle
//! split P = P_nw + P_w and the damping scales Σ², δΣ² of [`IrInputs`]:
//!
//! ```text
//! B_IR   = B_tree[P_NLO] + B_1loop[P_LO],
//! P_NLO  = P_nw(k_a) + e^{−x_a} (1 + x_a) P_w(k_a),   x_a = k_a² Σ²_tot(μ_a)   (each leg of the tree level),
//! P_LO   = P_nw(q) + e^{−q² Σ²} P_w(q)                                          (every leg of the loops),
//! Σ²_tot(μ) = [1 + fμ²(2 + f)] Σ² + f²μ²(μ² − 1) δΣ²,
//! ```
//!
//! B_1loop(P_LO) being B₂₂₂ + B₃₂₁ᴵ + B₃₂₁ᴵᴵ + B₄₁₁ with P_LO in place of P on every spectrum, inside the
//! integrals and at the sides (the renormalisation's σ² = ∫P_LO too). The (1 + x) of the tree level takes
//! out what the one-loop terms' own IR-enhanced part (≈ −x_a × the tree level's wiggles in leg a) would
//! count twice: to first order in x the wiggles of B_IR are those of the unresummed B_tree + B_1loop, and
//! to all orders in x they are damped by e^{−x_a} per leg. The tree level alone
//! ([`super::BispectrumPlan`]) resums with P_nw + e^{−x}P_w (no 1 + x: it has no loop).
//!
//! **What it neglects** (not in the errors, which are the loop rule's): the next-to-leading IR terms
//! (O(x) × the loops' wiggles, the size of the two-loop wiggles), and the anisotropy of the damping on the
//! loops' legs: P_LO is damped with the real-space Σ² (the loop momenta run over every direction, and a
//! leg's μ-dependent damping would tie the loops to the line of sight), so the one-loop terms' wiggles are
//! damped with Σ² where the tree level's are with Σ²_tot(μ_a) — a difference of
//! (Σ²_tot(μ) − Σ²)k² × the one-loop terms' wiggly part, of the order of the two-loop wiggles (bounded in
//! the tests: damping the loops with the largest Σ²_tot(μ = 1) moves B₀, B₂, B₄ by ≤ 6e-3 of B₀ at
//! 0.05–0.2 h/Mpc, z = 0.5). The wiggles' damping of the tree level is exact to leading order in each leg
//! (Σ²_tot(μ_a)).
//!
//! **Properties** (tested): with P_w = 0 (a smooth spectrum) B_IR is the unresummed B (the P_LO table equals
//! P to round-off); Σ² = δΣ² = 0 gives the unresummed B; at f = 0 the redshift-space terms are the
//! real-space resummed ones; every term stays a polynomial in the bias coefficients (the same monomials:
//! the damping does not depend on the bias), so a new bias costs what it did; the loops' cost is
//! unchanged (one pass, on P_LO instead of P; the multipoles' 45 orientations share it, each
//! orientation's tree level taking its own μ_a).
//!
//! P_LO is tabulated on the nodes of the linear spectrum's table (its spline and extrapolation built as
//! for any table), so the loops evaluate it as they evaluate P.

pub use super::ir_legs::leading_order_spectrum;

use super::bias_kernels::LoopBias;
use super::geometry::LegendreSide;
use super::ir_legs::tree_legs;
use super::one_loop::{triangle_vectors, OneLoopRule};
use super::one_loop_galaxy::{galaxy_terms, OneLoopGalaxy};
use super::one_loop_galaxy_basis::GalaxyLoopBasis;
use super::one_loop_galaxy_multipoles::{galaxy_multipoles, GalaxyLoopMultipoles};
use super::one_loop_galaxy_poly::{galaxy_polynomial, tree_polynomial, GalaxyLoopPolynomial};
use super::one_loop_rsd::Orientation;
use super::resum::IrInputs;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::loops::basis::Projection;

/// The IR-resummed [`super::one_loop_galaxy::one_loop_galaxy`]: the terms of the triangle `k` [h/Mpc] with
/// `bias`, real space (`redshift` None) or at (f, orientation), for the linear spectrum `p` resummed with
/// `ir` (module docs); `tree` is B_tree(P_NLO), the loop terms B_1loop(P_LO) (their errors the rule's).
///
/// # Errors
/// As [`super::one_loop_galaxy::one_loop_galaxy`].
pub fn one_loop_galaxy_ir(
    p: &LinearSpectrum,
    ir: &IrInputs,
    k: [f64; 3],
    bias: &LoopBias,
    redshift: Option<(f64, Orientation)>,
    rule: &OneLoopRule,
) -> Result<OneLoopGalaxy> {
    galaxy_terms(p, Some(ir), k, bias, redshift, rule)
}

/// The IR-resummed [`super::one_loop_galaxy_poly::one_loop_galaxy_polynomial`] (the same monomials; module
/// docs).
///
/// # Errors
/// As [`super::one_loop_galaxy_poly::one_loop_galaxy_polynomial`].
pub fn one_loop_galaxy_polynomial_ir(
    p: &LinearSpectrum,
    ir: &IrInputs,
    k: [f64; 3],
    redshift: Option<(f64, Orientation)>,
    rule: &OneLoopRule,
) -> Result<GalaxyLoopPolynomial> {
    galaxy_polynomial(p, Some(ir), k, redshift, rule)
}

/// The IR-resummed [`super::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles`]: B₀, B₂, B₄ per bias
/// monomial, each orientation's tree level with its legs' Σ²_tot(μ_a), the loops on P_LO (module docs).
///
/// # Errors
/// As [`super::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles`].
pub fn one_loop_galaxy_multipoles_ir(
    p: &LinearSpectrum,
    ir: &IrInputs,
    k: [f64; 3],
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    orientations: Option<(usize, usize)>,
) -> Result<GalaxyLoopMultipoles> {
    galaxy_multipoles(p, Some(ir), k, f, side, rule, orientations)
}

/// The real-space polynomials of every triangle of `basis` for `p` resummed with `ir`: the tensors
/// contracted with P_LO's projection (the loops), the tree level recomputed with P_NLO at the sides; and
/// P_LO's projection (its residual decides whether the basis represents it).
///
/// # Errors
/// As [`leading_order_spectrum`].
pub fn galaxy_basis_ir(
    basis: &GalaxyLoopBasis,
    p: &LinearSpectrum,
    ir: &IrInputs,
) -> Result<(Vec<GalaxyLoopPolynomial>, Projection)> {
    let lo = leading_order_spectrum(p, ir)?;
    let projection = basis.project(&lo);
    let mut polys = basis.evaluate(&lo);
    for poly in &mut polys {
        let kv = triangle_vectors(poly.k)?;
        poly.tree = tree_polynomial(poly.k, None, &tree_legs(p, ir, &kv, None))?;
    }
    Ok((polys, projection))
}

/// One line for a table header: the prescription and its Σ², δΣ².
pub fn describe(ir: &IrInputs) -> String {
    format!(
        "IR resummation of the BAO (leading order, Ivanov & Sibiryakov 2018; Philcox et al. 2022): B_tree \
         with P_nw + exp(-x)(1 + x) P_w in every leg, x = k^2 Sigma_tot^2(mu); the loops with P_nw + \
         exp(-q^2 Sigma^2) P_w in every leg (isotropic Sigma^2); Sigma^2 = {:.4} (Mpc/h)^2, delta Sigma^2 = {:.4} \
         (Mpc/h)^2; not in err_: the next-to-leading IR terms and the anisotropic part of the damping on the \
         loops' legs (both of the order of the two-loop wiggles)",
        ir.sigma2, ir.delta_sigma2
    )
}

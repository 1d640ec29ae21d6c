//! The P15 table's integrals as bilinear forms on the basis of linear spectra: what the 2-loop basis
//! tensors take from [`P15Table`] (kept here, so that the table does not know the basis).

use super::linear_basis::LinearBasis;
use crate::loops::p15::{NodeKernels, P15Table};

/// Kernels of [`p15_forms`]: [K_F, K_G] of P15, then the propagator part's δδ, δθ, θθ.
pub(crate) const FORM_KERNELS: usize = 5;

/// The table's integrals as bilinear forms on a basis at one `k`: for P15's [K_F, K_G] and the
/// propagator part's three kernels (in that order, [`FORM_KERNELS`]), the symmetric matrices
/// M[a][b] = Σ_nodes w K φ_a(kr₁)φ_b(kr₂) (stored as pairs a ≤ b,
/// off-diagonal entries doubled) of the fine rule, of fine − coarse radial rule, and of
/// |K_fine − K_coarse angle|, so that for P = Σ c_a φ_a the sums of [`P15Table::evaluate`] are
/// c·M·c (the last one for P ≥ 0). Returned as [type][kernel][pair] in one vector.
pub(crate) fn p15_forms(table: &P15Table, k: f64, basis: &LinearBasis) -> Vec<f64> {
    let n = basis.len();
    let pairs = n * (n + 1) / 2;
    let ln_k = k.ln();
    // Full matrices [type][kernel][a][b], symmetrised at the end.
    let mut full = vec![0.0; 3 * FORM_KERNELS * n * n];
    let (mut phi1, mut phi2) = (vec![0.0; n], vec![0.0; n]);
    // y[type][kernel][b] = Σ_run w K φ_b(kr₂), reset for each run of equal u₁.
    let mut y = vec![0.0; 3 * FORM_KERNELS * n];
    let kernels_at = |kernels: &NodeKernels<2>, prop: &NodeKernels<3>, i: usize, which: usize| {
        let (a, b) = match which {
            0 => (kernels.fine[i], prop.fine[i]),
            1 => (kernels.fine_coarse_angle[i], prop.fine_coarse_angle[i]),
            _ => (kernels.coarse[i], prop.coarse[i]),
        };
        [a[0], a[1], b[0], b[1], b[2]]
    };
    // (rule, [(kernels of the rule, sign, matrix type)]): the fine rule adds to the value and
    // the fine − coarse difference, and its angular difference to the third type; the coarse
    // rule subtracts from the difference.
    for (nodes, fine_rule) in [(&table.fine, true), (&table.coarse, false)] {
        let mut i = 0;
        while i < nodes.len() {
            let u1 = nodes[i].u1;
            let end = i + nodes[i..].iter().take_while(|n| n.u1 == u1).count();
            basis.at_ln(ln_k + u1, &mut phi1);
            if phi1.iter().all(|&p| p == 0.0) {
                i = end;
                continue;
            }
            y.iter_mut().for_each(|v| *v = 0.0);
            for (node, idx) in nodes[i..end].iter().zip(i..end) {
                basis.at_ln(ln_k + node.u2, &mut phi2);
                let add = |y: &mut [f64], t: usize, m: usize, c: f64| {
                    let row = &mut y[(t * FORM_KERNELS + m) * n..][..n];
                    row.iter_mut().zip(&phi2).for_each(|(r, p)| *r += c * p);
                };
                if fine_rule {
                    let (f, alt) = (
                        kernels_at(&table.p15, &table.propagator, idx, 0),
                        kernels_at(&table.p15, &table.propagator, idx, 1),
                    );
                    for m in 0..FORM_KERNELS {
                        add(&mut y, 0, m, node.w * f[m]);
                        add(&mut y, 1, m, node.w * f[m]);
                        add(&mut y, 2, m, (node.w * (f[m] - alt[m])).abs());
                    }
                } else {
                    let c = kernels_at(&table.p15, &table.propagator, idx, 2);
                    for (m, cm) in c.iter().enumerate() {
                        add(&mut y, 1, m, -node.w * cm);
                    }
                }
            }
            for (block, yb) in full.chunks_exact_mut(n * n).zip(y.chunks_exact(n)) {
                for (row, &p1) in block.chunks_exact_mut(n).zip(&phi1) {
                    row.iter_mut().zip(yb).for_each(|(r, y)| *r += p1 * y);
                }
            }
            i = end;
        }
    }
    let mut forms = vec![0.0; 3 * FORM_KERNELS * pairs];
    for (out, m) in forms.chunks_exact_mut(pairs).zip(full.chunks_exact(n * n)) {
        for b in 0..n {
            for a in 0..=b {
                out[b * (b + 1) / 2 + a] = if a == b {
                    m[a * n + a]
                } else {
                    m[a * n + b] + m[b * n + a]
                };
            }
        }
    }
    forms
}

//! The redshift-space mapping's weights of the galaxy kernels (at most four arguments), at a fixed growth
//! rate: what [`crate::loops::rsd_two_loop`]'s `redshift_weights` gives for up to five, with the
//! set-partition sums evaluated at f as they are built (one number per subset, not a polynomial in f) and
//! arrays of the 16 subsets of four arguments. The multipoles' one pass assembles the parts of 45
//! orientations per kernel from one table of subset fields, so this is its innermost work.

use crate::vec3::dot;

type Vec3 = [f64; 3];

/// k! for k = 0..=4.
const FACT: [f64; 5] = [1.0, 1.0, 2.0, 6.0, 24.0];

/// G_S/k_S² of every subset (zero where k_S = 0): what [`redshift_weights_4`] takes, the same for every line
/// of sight.
pub(super) fn velocity_over_k2(ks2: &[f64; 16], g: &[f64; 16]) -> [f64; 16] {
    std::array::from_fn(|s| if ks2[s] != 0.0 { g[s] / ks2[s] } else { 0.0 })
}

/// Z_n = Σ_{S₀ ⊆ args} `weights[S₀]` × density(S₀) + `velocity` along the unit line of sight `los` at `f`,
/// for the subsets' total momenta `ks`, their squares `ks2` and `h` = G_S/k_S² ([`velocity_over_k2`], with
/// G_S the velocity kernels) (Scoccimarro,
/// Couchman & Frieman 1999: `weights[S₀]` = (|S₀|!/n!) E(args∖S₀), E(R) the sum over the set partitions of R
/// of Π_B f |B|! (k·n̂)(k_B·n̂)/k_B² G_B, `velocity` = Σ_{S₀} (|S₀|!/n!) fμ_{S₀}² G_{S₀} E(args∖S₀); subsets of
/// zero momentum contribute zero).
pub(super) fn redshift_weights_4(
    ks: &[Vec3; 16],
    ks2: &[f64; 16],
    h: &[f64; 16],
    args: usize,
    los: &Vec3,
    f: f64,
) -> ([f64; 16], f64) {
    let nk = dot(los, &ks[args]);
    let (mut d1, mut u) = ([0.0; 16], [0.0; 16]);
    let mut sub = args;
    while sub != 0 {
        if ks2[sub] != 0.0 {
            let ns = dot(los, &ks[sub]);
            d1[sub] = ns * ns * h[sub];
            u[sub] = FACT[sub.count_ones() as usize] * nk * ns * h[sub];
        }
        sub = (sub - 1) & args;
    }
    // E(r) at f for every r ⊆ args: the block holding r's lowest element, times E of the rest
    let mut e = [0.0; 16];
    e[0] = 1.0;
    for r in 1..=args {
        if r & !args != 0 {
            continue;
        }
        let low = r & r.wrapping_neg();
        let rest = r ^ low;
        let mut sub = rest;
        let mut er = 0.0;
        loop {
            let block = sub | low;
            let c = u[block];
            if c != 0.0 {
                er += c * e[r ^ block];
            }
            if sub == 0 {
                break;
            }
            sub = (sub - 1) & rest;
        }
        e[r] = f * er;
    }
    let inverse = 1.0 / FACT[args.count_ones() as usize];
    let (mut weights, mut velocity) = ([0.0; 16], 0.0);
    let mut s0 = args;
    while s0 != 0 {
        if ks2[s0] != 0.0 {
            let c = FACT[s0.count_ones() as usize] * inverse * e[args ^ s0];
            weights[s0] = c;
            velocity += c * f * d1[s0];
        }
        s0 = (s0 - 1) & args;
    }
    (weights, velocity)
}

#[cfg(test)]
mod tests {
    use super::{redshift_weights_4, velocity_over_k2};
    use crate::loops::rsd_two_loop::redshift_weights;

    /// Equal to the general (five-argument, polynomial in f) weights of the two-loop code to 1e-14, for
    /// every subset of 1–4 pseudo-random arguments, at three f and an oblique line of sight; a subset of zero
    /// momentum gets no weight in either.
    #[test]
    fn equals_the_general_weights() {
        let mut seed = 7u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let los: [f64; 3] = {
            let v: [f64; 3] = [0.3, -0.5, 0.8];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| x / n)
        };
        for trial in 0..20 {
            let n = 1 + trial % 4;
            let mut q: Vec<[f64; 3]> = (0..n).map(|_| [rand(), rand(), rand()]).collect();
            if trial == 7 {
                q[1] = q[0].map(|x| -x); // a pair of zero momentum
            }
            let (mut ks, mut ks2, mut g) = ([[0.0; 3]; 16], [0.0; 16], [0.0; 16]);
            let (mut ks32, mut ks232) = ([[0.0; 3]; 32], [0.0; 32]);
            for s in 1..(1usize << n) {
                let mut v = [0.0; 3];
                for (i, qi) in q.iter().enumerate() {
                    if s >> i & 1 == 1 {
                        v = [v[0] + qi[0], v[1] + qi[1], v[2] + qi[2]];
                    }
                }
                ks[s] = v;
                ks32[s] = v;
                ks2[s] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                ks232[s] = ks2[s];
                g[s] = 0.3 + rand();
            }
            let full = (1usize << n) - 1;
            for f in [0.0, 0.7, 1.3] {
                let h = velocity_over_k2(&ks2, &g);
                let (w, vel) = redshift_weights_4(&ks, &ks2, &h, full, &los, f);
                let (w0, vel0) = redshift_weights(&ks32, &ks232, full, &los, |s| g[s], f);
                for s in 0..16 {
                    assert!(
                        (w[s] - w0[s]).abs() <= 1e-14 * (1.0 + w0[s].abs()),
                        "{trial} {s}"
                    );
                }
                assert!((vel - vel0).abs() <= 1e-14 * (1.0 + vel0.abs()), "{trial}");
            }
        }
    }
}

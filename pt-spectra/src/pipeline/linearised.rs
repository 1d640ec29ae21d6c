//! The nuisance-only step: the data vector at fixed cosmology as the polynomial
//! D(θ) = Σ_{i≤j} u_i u_j A_ij + Σ_c θ_c C_c in u = (1, b1, b2, bs, b3) and the counterterms and
//! stochastic terms θ_c (module docs of [`super`]), with its exact Jacobian.

use super::CosmologyStep;
use crate::error::{Error, Result};
use crate::rsd::ept::{checked_param, EptParams, PARAM_NAMES};

/// The nuisance parameters of the polynomial, in [`PARAM_NAMES`]' order (all but `f`, which the
/// cosmology step fixes).
pub const NUISANCE_NAMES: [&str; 11] = [
    "b1", "b2", "bs", "b3", "alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2", "sn4",
];

/// Bias parameters (u_1 … u_4 = b1, b2, bs, b3; u_0 = 1).
const BIASES: usize = 4;
/// Parameters entering linearly (α0, α2, α4, α6, sn, sn2, sn4).
const LINEAR: usize = 7;

/// The data vector of one cosmology as a polynomial in the nuisance parameters.
#[derive(Debug, Clone)]
pub struct Linearised {
    /// A_ij for 0 ≤ i ≤ j ≤ 4, row by row (i = 0: j = 0…4, i = 1: j = 1…4, …).
    quadratic: Vec<Vec<f64>>,
    /// C_c of the linear parameters.
    linear: Vec<Vec<f64>>,
    /// The growth rate f the polynomial is at.
    f: f64,
}

/// The index of A_ij (i ≤ j) in [`Linearised::quadratic`].
fn pair(i: usize, j: usize) -> usize {
    let (i, j) = if i <= j { (i, j) } else { (j, i) };
    // rows 0..i have 5, 4, … entries
    (0..i).map(|r| BIASES + 1 - r).sum::<usize>() + (j - i)
}

impl CosmologyStep<'_> {
    /// This step's data vector as a polynomial in the nuisance parameters at growth rate `f`
    /// (`None`: f(z) of the cosmology): 22 evaluations of the model (their projection onto the
    /// multipoles made once, [`crate::rsd::ept::EptPlan::multipole_values_many`]), after which every
    /// nuisance step is a few thousand multiplications ([`Linearised::data_vector`]).
    ///
    /// # Errors
    /// As [`CosmologyStep::data_vector`]; [`Error::InvalidChoice`] with a bispectrum block.
    pub fn linearise(&self, f: Option<f64>) -> Result<Linearised> {
        if self.has_bispectrum() {
            return Err(Error::InvalidChoice {
                what: "the nuisance polynomial of a pipeline with a bispectrum block".into(),
                reason:
                    "it is the power spectrum's (quadratic in b1, b2, bs, b3); the bispectrum is \
                         cubic in b1: evaluate the data vector instead"
                        .into(),
            });
        }
        let f = f.unwrap_or(self.growth_rate);
        // the 22 parameter sets: none, ±1 of each bias, each pair of biases at 1, each linear one at 1
        let mut sets: Vec<Vec<(usize, f64)>> = vec![Vec::new()];
        for i in 0..BIASES {
            sets.push(vec![(i, 1.0)]);
            sets.push(vec![(i, -1.0)]);
        }
        for i in 0..BIASES {
            for j in i + 1..BIASES {
                sets.push(vec![(i, 1.0), (j, 1.0)]);
            }
        }
        sets.extend((0..LINEAR).map(|c| vec![(BIASES + c, 1.0)]));
        let params: Vec<EptParams> = sets
            .iter()
            .map(|set| {
                let mut p = EptParams::new(0.0, f);
                for &(i, v) in set {
                    p.values[i] = v;
                }
                p
            })
            .collect();
        // their data vectors, the projection onto the multipoles made once for all
        let mut vectors = self.data_vectors_of(&params)?.into_iter();
        let mut next = || vectors.next().expect("one per set");
        let sub = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x - y).collect::<Vec<_>>();
        let a00 = next();
        let mut a0 = vec![Vec::new(); BIASES + 1];
        let mut aa = vec![Vec::new(); BIASES + 1];
        for i in 1..=BIASES {
            let (plus, minus) = (next(), next());
            a0[i] = plus
                .iter()
                .zip(&minus)
                .map(|(p, m)| 0.5 * (p - m))
                .collect();
            aa[i] = plus
                .iter()
                .zip(&minus)
                .zip(&a00)
                .map(|((p, m), c)| 0.5 * (p + m) - c)
                .collect();
        }
        let mut quadratic = vec![Vec::new(); pair(BIASES, BIASES) + 1];
        quadratic[pair(0, 0)] = a00.clone();
        for i in 1..=BIASES {
            quadratic[pair(0, i)] = a0[i].clone();
            quadratic[pair(i, i)] = aa[i].clone();
        }
        for i in 1..=BIASES {
            for j in i + 1..=BIASES {
                let both = next();
                quadratic[pair(i, j)] = (0..both.len())
                    .map(|r| both[r] - a00[r] - a0[i][r] - a0[j][r] - aa[i][r] - aa[j][r])
                    .collect();
            }
        }
        let linear = (0..LINEAR).map(|_| sub(&next(), &a00)).collect();
        Ok(Linearised {
            quadratic,
            linear,
            f,
        })
    }
}

impl Linearised {
    /// The growth rate of the polynomial.
    pub fn f(&self) -> f64 {
        self.f
    }

    /// The values of [`NUISANCE_NAMES`] from `params` by name (unset: 0). `f` may be given if it
    /// equals the polynomial's.
    fn values(&self, params: &[(&str, f64)]) -> Result<[f64; 11]> {
        let mut v = [0.0; 11];
        for &(name, value) in params {
            if name == "f" {
                if value != self.f {
                    return Err(Error::InvalidChoice {
                        what: format!("f = {value} in a nuisance-only step"),
                        reason: format!(
                            "the step was linearised at f = {}: a new f needs a new linearisation",
                            self.f
                        ),
                    });
                }
                continue;
            }
            let full = checked_param(name, value)?;
            let i = NUISANCE_NAMES
                .iter()
                .position(|&n| n == PARAM_NAMES[full])
                .ok_or_else(|| Error::InvalidChoice {
                    what: format!("ept parameter `{name}`"),
                    reason: format!(
                        "not a nuisance parameter: they are {}",
                        NUISANCE_NAMES.join(", ")
                    ),
                })?;
            v[i] = value;
        }
        Ok(v)
    }

    /// u = (1, b1, b2, bs, b3).
    fn u(v: &[f64; 11]) -> [f64; BIASES + 1] {
        [1.0, v[0], v[1], v[2], v[3]]
    }

    /// The data vector at `params` by name (the nuisance-only step).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the valid parameters for an unknown name, or for an `f`
    /// other than the polynomial's; [`Error::InvalidParameter`] for a value that is not finite.
    pub fn data_vector(&self, params: &[(&str, f64)]) -> Result<Vec<f64>> {
        let v = self.values(params)?;
        let u = Self::u(&v);
        let mut out = vec![0.0; self.quadratic[0].len()];
        for i in 0..=BIASES {
            for j in i..=BIASES {
                crate::simd::axpy(&mut out, u[i] * u[j], &self.quadratic[pair(i, j)]);
            }
        }
        for (c, vector) in self.linear.iter().enumerate() {
            crate::simd::axpy(&mut out, v[BIASES + c], vector);
        }
        Ok(out)
    }

    /// The exact Jacobian d(data vector)/d(parameter) at `params`: one vector per name of
    /// [`NUISANCE_NAMES`], in that order.
    ///
    /// # Errors
    /// As [`Self::data_vector`].
    pub fn jacobian(&self, params: &[(&str, f64)]) -> Result<Vec<Vec<f64>>> {
        let v = self.values(params)?;
        let u = Self::u(&v);
        let n = self.quadratic[0].len();
        let mut out = Vec::with_capacity(NUISANCE_NAMES.len());
        for i in 1..=BIASES {
            // d/du_i Σ_{a≤b} u_a u_b A_ab = Σ_{a≠i} u_a A_ai + 2 u_i A_ii
            let mut d = vec![0.0; n];
            for a in 0..=BIASES {
                let factor = if a == i { 2.0 * u[i] } else { u[a] };
                crate::simd::axpy(&mut d, factor, &self.quadratic[pair(a, i)]);
            }
            out.push(d);
        }
        out.extend(self.linear.iter().cloned());
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::{pair, BIASES};

    #[test]
    fn pairs_are_numbered_once_each_in_row_order() {
        let mut seen = Vec::new();
        for i in 0..=BIASES {
            for j in i..=BIASES {
                seen.push(pair(i, j));
                assert_eq!(pair(i, j), pair(j, i));
            }
        }
        assert_eq!(seen, (0..15).collect::<Vec<_>>());
    }
}

//! The nuisance-only step: the data vector at fixed cosmology as the polynomial
//! D(θ) = Σ_{i≤j} u_i u_j A_ij + Σ_c θ_c C_c in u = (1, b1, b2, bs, b3) and the counterterms and
//! stochastic terms θ_c (module docs of [`super`]), with its exact Jacobian.

use super::CosmologyStep;
use crate::error::{Error, Result};
use crate::rsd::ept::{checked_param, EptParams, PARAM_NAMES};

/// The nuisance parameters of the polynomial, in [`PARAM_NAMES`]' order (all but `f`, the last,
/// which the cosmology step fixes).
pub const NUISANCE_NAMES: [&str; 11] = {
    let mut names = [""; 11];
    let mut i = 0;
    while i < names.len() {
        names[i] = PARAM_NAMES[i];
        i += 1;
    }
    names
};

/// The parameters of the full Jacobian ([`CosmologyStep::jacobian`], and [`Linearised::jacobian`]
/// with the f-derivative), in its order: [`PARAM_NAMES`], the nuisance parameters then the growth
/// rate f (its derivative exact too: of the μ² polynomials and of the BAO damping).
pub const JACOBIAN_NAMES: [&str; 12] = PARAM_NAMES;

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
    /// With the f-derivative ([`CosmologyStep::linearise_with_df`]): ∂A_ij/∂f (as `quadratic`)
    /// and ∂C_c/∂f.
    df: Option<Polynomial>,
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
    /// As [`CosmologyStep::data_vector`]; [`Error::InvalidChoice`] with blocks after the power
    /// spectrum.
    pub fn linearise(&self, f: Option<f64>) -> Result<Linearised> {
        self.polynomial(f, false)
    }

    /// [`Self::linearise`] with the polynomial of the data vector's exact f-derivative as well, so
    /// that [`Linearised::jacobian`] has the row of f (twice the cost: the f-derivatives of the 22
    /// sets' μ² polynomials and BAO damping, projected by the same weights).
    ///
    /// # Errors
    /// As [`Self::linearise`].
    pub fn linearise_with_df(&self, f: Option<f64>) -> Result<Linearised> {
        self.polynomial(f, true)
    }

    /// The exact Jacobian of the data vector at `params` by name: one row per name of
    /// [`JACOBIAN_NAMES`] (the nuisance parameters from the polynomial of [`Self::linearise`], f from
    /// one f-derivative at `params`), with the data vector itself (from the polynomial: the same
    /// numbers as [`Self::data_vector`] to rounding).
    ///
    /// # Errors
    /// As [`Self::linearise`] and [`Linearised::jacobian`].
    pub fn jacobian(&self, params: &[(&str, f64)]) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
        self.refuse_blocks()?;
        let p = self.params(params)?;
        let (vectors, df) =
            self.data_vectors_and_df_of(&unit_sets(p.f()), std::slice::from_ref(&p))?;
        nuisance_jacobian(vectors, df, p.f(), params)
    }

    /// The exact derivatives of the data vector at `params` by name with respect to the template
    /// parameters f, α∥, α⊥ (in that order; f's as in [`Self::jacobian`], α's through
    /// [`crate::rsd::ept::EptPlan::multipole_ap_derivatives`], then the observation matrix).
    ///
    /// At a step without distortion, the derivatives at α∥ = α⊥ = 1.
    ///
    /// # Errors
    /// As [`Self::jacobian`]; [`Error::InvalidChoice`] for a pipeline whose plan has no AP grid.
    pub fn template_jacobian(&self, params: &[(&str, f64)]) -> Result<[Vec<f64>; 3]> {
        self.refuse_blocks()?;
        let p = self.params(params)?;
        let (_, mut df) = self.data_vectors_and_df_of(&[], std::slice::from_ref(&p))?;
        let [dpar, dperp] = self.ap_jacobian(params)?;
        Ok([df.remove(0), dpar, dperp])
    }

    /// The α∥ and α⊥ rows of [`Self::template_jacobian`] alone (for a caller that has f's row from
    /// [`Self::jacobian`]).
    ///
    /// # Errors
    /// As [`Self::template_jacobian`].
    pub(crate) fn ap_jacobian(&self, params: &[(&str, f64)]) -> Result<[Vec<f64>; 2]> {
        self.refuse_blocks()?;
        let ap = match self.ap {
            Some(ap) => ap,
            None => crate::rsd::ap::Distortion::new(1.0, 1.0)?,
        };
        let p = self.params(params)?;
        let pl = self.pipeline;
        let [dpar, dperp] =
            pl.plan
                .multipole_ap_derivatives(&self.terms, &p, pl.observation.model_ells(), ap)?;
        Ok([pl.observe(&dpar), pl.observe(&dperp)])
    }

    /// The polynomial is the power spectrum's.
    fn refuse_blocks(&self) -> Result<()> {
        if let Some(b) = self.pipeline.blocks.first() {
            return Err(Error::InvalidChoice {
                what: format!(
                    "the nuisance polynomial of a pipeline with a {} block",
                    b.kind().name
                ),
                reason: format!(
                    "it is the power spectrum's (quadratic in b1, b2, bs, b3), not the {}'s: \
                     evaluate the data vector instead",
                    b.kind().name
                ),
            });
        }
        Ok(())
    }

    fn polynomial(&self, f: Option<f64>, with_df: bool) -> Result<Linearised> {
        self.refuse_blocks()?;
        let f = f.unwrap_or(self.growth_rate);
        let params = unit_sets(f);
        // their data vectors (and f-derivatives), the projection onto the multipoles made once
        let (quadratic, linear, df) = if with_df {
            let (vectors, df) = self.data_vectors_and_df_of(&params, &params)?;
            let (q, l) = polynomial(vectors);
            (q, l, Some(polynomial(df)))
        } else {
            let (q, l) = polynomial(self.data_vectors_of(&params)?);
            (q, l, None)
        };
        Ok(Linearised {
            quadratic,
            linear,
            df,
            f,
        })
    }
}

/// [`CosmologyStep::jacobian`] from the data vectors of the [`unit_sets`] at f (their order) and f's
/// rows `df`: the data vector at `params` and the rows of [`JACOBIAN_NAMES`].
pub(super) fn nuisance_jacobian(
    vectors: Vec<Vec<f64>>,
    df: Vec<Vec<f64>>,
    f: f64,
    params: &[(&str, f64)],
) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
    let (quadratic, linear) = polynomial(vectors);
    let lin = Linearised {
        quadratic,
        linear,
        df: None,
        f,
    };
    let mut rows = lin.jacobian(params)?;
    rows.extend(df);
    Ok((lin.data_vector(params)?, rows))
}

/// The vectors of a polynomial: A_ij (i ≤ j, [`pair`] order) and C_c.
type Polynomial = (Vec<Vec<f64>>, Vec<Vec<f64>>);

/// The 22 parameter sets of the polynomial at growth rate f: none, ±1 of each bias, each pair of
/// biases at 1, each linear parameter at 1.
pub(super) fn unit_sets(f: f64) -> Vec<EptParams> {
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
    sets.iter()
        .map(|set| {
            let mut p = EptParams::new(0.0, f);
            for &(i, v) in set {
                p.values[i] = v;
            }
            p
        })
        .collect()
}

/// The vectors A_ij (i ≤ j, [`pair`] order) and C_c of the polynomial from its values at the 22
/// parameter sets of [`CosmologyStep::linearise`], in their order (the same extraction gives the
/// f-derivatives' polynomial from the sets' f-derivatives).
fn polynomial(vectors: Vec<Vec<f64>>) -> Polynomial {
    let mut vectors = vectors.into_iter();
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
    quadratic[pair(0, 0)] = a00;
    (quadratic, linear)
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
        Ok(Self::evaluate(&self.quadratic, &self.linear, &v))
    }

    /// Σ_{i≤j} u_i u_j A_ij + Σ_c θ_c C_c.
    fn evaluate(quadratic: &[Vec<f64>], linear: &[Vec<f64>], v: &[f64; 11]) -> Vec<f64> {
        let u = Self::u(v);
        let mut out = vec![0.0; quadratic[0].len()];
        for i in 0..=BIASES {
            for j in i..=BIASES {
                crate::simd::axpy(&mut out, u[i] * u[j], &quadratic[pair(i, j)]);
            }
        }
        for (c, vector) in linear.iter().enumerate() {
            crate::simd::axpy(&mut out, v[BIASES + c], vector);
        }
        out
    }

    /// The names of the rows of [`Self::jacobian`]: [`NUISANCE_NAMES`], and f if the polynomial has
    /// its f-derivative ([`CosmologyStep::linearise_with_df`]: [`JACOBIAN_NAMES`]).
    pub fn names(&self) -> &'static [&'static str] {
        if self.df.is_some() {
            &JACOBIAN_NAMES
        } else {
            &NUISANCE_NAMES
        }
    }

    /// The exact Jacobian d(data vector)/d(parameter) at `params`: one vector per name of
    /// [`Self::names`], in that order.
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
        // ∂/∂f: the polynomial of the f-derivatives at the same parameters
        if let Some((quadratic, linear)) = &self.df {
            out.push(Self::evaluate(quadratic, linear, &v));
        }
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

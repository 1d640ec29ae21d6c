//! The EFT counterterms to two-loop order: the models `2l-eft` (2-loop SPT + counterterms) and
//! `2l-eft-ir` (the same with IR-resummed BAO), and the c_s² that any model takes.
//!
//! **The set.** The effective stress of the short modes enters the Euler equation as c²∇²δ, with δ
//! the long-wavelength *nonlinear* field (Carrasco, Foreman, Green & Senatore 2014, arXiv:1310.0464;
//! Baldauf, Mercolli & Zaldarriaga 2015, arXiv:1507.02256). Its response is a counterterm field
//! δ_ct = −c k² δ_nl and, one derivative order up, −c₄ k⁴ δ_lin. To two loops in P_δδ this gives
//!
//!   P_δδ,ct = −2 cs2 k² P_lin − 2 cs2_1loop k² P_1loop − 2 c4 k⁴ P_lin,
//!
//! with P_1loop = P22 + 2 P13. Each parameter is its own number, as the UV limits of the loops ask:
//! - `cs2` [(Mpc/h)²] multiplies k² P_lin. It absorbs the UV limit of 2P13 (−(61/105) k² σ_v² P_lin
//!   for q → ∞) and the *double-hard* limit of the 2-loop terms (both loop momenta large), which has
//!   the same shape; at two loops it is the sum c_s²(1-loop) + c_s²(2-loop) of the literature.
//! - `cs2_1loop` [(Mpc/h)²] multiplies k² P_1loop: the counterterm inserted in the 1-loop diagrams,
//!   which also absorbs the *single-hard* limit of the 2-loop terms (one loop momentum large; there the
//!   2-loop integrand becomes k²/q² times a 1-loop integrand). In the one-parameter ansatz it would equal
//!   cs2; the UV limits of the loops do not tie them (below), so it is free.
//! - `c4` [(Mpc/h)⁴] multiplies k⁴ P_lin: the next derivative order and cs2², which appears at the
//!   same order.
//!
//! That this set is complete at two loops is tested by what it must do: absorb how the loops depend on
//! their cut-off. Between q_max = 2 h/Mpc and 10³ h/Mpc, 2-loop SPT at z = 0 changes by 12% of P_lin
//! at k = 0.3 h/Mpc; a least-squares cs2 alone leaves 2.9e-3 of P_lin, the set leaves 2.7e-4, the
//! level of the 2-loop integration error (tests/tests/suite/eft.rs; docs/eft.md).
//!
//! **Velocities.** With c ∝ D^n (the time dependence of the P13, resp. 2-loop, UV limit that each
//! counterterm renormalises: n = 2 for cs2 and cs2_1loop, 4 for c4), mass conservation linearised in
//! the counterterm gives θ_ct = ∂δ_ct/∂ln D = −c kᵐ (n δ + θ) (θ ≡ −∇·v/(aHf), θ_lin = δ_lin).
//! Hence, for a counterterm of shape S (P_lin or P_1loop of each pair) and kᵐ:
//!
//!   T_δδ = −2 kᵐ S_δδ,   T_δθ = −kᵐ (n S_δδ + 2 S_δθ),   T_θθ = −2 kᵐ (n S_δθ + S_θθ),
//!
//! which for S = P_lin gives the factors 2, 4, 6 of cs2 ([`super::counterterm`](mod@super::counterterm))
//! and 2, 6, 10 of c4. The velocities of the EFT need counterterms of their own (Mercolli & Pajer
//! 2014), which are not modelled: these factors hold for the density-weighted time dependence above.
//!
//! **IR resummation.** In `2l-eft-ir` and the other IR-resummed models, S is the IR-resummed spectrum
//! at the matching order ([`crate::ir`]): P_nw + e^{−k²Σ²} P_w for P_lin and
//! P_1loop,nw + e^{−k²Σ²}(k²Σ² P_w + P_1loop,w) for P_1loop, so the counterterms carry damped wiggles.
//! With massive neutrinos the shapes are those of cold matter, times f_cb² in P_δδ of all matter.
//!
//! Every template T_X = ∂P/∂X is exact in the parameters: the model is P(0) + Σ X T_X, so a fit of the
//! counterterms is linear ([`fit_counterterms`]). A counterterm adds |X| times the error of its shape
//! to the error estimate (zero for P_lin).

use super::{RealModel, RealSpectra};
use crate::error::{Error, Result};
use crate::loops::{ByPair, Estimate, Pair};
use std::fmt;

/// One counterterm parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Counterterm {
    /// c_s² [(Mpc/h)²] of −2 c_s² k² P_lin.
    Cs2,
    /// The 1-loop insertion [(Mpc/h)²] of −2 cs2_1loop k² P_1loop.
    Cs2OneLoop,
    /// The k⁴ counterterm [(Mpc/h)⁴] of −2 c4 k⁴ P_lin.
    C4,
}

/// The accepted counterterm names, for messages.
const NAMES: &str = "cs2, cs2_1loop, c4";

impl Counterterm {
    /// Every counterterm, in the order of the output columns.
    pub const ALL: [Counterterm; 3] = [Counterterm::Cs2, Counterterm::Cs2OneLoop, Counterterm::C4];

    /// The name, as in `--ct NAME=VALUE` and the columns `T_dd_NAME`.
    pub fn name(self) -> &'static str {
        match self {
            Counterterm::Cs2 => "cs2",
            Counterterm::Cs2OneLoop => "cs2_1loop",
            Counterterm::C4 => "c4",
        }
    }

    /// The unit of the parameter.
    pub fn unit(self) -> &'static str {
        match self {
            Counterterm::C4 => "(Mpc/h)^4",
            _ => "(Mpc/h)^2",
        }
    }

    /// The power m of kᵐ.
    fn k_power(self) -> i32 {
        match self {
            Counterterm::C4 => 4,
            _ => 2,
        }
    }

    /// The power n of the coefficient's growth c ∝ Dⁿ (module docs).
    fn growth_power(self) -> f64 {
        match self {
            Counterterm::C4 => 4.0,
            _ => 2.0,
        }
    }

    /// Whether only the EFT models take it (c_s² is open to every model).
    pub fn eft_only(self) -> bool {
        self != Counterterm::Cs2
    }

    /// Its term of P_δδ, for headers.
    fn formula(self) -> &'static str {
        match self {
            Counterterm::Cs2 => "-2 cs2 k^2 P_lin",
            Counterterm::Cs2OneLoop => "-2 cs2_1loop k^2 P_1loop",
            Counterterm::C4 => "-2 c4 k^4 P_lin",
        }
    }
}

impl fmt::Display for Counterterm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Counterterm {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        Counterterm::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::UnknownName {
                what: "EFT counterterm",
                name: s.to_string(),
                available: NAMES,
            })
    }
}

/// The values of the counterterm parameters (module docs); all 0 by default.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counterterms {
    /// c_s² [(Mpc/h)²].
    pub cs2: f64,
    /// The 1-loop insertion [(Mpc/h)²].
    pub cs2_1loop: f64,
    /// The k⁴ counterterm [(Mpc/h)⁴].
    pub c4: f64,
}

impl Counterterms {
    /// Only c_s² = `cs2`.
    pub fn cs2(cs2: f64) -> Self {
        Self {
            cs2,
            ..Self::default()
        }
    }

    /// The value of `c`.
    pub fn get(&self, c: Counterterm) -> f64 {
        match c {
            Counterterm::Cs2 => self.cs2,
            Counterterm::Cs2OneLoop => self.cs2_1loop,
            Counterterm::C4 => self.c4,
        }
    }

    /// Sets `c` to `value`.
    pub fn set(&mut self, c: Counterterm, value: f64) {
        match c {
            Counterterm::Cs2 => self.cs2 = value,
            Counterterm::Cs2OneLoop => self.cs2_1loop = value,
            Counterterm::C4 => self.c4 = value,
        }
    }

    /// Whether every parameter is 0.
    pub fn is_zero(&self) -> bool {
        Counterterm::ALL.iter().all(|&c| self.get(c) == 0.0)
    }

    /// The counterterms of `NAME=VALUE` assignments (`--ct cs2=1.2 --ct c4=-3`), each name at most once.
    ///
    /// ```
    /// use pt_spectra::real::eft::Counterterms;
    /// let ct = Counterterms::from_assignments(["cs2=1.5", "c4 = -2"])?;
    /// assert_eq!((ct.cs2, ct.cs2_1loop, ct.c4), (1.5, 0.0, -2.0));
    /// assert!(Counterterms::from_assignments(["cs2=1", "cs2=2"]).is_err());
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for text without `=`, a value that is not a finite number or a name
    /// given twice; [`Error::UnknownName`] for an unknown name.
    pub fn from_assignments<S: AsRef<str>>(items: impl IntoIterator<Item = S>) -> Result<Self> {
        let mut ct = Self::default();
        let mut seen = Vec::new();
        for item in items {
            let text = item.as_ref();
            let bad = |reason: String| Error::InvalidChoice {
                what: format!("EFT counterterm `{text}`"),
                reason,
            };
            let (name, value) = text
                .split_once('=')
                .ok_or_else(|| bad(format!("write NAME=VALUE, NAME one of {NAMES}")))?;
            let c: Counterterm = name.parse()?;
            let value: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| bad(format!("the value of {c} must be a finite number")))?;
            if seen.contains(&c) {
                return Err(bad(format!("{c} is given twice")));
            }
            seen.push(c);
            ct.set(c, value);
        }
        Ok(ct)
    }

    /// These counterterms with c_s² = `cs2` from a separate option (`--cs2`, Python `cs2=`).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] if both set c_s² to a non-zero value.
    pub fn with_cs2(mut self, cs2: f64) -> Result<Self> {
        if cs2 != 0.0 && self.cs2 != 0.0 {
            return Err(Error::InvalidChoice {
                what: format!("cs2 = {cs2} and the counterterm cs2 = {}", self.cs2),
                reason: "c_s² is given twice: give it once (--cs2 or --ct cs2=VALUE)".into(),
            });
        }
        if cs2 != 0.0 {
            self.cs2 = cs2;
        }
        Ok(self)
    }

    /// Checks the values for `model`: finite, and the 2-loop counterterms only for the EFT models.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a value that is not finite; [`Error::InvalidChoice`] for
    /// cs2_1loop or c4 ≠ 0 with a model other than `2l-eft`, `2l-eft-ir`.
    pub fn check(&self, model: RealModel) -> Result<()> {
        super::check_cs2(self.cs2)?;
        for c in Counterterm::ALL {
            let v = self.get(c);
            if !v.is_finite() {
                return Err(Error::InvalidChoice {
                    what: format!("EFT counterterm {c} = {v}"),
                    reason: "must be a finite number".into(),
                });
            }
            if c.eft_only() && v != 0.0 && !model.is_eft() {
                return Err(Error::InvalidChoice {
                    what: format!("EFT counterterm {c} = {v} with model {model}"),
                    reason: "the 2-loop counterterms belong to the models 2l-eft and 2l-eft-ir \
                             (every model takes cs2)"
                        .into(),
                });
            }
        }
        Ok(())
    }

    /// The header lines that state the counterterms of `model` (none for a non-EFT model without
    /// counterterms).
    pub fn describe(&self, model: RealModel) -> Vec<String> {
        if !model.is_eft() {
            return if self.cs2 == 0.0 {
                vec![]
            } else {
                vec![super::counterterm::counterterm_line(self.cs2)]
            };
        }
        let values: Vec<String> = Counterterm::ALL
            .iter()
            .map(|&c| format!("{c} = {} {}", self.get(c), c.unit()))
            .collect();
        let formulae: Vec<&str> = Counterterm::ALL.iter().map(|c| c.formula()).collect();
        let mut lines = vec![format!(
            "EFT counterterms (Carrasco et al. 2014, Baldauf et al. 2015; docs/eft.md): {}; P_dd gets {}; \
             P_dt, P_tt from theta_ct = -c k^m (n delta + theta), c ~ D^n, n = 2, 2, 4; {}",
            values.join(", "),
            formulae.join(" "),
            if model.needs_ir() {
                "shapes IR-resummed"
            } else {
                "P_1loop = P22 + 2 P13"
            }
        )];
        if self.is_zero() {
            lines.push(format!(
                "warning: every counterterm is 0, so {model} is {}: set them with --ct NAME=VALUE or fit \
                 them (the columns T_dd_NAME = dP_dd/dNAME of --terms make the fit linear)",
                if model.needs_ir() { "2l-spt-ir" } else { "2l-spt" }
            ));
        }
        lines
    }
}

impl RealSpectra {
    /// The shape S_XY of counterterm `c` at k index `i`: P_lin or P_1loop, IR-resummed for the
    /// IR models (module docs).
    fn counterterm_shape(&self, c: Counterterm, pair: Pair, i: usize) -> Estimate {
        let t = &self.terms.one_loop;
        let one_loop = c == Counterterm::Cs2OneLoop;
        match (&self.terms.ir, self.model.needs_ir()) {
            (Some(ir), true) => {
                let w = crate::ir::wiggle_parts(t, ir, pair, i);
                if one_loop {
                    w.one_nw + w.d * (w.x * w.p_w + w.one_w)
                } else {
                    w.p_nw + w.d * w.p_w
                }
            }
            _ if one_loop => t.one_loop(pair, i),
            _ => Estimate::exact(t.p_lin[i]),
        }
    }

    /// The template T_XY = ∂P_XY/∂X of counterterm `c` at every k [(Mpc/h)^3 per unit of X], with
    /// its error (module docs).
    pub fn counterterm_template(&self, c: Counterterm) -> ByPair<Vec<Estimate>> {
        let (m, n) = (c.k_power(), c.growth_power());
        let dd_scale = self.cold_fraction.map_or(1.0, |f| f * f);
        ByPair::from_fn(|pair| {
            (0..self.k.len())
                .map(|i| {
                    let s = |p: Pair| self.counterterm_shape(c, p, i);
                    let km = -self.k[i].powi(m);
                    match pair {
                        Pair::DeltaDelta => (2.0 * km * dd_scale) * s(Pair::DeltaDelta),
                        Pair::DeltaTheta => {
                            km * (n * s(Pair::DeltaDelta) + 2.0 * s(Pair::DeltaTheta))
                        }
                        Pair::ThetaTheta => {
                            (2.0 * km) * (n * s(Pair::DeltaTheta) + s(Pair::ThetaTheta))
                        }
                    }
                })
                .collect()
        })
    }

    /// The spectra with the counterterms `ct` added ([`counterterm_template`](Self::counterterm_template)
    /// times each value; module docs), [`counterterms`](Self::counterterms) increased by them.
    /// All-zero `ct` returns the spectra untouched.
    ///
    /// # Errors
    /// As [`Counterterms::check`] for this model.
    pub fn with_counterterms(mut self, ct: &Counterterms) -> Result<Self> {
        ct.check(self.model)?;
        for c in Counterterm::ALL {
            let x = ct.get(c);
            if x == 0.0 {
                continue;
            }
            let template = self.counterterm_template(c);
            for pair in Pair::ALL {
                for (e, t) in self.spectra[pair].iter_mut().zip(&template[pair]) {
                    *e += x * *t;
                }
            }
            self.counterterms.set(c, self.counterterms.get(c) + x);
        }
        Ok(self)
    }

    /// The counterterms that [`spectra`](Self::spectra) include, of `pair`, at each k [(Mpc/h)^3].
    pub fn counterterm(&self, pair: Pair) -> Vec<f64> {
        let mut total = vec![0.0; self.k.len()];
        for c in Counterterm::ALL {
            let x = self.counterterms.get(c);
            if x != 0.0 {
                for (s, t) in total.iter_mut().zip(&self.counterterm_template(c)[pair]) {
                    *s += x * t.value;
                }
            }
        }
        total
    }
}

/// The counterterms of `spectra` (an EFT model, computed without counterterms) that fit `data`
/// (P_δδ at the spectra's k, with 1σ errors `sigma`) by weighted least squares over the points with
/// k ≤ `k_max`: the model is linear in them, so this is exact. Returns the values and their 1σ
/// errors.
///
/// # Errors
/// [`Error::LengthMismatch`] unless `data` and `sigma` have one value per k; [`Error::InvalidChoice`]
/// for a non-EFT model, spectra that already include counterterms, a non-positive σ, or fewer than
/// four points below k_max.
pub fn fit_counterterms(
    spectra: &RealSpectra,
    data: &[f64],
    sigma: &[f64],
    k_max: f64,
) -> Result<(Counterterms, Counterterms)> {
    let bad = |reason: &str| Error::InvalidChoice {
        what: format!("counterterm fit of model {}", spectra.model),
        reason: reason.into(),
    };
    for (what, v) in [("k and the data", data), ("k and sigma", sigma)] {
        if v.len() != spectra.k.len() {
            return Err(Error::LengthMismatch {
                what,
                left: spectra.k.len(),
                right: v.len(),
            });
        }
    }
    if !spectra.model.is_eft() {
        return Err(bad(
            "only the models 2l-eft and 2l-eft-ir have the counterterm set",
        ));
    }
    if !spectra.counterterms.is_zero() {
        return Err(bad("the spectra already include counterterms"));
    }
    if sigma.iter().any(|&s| s.is_nan() || s <= 0.0) {
        return Err(bad("every sigma must be positive"));
    }
    let rows: Vec<usize> = (0..spectra.k.len())
        .filter(|&i| spectra.k[i] <= k_max)
        .collect();
    if rows.len() < 4 {
        return Err(bad(
            "at least four points with k <= k_max are needed for three parameters",
        ));
    }
    let templates: Vec<Vec<Estimate>> = Counterterm::ALL
        .iter()
        .map(|&c| spectra.counterterm_template(c).dd)
        .collect();
    // Normal equations of the weighted problem, 3×3.
    let mut normal = vec![vec![0.0; 3]; 3];
    let mut rhs = vec![0.0; 3];
    for &i in &rows {
        let w = 1.0 / (sigma[i] * sigma[i]);
        let r = data[i] - spectra.spectra.dd[i].value;
        for p in 0..3 {
            rhs[p] += w * templates[p][i].value * r;
            for q in 0..3 {
                normal[p][q] += w * templates[p][i].value * templates[q][i].value;
            }
        }
    }
    let (solution, inverse, _) = crate::linalg::solve_spd(&normal, &rhs)?;
    let (mut values, mut errors) = (Counterterms::default(), Counterterms::default());
    for (p, &c) in Counterterm::ALL.iter().enumerate() {
        values.set(c, solution[p]);
        errors.set(c, inverse[p][p].sqrt());
    }
    Ok((values, errors))
}

//! What a face asks of the observation ([`ObservationSpec`]: window, bins, ξ, the Alcock–Paczynski
//! distortion), and any model's multipole table taken through a window and bins, or to ξ_ℓ(s)
//! ([`crate::survey::observe::Observation`]).

use crate::error::{Error, Result};
use crate::output::{Table, POWER, WAVENUMBER};
pub use crate::rsd::ap::ApSpec;
use crate::survey::observe::{Bins, Observation, Window};

/// The observed table of a model table `model` computed on the observation's
/// [`Observation::k_model`] with (at least) its [`Observation::model_ells`]: columns `k P<l>… err_P<l>…`
/// (`s xi<l>… err_xi<l>…` for ξ) at the observation's output k, its header the model's plus the
/// chain's description. The model's own error estimates are carried through the chain (applied to
/// them as to the values, in absolute value) and added to the chain's.
///
/// # Errors
/// [`Error::InvalidChoice`] if the model is not on the observation's model k or lacks one of its
/// multipoles; as [`Observation::apply`].
pub fn observed_table(model: &Table, observation: &Observation) -> Result<Table> {
    let k = model.column("k").unwrap_or_default();
    if k != observation.k_model() {
        return Err(Error::InvalidChoice {
            what: "the model of a windowed, binned or xi table".into(),
            reason: "must be computed on the observation's model k".into(),
        });
    }
    let column = |name: String| -> Result<Vec<f64>> {
        model
            .column(&name)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| Error::InvalidChoice {
                what: "the model of a windowed, binned or xi table".into(),
                reason: format!(
                    "has no column {name} (the chain needs {:?})",
                    observation.model_ells()
                ),
            })
    };
    let ells = observation.model_ells();
    let values = ells
        .iter()
        .map(|l| column(format!("P{l}")))
        .collect::<Result<Vec<_>>>()?;
    let errors = ells
        .iter()
        .map(|l| column(format!("err_P{l}")))
        .collect::<Result<Vec<_>>>()?;
    let observed = observation.apply(&values)?;
    let carried = observation.apply(&errors)?;
    let mut header: Vec<String> = model.header.clone();
    header.extend(observation.description().iter().cloned());
    let mut t = Table::new(header);
    t.methods = model.methods.clone();
    let (x, name, unit) = if observation.is_xi() {
        (("s", "Mpc/h"), "xi", "1")
    } else {
        (("k", WAVENUMBER), "P", POWER)
    };
    t.push(x.0, x.1, observation.k_out().to_vec());
    for (l, p) in observation.ells().iter().zip(&observed) {
        t.push(
            format!("{name}{l}"),
            unit,
            p.iter().map(|e| e.value).collect(),
        );
    }
    for ((l, p), c) in observation.ells().iter().zip(&observed).zip(&carried) {
        t.push(
            format!("err_{name}{l}"),
            unit,
            p.iter()
                .zip(c)
                .map(|(e, c)| e.error + c.value.abs())
                .collect(),
        );
    }
    Ok(t)
}

/// What a face asks of the observation, as its options say it (the one place that turns them into
/// an [`Observation`] and a distortion): correlation-function multipoles (`xi`, with optional s bin
/// edges), or the power spectrum through a window and/or bins, or neither (the model's own
/// multipoles); and the Alcock–Paczynski distortion of the measurement ([`ApSpec`]).
#[derive(Debug, Clone, Default)]
pub struct ObservationSpec {
    /// The survey window, if any.
    pub window: Option<Window>,
    /// The k bins, if any.
    pub bins: Option<Bins>,
    /// ξ_ℓ(s) instead of P_ℓ(k).
    pub xi: bool,
    /// With `xi`: the s bin edges [Mpc/h] (None: ξ at the given s).
    pub s_edges: Option<Vec<f64>>,
    /// The Alcock–Paczynski distortion of the measurement ([`ApSpec::distortion`] makes it for a
    /// prediction's cosmology and redshift).
    pub ap: ApSpec,
}

impl ObservationSpec {
    /// The observation of multipoles `ells` at the data's `k` [h/Mpc] (s [Mpc/h] for ξ), or `None`
    /// when nothing is asked for (the model's multipoles at k).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for ξ with a window or k bins (a Landy–Szalay ξ has the window divided
    /// out), or s edges without ξ; as [`Observation::new`] and [`Observation::xi`].
    pub fn build(self, ells: &[usize], k: &[f64]) -> Result<Option<Observation>> {
        let refuse = |reason: &str| Error::InvalidChoice {
            what: "the observation".into(),
            reason: reason.into(),
        };
        match (self.xi, self.window, self.bins) {
            (true, None, None) => Ok(Some(Observation::xi(ells, k, self.s_edges.as_deref())?)),
            (true, _, _) => Err(refuse(
                "correlation-function multipoles take no window or k bins (a Landy-Szalay xi has \
                 the window divided out)",
            )),
            (false, _, _) if self.s_edges.is_some() => Err(refuse(
                "s bin edges are for correlation-function multipoles (xi)",
            )),
            (false, None, None) => Ok(None),
            (false, window, bins) => Ok(Some(Observation::new(ells, k, window, bins)?)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spec makes the observation each face used to make by hand, and refuses the combinations
    /// that have no meaning (one of which a face used to ignore silently: ξ with a window).
    #[test]
    fn the_spec_decides_the_observation_and_refuses_what_has_no_meaning() {
        let k: Vec<f64> = (1..=20).map(|i| 0.01 * f64::from(i)).collect();
        assert!(ObservationSpec::default()
            .build(&[0, 2], &k)
            .unwrap()
            .is_none());
        let binned = ObservationSpec {
            bins: Bins::of(Some(vec![0.02, 0.06, 0.1]), None).unwrap(),
            ..ObservationSpec::default()
        };
        let o = binned.build(&[0, 2], &k).unwrap().unwrap();
        assert_eq!(o.k_out().len(), 2);
        let s: Vec<f64> = (1..=10).map(|i| 20.0 * f64::from(i)).collect();
        let xi = ObservationSpec {
            xi: true,
            ..ObservationSpec::default()
        };
        assert!(xi.build(&[0, 2], &s).unwrap().unwrap().is_xi());
        let bad = ObservationSpec {
            xi: true,
            bins: Bins::of(Some(vec![0.02, 0.06]), None).unwrap(),
            ..ObservationSpec::default()
        };
        let e = bad.build(&[0], &s).err().expect("refused").to_string();
        assert!(e.contains("no window or k bins"), "{e}");
        let stray = ObservationSpec {
            s_edges: Some(vec![10.0, 20.0]),
            ..ObservationSpec::default()
        };
        let e = stray.build(&[0], &k).err().expect("refused").to_string();
        assert!(e.contains("xi"), "{e}");
        let e = Bins::of(None, Some(1000.0)).unwrap_err().to_string();
        assert!(e.contains("give their edges"), "{e}");
    }
}

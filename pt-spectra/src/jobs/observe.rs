//! Any model's multipole table taken through a window and bins, or to ξ_ℓ(s)
//! ([`crate::survey::observe::Observation`]).

use crate::error::{Error, Result};
use crate::output::{Table, POWER, WAVENUMBER};
use crate::survey::observe::Observation;

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

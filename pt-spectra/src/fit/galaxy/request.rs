//! The checks of a galaxy fit's request: its parameter names, the free and marginalised sets, the
//! per-multipole k ranges and the priors.

use super::{linear_names, slot_index, GalaxyFitRequest, PriorShape, OWN_SLOT};
use crate::error::{Error, Result};
use crate::statistic::Kind;

/// The free and marginalised parameter indices, and per parameter its prior (mean, 1/σ²).
type Validated = (Vec<usize>, Vec<usize>, Vec<Option<PriorShape>>);

/// Checks the request's names and values, for a data set with a block of kind `block` (if any).
pub(super) fn validate(request: &GalaxyFitRequest, block: Option<&Kind>) -> Result<Validated> {
    let basis = &request.basis;
    let own = block.map_or(&[][..], |k| k.own);
    let slot = |name: &str| slot_index(name, basis, own);
    let free = request
        .free
        .iter()
        .map(|n| slot(n))
        .collect::<Result<Vec<_>>>()?;
    let mut marg = Vec::new();
    let linear: Vec<&str> = linear_names(basis)
        .iter()
        .chain(block.map_or(&[][..], |k| k.linear))
        .copied()
        .collect();
    for name in &request.marginalise {
        if !linear.contains(&name.as_str()) {
            if crate::blocks::owner(name).is_some() {
                slot(name)?; // a block's parameter: is the block there?
            }
            return Err(Error::InvalidChoice {
                what: format!("--marginalise {name}"),
                reason: format!(
                    "only parameters that enter linearly can be marginalised: {}",
                    linear.join(", ")
                ),
            });
        }
        marg.push(slot(name)?);
    }
    let mut seen = std::collections::HashSet::new();
    for name in request.free.iter().chain(&request.marginalise) {
        if !seen.insert(name.as_str()) {
            return Err(Error::InvalidChoice {
                what: format!("fit parameter `{name}`"),
                reason: "is listed twice (free and marginalised are exclusive)".into(),
            });
        }
    }
    if free.is_empty() {
        return Err(Error::InvalidChoice {
            what: "--free".into(),
            reason: "name at least one free parameter".into(),
        });
    }
    for &(l, lo, hi) in &request.ell_ranges {
        if !request.ells.contains(&l) {
            return Err(Error::InvalidChoice {
                what: format!("the k range of multipole {l}"),
                reason: format!("{l} is not a fitted multipole ({:?})", request.ells),
            });
        }
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::InvalidParameter {
                name: "per-multipole k_max [h/Mpc]",
                value: hi,
                reason: "a multipole's range needs finite k_min < k_max",
            });
        }
    }
    let mut priors = vec![None; OWN_SLOT + own.len()];
    for p in &request.priors {
        let i = slot(&p.name)?;
        p.shape.check(&p.name)?;
        if !free.contains(&i) && !marg.contains(&i) {
            return Err(Error::InvalidChoice {
                what: format!("the prior on {}", p.name),
                reason: format!(
                    "{} is fixed, and a prior acts only on a free or marginalised parameter \
                     (free: {}; marginalised: {})",
                    p.name,
                    request.free.join(", "),
                    if request.marginalise.is_empty() {
                        "none".to_string()
                    } else {
                        request.marginalise.join(", ")
                    }
                ),
            });
        }
        if marg.contains(&i) && p.shape.gaussian().is_none() {
            return Err(Error::InvalidChoice {
                what: format!("the prior {} on {}", p.shape, p.name),
                reason: "a marginalised parameter takes a Gaussian prior (or none): the analytic \
                         marginalisation integrates a Gaussian"
                    .into(),
            });
        }
        if priors[i].is_some() {
            return Err(Error::InvalidChoice {
                what: format!("the prior on {}", p.name),
                reason: "is given twice".into(),
            });
        }
        priors[i] = Some(p.shape.clone());
    }
    Ok((free, marg, priors))
}

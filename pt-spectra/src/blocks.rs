//! The statistics a data vector can hold after the power spectrum: the registration list of the
//! [`crate::statistic::Block`]s (docs/architecture.md, "Adding a statistic"). The pipeline and the
//! fits read it to say which block a parameter name belongs to when the data vector has none.

use crate::error::{Error, Result};
use crate::statistic::Kind;

/// Every kind of block, in the order of their registration.
pub const AVAILABLE: [&Kind; 2] = [
    &crate::bispectrum::block::KIND,
    &crate::bispectrum::loop_block::KIND,
];

/// The kind of block named `name` (its [`Kind::name`]).
///
/// # Errors
/// [`Error::InvalidChoice`] for another name, listing the registered ones.
pub fn by_name(name: &str) -> Result<&'static Kind> {
    AVAILABLE
        .into_iter()
        .find(|k| k.name == name)
        .ok_or_else(|| Error::InvalidChoice {
            what: format!("block `{name}`"),
            reason: format!("the blocks are {}", names().join(", ")),
        })
}

/// The names of the registered kinds.
pub fn names() -> Vec<&'static str> {
    AVAILABLE.iter().map(|k| k.name).collect()
}

/// The kind of block whose own parameter `name` is (`None`: no block's).
pub fn owner(name: &str) -> Option<&'static Kind> {
    AVAILABLE.into_iter().find(|k| k.index(name).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_not_registered_is_refused_listing_the_registered_ones() {
        for kind in AVAILABLE {
            assert_eq!(by_name(kind.name).unwrap().name, kind.name);
        }
        let e = by_name("trispectrum").unwrap_err().to_string();
        assert!(e.contains("trispectrum"), "{e}");
        for name in names() {
            assert!(e.contains(name), "{e}");
        }
    }

    #[test]
    fn every_face_builds_nothing_from_no_options_and_refuses_unknown_keys() {
        use crate::statistic::{OptionValue, Options};
        for kind in AVAILABLE {
            let n = kind.own.len();
            assert_eq!(
                (kind.defaults.len(), kind.units.len(), kind.ranges.len()),
                (n, n, n),
                "{}",
                kind.name
            );
            assert!((kind.faces.pipeline)(&Options::default())
                .unwrap()
                .is_none());
            let unknown = Options {
                entries: vec![("no_such_key".into(), OptionValue::Flag(true))],
                ..Options::default()
            };
            let e = (kind.faces.pipeline)(&unknown).unwrap_err().to_string();
            assert!(
                e.contains("no_such_key") && e.contains("unknown key"),
                "{e}"
            );
            if let Some(face) = kind.faces.analysis {
                let e = (face.check)(&unknown).unwrap_err().to_string();
                assert!(e.contains("no_such_key"), "{e}");
            }
        }
    }
}

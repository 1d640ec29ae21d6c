//! A block's settings as the faces give them, whatever the face: an analysis file's table
//! (`[dataset.<kind name>]`), a Python keyword's dict or keywords, a forecast bin's keys. Each face
//! converts its own text into [`Options`] without knowing the block; the block's [`super::Kind`]
//! reads them ([`super::Faces`]). The errors name where the options came from ([`Options::origin`])
//! and the key, as the analysis file's own keys do.

use crate::error::{Error, Result};
use std::path::PathBuf;

/// One value of a block's options.
#[derive(Debug, Clone, PartialEq)]
pub enum OptionValue {
    /// An integer (TOML's integers, Python's `int`).
    Integer(i64),
    /// A number.
    Number(f64),
    /// A string.
    Text(String),
    /// true or false.
    Flag(bool),
    /// A list (TOML's arrays, Python's sequences and arrays).
    List(Vec<OptionValue>),
    /// A value of another type (e.g. a table or a date), by its type's name: refused where read.
    Other(String),
}

/// A block's options by name (module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Options {
    /// Where they were given (e.g. the analysis file), for errors; empty: no prefix.
    pub origin: String,
    /// The prefix of their keys in errors (e.g. `dataset[1].bispectrum.`).
    pub at: String,
    /// The options, in the order given.
    pub entries: Vec<(String, OptionValue)>,
    /// The enclosing table's values (e.g. the data set's), which [`Self::inherited`] falls back on.
    pub parent: Vec<(String, OptionValue)>,
    /// The directory relative paths are resolved against (an analysis file's).
    pub base: Option<PathBuf>,
}

impl Options {
    /// The error at `key`: "{origin}: `{at}{key}`" and the rule.
    pub fn bad(&self, key: &str, reason: impl Into<String>) -> Error {
        let what = if self.origin.is_empty() {
            format!("`{}{key}`", self.at)
        } else {
            format!("{}: `{}{key}`", self.origin, self.at)
        };
        Error::InvalidChoice {
            what,
            reason: reason.into(),
        }
    }

    /// The value of `key`, if given.
    pub fn get(&self, key: &str) -> Option<&OptionValue> {
        self.entries.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// Whether `key` is given.
    pub fn has(&self, key: &str) -> bool {
        self.get(key).is_some()
    }

    /// The value of `key`, else the enclosing table's.
    pub fn inherited(&self, key: &str) -> Option<&OptionValue> {
        self.get(key)
            .or_else(|| self.parent.iter().find(|(k, _)| k == key).map(|(_, v)| v))
    }

    /// Refuses keys not in `allowed`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the first unknown key and the valid ones.
    pub fn known(&self, allowed: &[&str]) -> Result<()> {
        for (key, _) in &self.entries {
            if !allowed.contains(&key.as_str()) {
                return Err(self.bad(
                    key,
                    format!("unknown key; the keys here are {}", allowed.join(", ")),
                ));
            }
        }
        Ok(())
    }

    /// `v` (at `key`) as a finite number.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another value.
    pub fn number_of(&self, key: &str, v: &OptionValue) -> Result<f64> {
        match v {
            OptionValue::Number(x) if x.is_finite() => Ok(*x),
            OptionValue::Integer(n) => Ok(*n as f64),
            _ => Err(self.bad(key, "must be a finite number")),
        }
    }

    /// The number at `key`, if given.
    ///
    /// # Errors
    /// As [`Self::number_of`].
    pub fn number(&self, key: &str) -> Result<Option<f64>> {
        self.get(key).map(|v| self.number_of(key, v)).transpose()
    }

    /// The required value at `key`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] if it is missing.
    pub fn need(&self, key: &str) -> Result<&OptionValue> {
        self.get(key)
            .ok_or_else(|| self.bad(key, "is required (missing)"))
    }

    /// The string at `key`, if given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another value.
    pub fn text(&self, key: &str) -> Result<Option<&str>> {
        match self.get(key) {
            None => Ok(None),
            Some(OptionValue::Text(s)) => Ok(Some(s)),
            Some(_) => Err(self.bad(key, "must be a string")),
        }
    }

    /// The list of numbers at `key`, if given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another value.
    pub fn numbers(&self, key: &str) -> Result<Option<Vec<f64>>> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let bad = || self.bad(key, "must be an array `[…]` of numbers");
        let OptionValue::List(items) = v else {
            return Err(bad());
        };
        items
            .iter()
            .map(|x| match x {
                OptionValue::Number(v) => Ok(*v),
                OptionValue::Integer(n) => Ok(*n as f64),
                _ => Err(bad()),
            })
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// The list of non-negative integers at `key`, if given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another value.
    pub fn counts(&self, key: &str) -> Result<Option<Vec<usize>>> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let OptionValue::List(items) = v else {
            return Err(self.bad(key, "must be an array `[…]`"));
        };
        items
            .iter()
            .map(|x| match x {
                OptionValue::Integer(n) => usize::try_from(*n).ok(),
                _ => None,
            })
            .map(|n| n.ok_or_else(|| self.bad(key, "must be a non-negative integer")))
            .collect::<Result<Vec<usize>>>()
            .map(Some)
    }

    /// The rows of `width` numbers at `key` (e.g. triangles), if given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another value, naming `columns`.
    pub fn rows<const N: usize>(&self, key: &str, columns: &str) -> Result<Option<Vec<[f64; N]>>> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let bad = || self.bad(key, format!("must be an (n, {N}) array of {columns}"));
        let OptionValue::List(rows) = v else {
            return Err(bad());
        };
        rows.iter()
            .map(|r| match r {
                OptionValue::List(x) if x.len() == N => {
                    let mut row = [0.0; N];
                    for (slot, x) in row.iter_mut().zip(x) {
                        *slot = match x {
                            OptionValue::Number(v) => *v,
                            OptionValue::Integer(n) => *n as f64,
                            _ => return Err(bad()),
                        };
                    }
                    Ok(row)
                }
                _ => Err(bad()),
            })
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// The file at `key`, relative to [`Self::base`], which must exist; if given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a value that is not a string or a file that does not exist.
    pub fn file(&self, key: &str) -> Result<Option<PathBuf>> {
        let Some(name) = self.text(key)? else {
            return Ok(None);
        };
        let p = match &self.base {
            Some(b) => b.join(name),
            None => PathBuf::from(name),
        };
        if !p.is_file() {
            let relative = if self.base.is_some() {
                "the analysis file's directory"
            } else {
                "the working directory"
            };
            return Err(self.bad(
                key,
                format!(
                    "the file {} does not exist (paths are relative to {relative})",
                    p.display()
                ),
            ));
        }
        Ok(Some(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(entries: Vec<(&str, OptionValue)>) -> Options {
        Options {
            origin: "a.toml".into(),
            at: "dataset[1].block.".into(),
            entries: entries.into_iter().map(|(k, v)| (k.into(), v)).collect(),
            parent: vec![("n_bar".into(), OptionValue::Number(3e-4))],
            base: None,
        }
    }

    #[test]
    fn values_are_read_by_type_and_errors_name_origin_and_key() {
        use OptionValue::*;
        let o = options(vec![
            ("k", Integer(2)),
            ("x", Number(0.5)),
            ("name", Text("none".into())),
            ("ells", List(vec![Integer(0), Integer(2)])),
            ("rows", List(vec![List(vec![Number(0.1), Integer(1)])])),
            ("bad", List(vec![Number(0.5)])),
        ]);
        assert_eq!(o.number("k").unwrap(), Some(2.0));
        assert_eq!(o.number("x").unwrap(), Some(0.5));
        assert_eq!(o.number("absent").unwrap(), None);
        assert_eq!(o.text("name").unwrap(), Some("none"));
        assert_eq!(o.counts("ells").unwrap(), Some(vec![0, 2]));
        assert_eq!(o.rows::<2>("rows", "a, b").unwrap(), Some(vec![[0.1, 1.0]]));
        assert_eq!(o.inherited("n_bar"), Some(&Number(3e-4)));
        let e = o.counts("bad").unwrap_err().to_string();
        assert!(
            e.contains("a.toml: `dataset[1].block.bad`") && e.contains("non-negative integer"),
            "{e}"
        );
        let e = o.number("name").unwrap_err().to_string();
        assert!(e.contains("finite number"), "{e}");
        let e = o.rows::<3>("rows", "k1, k2, k3").unwrap_err().to_string();
        assert!(e.contains("(n, 3) array of k1, k2, k3"), "{e}");
        let e = o.known(&["k", "x"]).unwrap_err().to_string();
        assert!(
            e.contains("`dataset[1].block.name`") && e.contains("k, x"),
            "{e}"
        );
        let e = o.need("absent").unwrap_err().to_string();
        assert!(e.contains("required"), "{e}");
    }
}

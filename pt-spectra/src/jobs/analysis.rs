//! The analysis file of a joint fit (`fit --analysis FILE.toml`, `pt.fit_joint`): TOML, read into an
//! [`Analysis`]. Format and example: docs/analysis.md, examples/joint_analysis.toml.
//!
//! Every key is checked: an unknown key, a value of the wrong type, a missing required key, a file
//! that does not exist are errors naming the file, the key and the rule. Paths are relative to the
//! analysis file's directory.

use super::joint_fit::{Analysis, SetSpec};
use crate::error::{Error, Result};
use crate::fit::galaxy::{Linear, Prior, Search};
use crate::statistic::{OptionValue, Options};
use std::path::{Path, PathBuf};
use toml::value::Table as Map;
use toml::Value;

/// The top-level keys.
const TOP: [&str; 3] = ["shared", "search", "dataset"];
/// The keys of `[search]`.
const SEARCH: [&str; 4] = ["starts", "seed", "profile_check", "linear"];
/// The keys of a `[[dataset]]` besides the registered blocks' tables (`[dataset.<kind name>]`).
const SET: [&str; 29] = [
    "label",
    "z",
    "tracer",
    "data",
    "data_ells",
    "data_columns",
    "covariance",
    "n_mocks",
    "ells",
    "k_min",
    "k_max",
    "ell_ranges",
    "free",
    "marginalise",
    "priors",
    "start",
    "apar",
    "aperp",
    "fiducial",
    "window",
    "window_format",
    "window_mixing",
    "k_edges",
    "box",
    "ir",
    "basis",
    "n_bar",
    "satellites",
    "desi_priors",
];

/// The error at `key` of `origin`.
fn bad(origin: &str, key: &str, reason: impl Into<String>) -> Error {
    Error::InvalidChoice {
        what: format!("{origin}: `{key}`"),
        reason: reason.into(),
    }
}

/// Reads the analysis file at `path`.
///
/// # Errors
/// [`Error::Io`] if it cannot be read; [`Error::InvalidChoice`] naming the file, the key and the rule
/// for a TOML syntax error (with its line), an unknown key, a wrong type, a missing key, a data,
/// covariance or window file that does not exist, a label given twice.
pub fn read_analysis(path: &Path) -> Result<Analysis> {
    let text = crate::table::read_text(path)?;
    let base = path.parent().unwrap_or(Path::new("."));
    parse_analysis(&text, &path.display().to_string(), base)
}

/// Parses an analysis file's `text` (named `origin`; paths relative to `base`).
///
/// # Errors
/// As [`read_analysis`].
pub fn parse_analysis(text: &str, origin: &str, base: &Path) -> Result<Analysis> {
    let value: Value = text
        .parse()
        .map_err(|e: toml::de::Error| Error::InvalidChoice {
            what: origin.to_string(),
            reason: format!("is not valid TOML: {e}"),
        })?;
    let Value::Table(top) = value else {
        return Err(bad(origin, "", "the file must be a TOML table"));
    };
    known(origin, "", &top, &TOP)?;
    let shared = match top.get("shared") {
        None => None,
        Some(v) => Some(strings(origin, "shared", v)?),
    };
    let search = match top.get("search") {
        None => Search::default(),
        Some(Value::Table(t)) => search(origin, t)?,
        Some(_) => return Err(bad(origin, "search", "must be a table `[search]`")),
    };
    let sets = match top.get("dataset") {
        Some(Value::Array(a)) if !a.is_empty() => a,
        Some(_) => {
            return Err(bad(
                origin,
                "dataset",
                "must be an array of tables `[[dataset]]`",
            ))
        }
        None => {
            return Err(bad(
                origin,
                "dataset",
                "is missing: list each data set as a `[[dataset]]` table",
            ))
        }
    };
    let mut out = Vec::with_capacity(sets.len());
    for (i, v) in sets.iter().enumerate() {
        let Value::Table(t) = v else {
            return Err(bad(
                origin,
                &format!("dataset[{}]", i + 1),
                "must be a table",
            ));
        };
        let set = data_set(origin, base, i + 1, t)?;
        if out.iter().any(|s: &SetSpec| s.label == set.label) {
            return Err(bad(
                origin,
                &format!("dataset[{}].label", i + 1),
                format!("`{}` is given twice: labels must be unique", set.label),
            ));
        }
        out.push(set);
    }
    if let Some(shared) = &shared {
        for name in shared {
            if !out.iter().any(|s| s.free.contains(name)) {
                return Err(bad(
                    origin,
                    "shared",
                    format!(
                        "`{name}` is declared shared but no data set has it free (a shared \
                         parameter must be in every set's `free`)"
                    ),
                ));
            }
        }
    }
    Ok(Analysis {
        origin: origin.to_string(),
        shared,
        search,
        sets: out,
    })
}

/// Refuses keys of `table` (at `at`) not in `allowed`.
fn known(origin: &str, at: &str, table: &Map, allowed: &[&str]) -> Result<()> {
    for key in table.keys() {
        if !allowed.contains(&key.as_str()) {
            return Err(bad(
                origin,
                &format!("{at}{key}"),
                format!("unknown key; the keys here are {}", allowed.join(", ")),
            ));
        }
    }
    Ok(())
}

fn search(origin: &str, t: &Map) -> Result<Search> {
    known(origin, "search.", t, &SEARCH)?;
    let mut s = Search::default();
    if let Some(v) = t.get("starts") {
        s.starts = count(origin, "search.starts", v)?;
        if s.starts == 0 {
            return Err(bad(origin, "search.starts", "must be at least 1"));
        }
    }
    if let Some(v) = t.get("seed") {
        s.seed = count(origin, "search.seed", v)? as u64;
    }
    if let Some(v) = t.get("profile_check") {
        s.profile_check = v
            .as_bool()
            .ok_or_else(|| bad(origin, "search.profile_check", "must be true or false"))?;
    }
    if let Some(v) = t.get("linear") {
        s.linear = match v.as_str() {
            Some("marginalised") => Linear::Marginalised,
            Some("profiled") => Linear::Profiled,
            _ => {
                return Err(bad(
                    origin,
                    "search.linear",
                    "must be \"marginalised\" or \"profiled\"",
                ))
            }
        };
    }
    Ok(s)
}

fn number(origin: &str, key: &str, v: &Value) -> Result<f64> {
    match v {
        Value::Float(x) if x.is_finite() => Ok(*x),
        Value::Integer(n) => Ok(*n as f64),
        _ => Err(bad(origin, key, "must be a finite number")),
    }
}

fn count(origin: &str, key: &str, v: &Value) -> Result<usize> {
    v.as_integer()
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| bad(origin, key, "must be a non-negative integer"))
}

fn string(origin: &str, key: &str, v: &Value) -> Result<String> {
    v.as_str()
        .map(str::to_string)
        .ok_or_else(|| bad(origin, key, "must be a string"))
}

fn array<'v>(origin: &str, key: &str, v: &'v Value) -> Result<&'v Vec<Value>> {
    v.as_array()
        .ok_or_else(|| bad(origin, key, "must be an array `[…]`"))
}

fn strings(origin: &str, key: &str, v: &Value) -> Result<Vec<String>> {
    array(origin, key, v)?
        .iter()
        .map(|x| string(origin, key, x))
        .collect()
}

fn counts(origin: &str, key: &str, v: &Value) -> Result<Vec<usize>> {
    array(origin, key, v)?
        .iter()
        .map(|x| count(origin, key, x))
        .collect()
}

/// A path relative to `base` that must exist.
fn file(origin: &str, key: &str, base: &Path, v: &Value) -> Result<PathBuf> {
    let p = base.join(string(origin, key, v)?);
    if !p.is_file() {
        return Err(bad(
            origin,
            key,
            format!(
                "the file {} does not exist (paths are relative to the analysis file's directory)",
                p.display()
            ),
        ));
    }
    Ok(p)
}

/// The value of the optional `key` of `t` (at `at`) read by `read`.
fn optional<T>(
    origin: &str,
    at: &str,
    t: &Map,
    key: &str,
    read: impl Fn(&str, &str, &Value) -> Result<T>,
) -> Result<Option<T>> {
    t.get(key)
        .map(|v| read(origin, &format!("{at}{key}"), v))
        .transpose()
}

fn data_set(origin: &str, base: &Path, n: usize, t: &Map) -> Result<SetSpec> {
    let at = format!("dataset[{n}].");
    let mut keys = SET.to_vec();
    keys.extend(
        crate::blocks::AVAILABLE
            .iter()
            .filter(|k| k.faces.analysis.is_some())
            .map(|k| k.name),
    );
    known(origin, &at, t, &keys)?;
    let key = |k: &str| format!("{at}{k}");
    let need = |k: &str| {
        t.get(k)
            .ok_or_else(|| bad(origin, &key(k), "is required (missing)"))
    };
    let opt = |k: &str| t.get(k);
    let label = match opt("label") {
        Some(v) => string(origin, &key("label"), v)?,
        None => n.to_string(),
    };
    if label.is_empty()
        || !label
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(bad(
            origin,
            &key("label"),
            format!("`{label}`: a label is letters, digits, `_` or `-` (it names parameters)"),
        ));
    }
    let z = number(origin, &key("z"), need("z")?)?;
    let ells = counts(origin, &key("ells"), need("ells")?)?;
    let mut priors = Vec::new();
    if let Some(v) = opt("priors") {
        for text in strings(origin, &key("priors"), v)? {
            priors
                .push(Prior::parse(&text).map_err(|e| bad(origin, &key("priors"), e.to_string()))?);
        }
    }
    let mut start = Vec::new();
    if let Some(v) = opt("start") {
        let Value::Table(s) = v else {
            return Err(bad(
                origin,
                &key("start"),
                "must be a table of name = value",
            ));
        };
        for (name, v) in s {
            start.push((
                name.clone(),
                number(origin, &key(&format!("start.{name}")), v)?,
            ));
        }
    }
    let ap = match (opt("apar"), opt("aperp")) {
        (Some(a), Some(p)) => Some((
            number(origin, &key("apar"), a)?,
            number(origin, &key("aperp"), p)?,
        )),
        (None, None) => None,
        _ => return Err(bad(origin, &key("apar"), "apar and aperp go together")),
    };
    let ell_ranges = match opt("ell_ranges") {
        None => Vec::new(),
        Some(v) => array(origin, &key("ell_ranges"), v)?
            .iter()
            .map(|r| match r.as_array().map(Vec::as_slice) {
                Some([l, a, b]) => Ok((
                    count(origin, &key("ell_ranges"), l)?,
                    number(origin, &key("ell_ranges"), a)?,
                    number(origin, &key("ell_ranges"), b)?,
                )),
                _ => Err(bad(
                    origin,
                    &key("ell_ranges"),
                    "each entry is [ell, k_min, k_max], e.g. [4, 0.02, 0.1]",
                )),
            })
            .collect::<Result<_>>()?,
    };
    let flag = |name: &str| -> Result<Option<bool>> {
        opt(name)
            .map(|v| {
                v.as_bool()
                    .ok_or_else(|| bad(origin, &key(name), "must be true or false"))
            })
            .transpose()
    };
    let k_edges = match opt("k_edges") {
        None => None,
        Some(v) => Some(
            array(origin, &key("k_edges"), v)?
                .iter()
                .map(|x| number(origin, &key("k_edges"), x))
                .collect::<Result<Vec<_>>>()?,
        ),
    };
    Ok(SetSpec {
        label,
        z,
        tracer: optional(origin, &at, t, "tracer", string)?.unwrap_or_default(),
        data: file(origin, &key("data"), base, need("data")?)?,
        data_ells: match opt("data_ells") {
            Some(v) => counts(origin, &key("data_ells"), v)?,
            None => vec![0, 2, 4],
        },
        data_columns: optional(origin, &at, t, "data_columns", counts)?,
        covariance: optional(origin, &at, t, "covariance", |o, k, v| file(o, k, base, v))?,
        n_mocks: optional(origin, &at, t, "n_mocks", count)?,
        ells,
        k_min: optional(origin, &at, t, "k_min", number)?.unwrap_or(0.0),
        k_max: number(origin, &key("k_max"), need("k_max")?)?,
        ell_ranges,
        free: strings(origin, &key("free"), need("free")?)?,
        marginalise: optional(origin, &at, t, "marginalise", strings)?.unwrap_or_default(),
        priors,
        start,
        ap,
        fiducial: optional(origin, &at, t, "fiducial", string)?,
        window: optional(origin, &at, t, "window", |o, k, v| file(o, k, base, v))?,
        window_format: optional(origin, &at, t, "window_format", string)?
            .unwrap_or_else(|| "header".into()),
        window_mixing: optional(origin, &at, t, "window_mixing", string)?
            .unwrap_or_else(|| "wilson".into()),
        k_edges,
        box_side: optional(origin, &at, t, "box", number)?,
        ir: flag("ir")?.unwrap_or(true),
        basis: optional(origin, &at, t, "basis", string)?.unwrap_or_else(|| "velocileptors".into()),
        n_bar: optional(origin, &at, t, "n_bar", number)?,
        satellites: match opt("satellites") {
            None => None,
            Some(v) => match &array(origin, &key("satellites"), v)?[..] {
                [a, b] => Some((
                    number(origin, &key("satellites"), a)?,
                    number(origin, &key("satellites"), b)?,
                )),
                _ => {
                    return Err(bad(
                        origin,
                        &key("satellites"),
                        "is [f_sat, sigma_v], e.g. [0.1, 5.0]",
                    ))
                }
            },
        },
        desi_priors: flag("desi_priors")?.unwrap_or(false),
        block: block(origin, base, &at, t)?,
    })
}

/// `v` as a block's option value.
fn option_value(v: &Value) -> OptionValue {
    match v {
        Value::Integer(n) => OptionValue::Integer(*n),
        Value::Float(x) => OptionValue::Number(*x),
        Value::String(s) => OptionValue::Text(s.clone()),
        Value::Boolean(b) => OptionValue::Flag(*b),
        Value::Array(a) => OptionValue::List(a.iter().map(option_value).collect()),
        Value::Table(_) => OptionValue::Other("table".into()),
        Value::Datetime(_) => OptionValue::Other("date".into()),
    }
}

/// The entries of `t` as block options.
fn option_entries(t: &Map) -> Vec<(String, OptionValue)> {
    t.iter()
        .map(|(k, v)| (k.clone(), option_value(v)))
        .collect()
}

/// A data set's block: the table `[dataset.<kind name>]` of a registered kind that can be fitted,
/// checked by the kind ([`crate::statistic::AnalysisFace::check`]); the data set's table `set` (at
/// `at`) is its parent (e.g. its n_bar a default).
fn block(
    origin: &str,
    base: &Path,
    at: &str,
    set: &Map,
) -> Result<Option<(&'static str, Options)>> {
    let mut found = None;
    for kind in crate::blocks::AVAILABLE {
        let (Some(face), Some(v)) = (kind.faces.analysis, set.get(kind.name)) else {
            continue;
        };
        let Value::Table(b) = v else {
            return Err(bad(
                origin,
                &format!("{at}{}", kind.name),
                format!("must be a table `[dataset.{}]`", kind.name),
            ));
        };
        if let Some((other, _)) = found {
            return Err(bad(
                origin,
                &format!("{at}{}", kind.name),
                format!(
                    "a data set holds one block after the power spectrum (and it has a {other})"
                ),
            ));
        }
        let options = Options {
            origin: origin.to_string(),
            at: format!("{at}{}.", kind.name),
            entries: option_entries(b),
            parent: option_entries(set),
            base: Some(base.to_path_buf()),
        };
        (face.check)(&options)?;
        found = Some((kind.name, options));
    }
    Ok(found)
}

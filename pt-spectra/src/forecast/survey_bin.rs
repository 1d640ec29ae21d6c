//! One redshift bin of a forecast's survey: its shells, density, multipoles, fiducial nuisance
//! parameters and the blocks after its power spectrum (each by its kind's
//! [`crate::statistic::SurveyFace`]).

use super::DEFAULT_FREE_NUISANCE;
use crate::cosmology::Cosmology;
use crate::error::{Error, Result};
use crate::pipeline::{PipelineSettings, NUISANCE_NAMES};
use crate::statistic::{Shells, SurveyFace};

/// One redshift bin of a survey.
#[derive(Debug, Clone, PartialEq)]
pub struct SurveyBin {
    /// Effective redshift.
    pub z: f64,
    /// Comoving volume [(Mpc/h)³].
    pub volume: f64,
    /// Number density [(h/Mpc)³].
    pub n_bar: f64,
    /// The first shell's lower edge [h/Mpc].
    pub k_min: f64,
    /// The last shell's upper edge [h/Mpc] (shells of width `dk` up to it).
    pub k_max: f64,
    /// The shell width [h/Mpc].
    pub dk: f64,
    /// The multipoles measured (even, ≤ 4).
    pub ells: Vec<usize>,
    /// Fiducial nuisance parameters by name ([`NUISANCE_NAMES`]; unset: 0; b1 is required).
    pub nuisance: Vec<(String, f64)>,
    /// The free nuisance parameters (the others are fixed).
    pub free: Vec<String>,
    /// Gaussian priors (name, σ) on free nuisance parameters, centred on the fiducial.
    pub priors: Vec<(String, f64)>,
    /// The blocks after the power spectrum: each its kind's name and the number of its survey key
    /// ([`crate::statistic::SurveyFace`]); none: P alone.
    pub blocks: Vec<(&'static str, f64)>,
}

impl SurveyBin {
    /// A bin with k from 0.01 to `k_max` in shells of 0.01 h/Mpc, P0 and P2, b1, the
    /// [`DEFAULT_FREE_NUISANCE`] free with no priors.
    pub fn new(z: f64, volume: f64, n_bar: f64, k_max: f64, b1: f64) -> Self {
        Self {
            z,
            volume,
            n_bar,
            k_min: 0.01,
            k_max,
            dk: 0.01,
            ells: vec![0, 2],
            nuisance: vec![("b1".into(), b1)],
            free: DEFAULT_FREE_NUISANCE
                .iter()
                .map(|s| s.to_string())
                .collect(),
            priors: Vec::new(),
            blocks: Vec::new(),
        }
    }

    /// The numeric keys of a bin besides the nuisance parameters and the blocks' survey keys
    /// ([`Self::from_values`]).
    pub const KEYS: [&'static str; 7] = ["z", "volume", "n_bar", "k_max", "b1", "k_min", "dk"];

    /// The numeric keys of a bin: [`Self::KEYS`], then the survey key of every registered block.
    pub fn keys() -> Vec<&'static str> {
        let blocks = crate::blocks::AVAILABLE
            .iter()
            .filter_map(|k| k.faces.survey.map(|s| s.key));
        Self::KEYS.iter().copied().chain(blocks).collect()
    }

    /// A bin from its values by name, as the faces take them: `z`, `volume`, `n_bar`, `k_max`, `b1`
    /// (required), `k_min`, `dk`, a block's survey key ([`Self::with_block`]) and fiducial nuisance
    /// values by name; `what` names the bin in errors.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming a missing or unknown key.
    pub fn from_values(what: &str, values: &[(String, f64)]) -> Result<Self> {
        let bad = |reason: String| Error::InvalidChoice {
            what: what.to_string(),
            reason,
        };
        let get = |key: &str| values.iter().find(|(k, _)| k == key).map(|p| p.1);
        let required = |key: &str| get(key).ok_or_else(|| bad(format!("`{key}` is required")));
        let mut bin = Self::new(
            required("z")?,
            required("volume")?,
            required("n_bar")?,
            required("k_max")?,
            required("b1")?,
        );
        for kind in crate::blocks::AVAILABLE {
            if let Some(b) = kind.faces.survey.and_then(|s| get(s.key)) {
                bin = bin.with_block(kind, b);
            }
        }
        bin.k_min = get("k_min").unwrap_or(bin.k_min);
        bin.dk = get("dk").unwrap_or(bin.dk);
        let valid = bin.parameter_names();
        let keys = Self::keys();
        for (key, value) in values {
            if keys.contains(&key.as_str()) {
                continue;
            }
            if !valid.contains(&key.as_str()) {
                return Err(bad(format!(
                    "unknown key `{key}` (valid: {}, and the nuisance parameters {})",
                    keys.join(", "),
                    valid.join(", ")
                )));
            }
            bin.nuisance.push((key.clone(), *value));
        }
        Ok(bin)
    }

    /// With the block of `kind` whose survey key ([`crate::statistic::SurveyFace::key`]) is
    /// `value`, and its [`crate::statistic::Kind::forecast_free`] parameters free.
    pub fn with_block(mut self, kind: &'static crate::statistic::Kind, value: f64) -> Self {
        self.blocks.push((kind.name, value));
        for name in kind.forecast_free {
            if !self.free.iter().any(|n| n == name) {
                self.free.push(name.to_string());
            }
        }
        self
    }

    /// The shell centres [h/Mpc] and their lower and upper edges.
    pub(super) fn shells(&self) -> Vec<(f64, f64, f64)> {
        let n = ((self.k_max - self.k_min) / self.dk + 1e-9).floor() as usize;
        (0..n)
            .map(|i| {
                let lo = self.k_min + i as f64 * self.dk;
                (lo + 0.5 * self.dk, lo, lo + self.dk)
            })
            .collect()
    }

    /// The nuisance parameters of the bin's data vector: the power spectrum's, then each block's
    /// own.
    pub fn parameter_names(&self) -> Vec<&'static str> {
        let mut names = NUISANCE_NAMES.to_vec();
        for (kind, _) in self.block_faces() {
            names.extend(kind.own);
        }
        names
    }

    /// The bin's blocks: each registered kind and its survey face with the bin's number (a kind
    /// not registered or without a survey face is left out here and refused by [`Self::validate`]).
    fn block_faces(&self) -> Vec<(&'static crate::statistic::Kind, (SurveyFace, f64))> {
        self.blocks
            .iter()
            .filter_map(|(name, v)| {
                let kind = crate::blocks::by_name(name).ok()?;
                Some((kind, (kind.faces.survey?, *v)))
            })
            .collect()
    }

    /// The shells and n̄ the bin's blocks are planned on.
    fn block_shells(&self) -> Shells {
        Shells {
            k_min: self.k_min,
            k_max: self.k_max,
            dk: self.dk,
            edges: std::iter::once(self.k_min)
                .chain(self.shells().iter().map(|s| s.2))
                .collect(),
            n_bar: self.n_bar,
        }
    }

    /// The pipeline's settings of the bin: `ept` at its z with the AP distortion against `fiducial`
    /// and its blocks ([`crate::statistic::SurveyFace::plan`]).
    pub(super) fn pipeline_settings(&self, fiducial: &Cosmology) -> Result<PipelineSettings> {
        let mut settings = PipelineSettings::ept(self.z, Some(*fiducial));
        let shells = self.block_shells();
        for (_, (face, value)) in self.block_faces() {
            settings.blocks.push((face.plan)(value, &shells)?);
        }
        Ok(settings)
    }

    /// What the bin's blocks add, for a header (a phrase per block after the power spectrum's).
    pub fn block_notes(&self) -> String {
        self.block_faces()
            .iter()
            .map(|(_, (face, value))| (face.note)(*value))
            .collect()
    }

    /// Checks the values and names; the error names the bin (1-based) and the value.
    pub(super) fn validate(&self, index: usize) -> Result<()> {
        let bad = |what: String, reason: &str| Error::InvalidChoice {
            what: format!("survey bin {}: {what}", index + 1),
            reason: reason.into(),
        };
        for (name, v) in [
            ("volume [(Mpc/h)^3]", self.volume),
            ("n_bar [(h/Mpc)^3]", self.n_bar),
            ("k_min [h/Mpc]", self.k_min),
            ("dk [h/Mpc]", self.dk),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(format!("{name} = {v}"), "must be finite and > 0"));
            }
        }
        if !(self.z.is_finite() && self.z >= 0.0) {
            return Err(bad(format!("z = {}", self.z), "must be finite and >= 0"));
        }
        if !(self.k_max.is_finite() && self.k_max >= self.k_min + self.dk) {
            return Err(bad(
                format!("k_max = {}", self.k_max),
                "must reach at least one shell above k_min",
            ));
        }
        let shells = self.block_shells();
        for (name, value) in &self.blocks {
            let kind = crate::blocks::by_name(name).map_err(|e| in_bin(index, e))?;
            let face = kind.faces.survey.ok_or_else(|| {
                bad(
                    format!("block `{name}`"),
                    "has no survey face: a forecast cannot hold it",
                )
            })?;
            (face.check)(*value, &shells).map_err(|e| in_bin(index, e))?;
        }
        if self.ells.is_empty() || self.ells.iter().any(|&l| l % 2 == 1 || l > 4) {
            return Err(bad(
                format!("ells = {:?}", self.ells),
                "must be among 0, 2, 4",
            ));
        }
        let valid = self.parameter_names();
        for (name, _) in &self.nuisance {
            if !valid.contains(&name.as_str()) {
                return Err(bad(
                    format!("nuisance parameter `{name}`"),
                    &format!("valid: {}", valid.join(", ")),
                ));
            }
        }
        if !self.nuisance.iter().any(|(n, _)| n == "b1") {
            return Err(bad("b1".into(), "the fiducial linear bias is required"));
        }
        for name in self.free.iter().chain(self.priors.iter().map(|p| &p.0)) {
            if !valid.contains(&name.as_str()) {
                return Err(bad(
                    format!("free parameter `{name}`"),
                    &format!(
                        "the free nuisance parameters are among {}",
                        valid.join(", ")
                    ),
                ));
            }
        }
        for (name, sigma) in &self.priors {
            if !(sigma.is_finite() && *sigma > 0.0 && self.free.contains(name)) {
                return Err(bad(
                    format!("prior on `{name}` (sigma {sigma})"),
                    "a prior needs sigma > 0 on a free parameter",
                ));
            }
        }
        Ok(())
    }
}

/// `e` of survey bin `index` (0-based): its setting prefixed with the bin.
fn in_bin(index: usize, e: Error) -> Error {
    match e {
        Error::InvalidChoice { what, reason } => Error::InvalidChoice {
            what: format!("survey bin {}: {what}", index + 1),
            reason,
        },
        e => e,
    }
}

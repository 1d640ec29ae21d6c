//! Reading the tables the other subcommands write (by column name) and measured data (by position).

use anyhow::Result;
use std::path::Path;

/// A table written by pt-spectra, read back by name (the library's reader), with the plot's own
/// helpers.
pub struct Named(pub pt_spectra::output::WrittenTable);

impl std::ops::Deref for Named {
    type Target = pt_spectra::output::WrittenTable;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl Named {
    /// Reads a table (see [`pt_spectra::output::WrittenTable::parse`]).
    pub fn read(path: &Path) -> Result<Self> {
        Ok(Self(pt_spectra::output::WrittenTable::read(path)?))
    }

    /// A legend label: `z = …` from the first header line, else the file name.
    pub fn z_label(&self) -> String {
        match self.after(" z = ") {
            Some(z) if !z.is_empty() => format!("z = {}", z.split(';').next().unwrap_or(&z)),
            _ => Path::new(&self.origin)
                .file_stem()
                .map_or_else(|| self.origin.clone(), |s| s.to_string_lossy().into_owned()),
        }
    }

    /// The values of the column `name`, or an error naming the table's columns.
    pub fn need(&self, name: &str) -> Result<Vec<f64>> {
        Ok(self.0.need(name)?)
    }
}

/// Measured values: k, then per quantity its values and 1σ errors (zero if not given).
pub struct Measured {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// `values[j]`: the j-th quantity.
    pub values: Vec<Vec<f64>>,
    /// `sigma[j]`: its errors.
    pub sigma: Vec<Vec<f64>>,
}

impl Measured {
    /// Measured multipoles k P0 s0 P2 s2 P4 s4 (1-based columns 1..7, as `fit` reads by default).
    pub fn multipoles(path: &Path) -> Result<Self> {
        let t = pt_spectra::table::DataColumns::read(path, &[0, 1, 2, 3, 4, 5, 6])
            .map_err(|e| anyhow::anyhow!("--data: {e}"))?;
        let c = t.columns;
        Ok(Self {
            k: c[0].clone(),
            values: vec![c[1].clone(), c[3].clone(), c[5].clone()],
            sigma: vec![c[2].clone(), c[4].clone(), c[6].clone()],
        })
    }

    /// A measured real-space spectrum k P [σ] (1-based columns 1, 2 and, if every row has it, 3).
    pub fn spectrum(path: &Path) -> Result<Self> {
        let with_errors = pt_spectra::table::DataColumns::read(path, &[0, 1, 2]);
        let t = match with_errors {
            Ok(t) => t,
            Err(_) => pt_spectra::table::DataColumns::read(path, &[0, 1])
                .map_err(|e| anyhow::anyhow!("--data: {e}"))?,
        };
        let c = t.columns;
        let sigma = c.get(2).cloned().unwrap_or_else(|| vec![0.0; c[0].len()]);
        Ok(Self {
            k: c[0].clone(),
            values: vec![c[1].clone()],
            sigma: vec![sigma],
        })
    }
}

/// y(at) interpolated linearly in `x` (increasing), extended linearly by the end segments.
pub fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    if x.len() < 2 {
        return y.first().copied().unwrap_or(f64::NAN);
    }
    let j = x.partition_point(|&v| v <= at).clamp(1, x.len() - 1);
    let t = (at - x[j - 1]) / (x[j] - x[j - 1]);
    y[j - 1] + t * (y[j] - y[j - 1])
}

//! Reading the tables the other subcommands write (by column name) and measured data (by position).

use anyhow::{bail, Context, Result};
use std::path::Path;

/// A table written by pt-spectra: its header lines, the names of its `# k …` line, and its rows.
pub struct Named {
    /// The file, for messages.
    pub path: String,
    /// The header lines without `# ` (the first says what was computed).
    pub header: Vec<String>,
    /// The column names.
    pub names: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Named {
    /// Reads a table: the names are on the last `#` line before the first row, which must start with
    /// `# k` (`k`, `k_max`).
    pub fn read(path: &Path) -> Result<Self> {
        let shown = path.display().to_string();
        let text =
            std::fs::read_to_string(path).with_context(|| format!("cannot read `{shown}`"))?;
        let header: Vec<String> = text
            .lines()
            .take_while(|l| l.starts_with('#'))
            .map(|l| l.trim_start_matches('#').trim().to_string())
            .collect();
        let names: Vec<String> = header
            .last()
            .filter(|l| l.starts_with('k'))
            .with_context(|| format!("`{shown}`: no `# k …` names line (not a pt-spectra table?)"))?
            .split_whitespace()
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (i, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty())
        {
            let row: Vec<f64> = line
                .split_whitespace()
                .map(|v| v.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .with_context(|| format!("`{shown}`:{}: not a row of numbers", i + 1))?;
            if row.len() != names.len() {
                bail!(
                    "`{shown}`:{}: {} values for {} columns",
                    i + 1,
                    row.len(),
                    names.len()
                );
            }
            rows.push(row);
        }
        if rows.is_empty() {
            bail!("`{shown}`: no data rows");
        }
        Ok(Self {
            path: shown,
            header,
            names,
            rows,
        })
    }

    /// The first header line (what was computed).
    pub fn title(&self) -> &str {
        self.header.first().map_or("", String::as_str)
    }

    /// The text of the first header line after `key` up to the next `,` (e.g. the model after `rsd: `).
    pub fn after(&self, key: &str) -> Option<String> {
        let t = self.title();
        let at = t.find(key)? + key.len();
        Some(t[at..].split(',').next().unwrap_or("").trim().to_string())
    }

    /// The number after `key` in any header line (e.g. `sigma_v2 = `).
    pub fn header_number(&self, key: &str) -> Option<f64> {
        self.header.iter().find_map(|l| {
            let at = l.find(key)? + key.len();
            let rest = &l[at..];
            let end = rest
                .find(|c: char| c == ',' || c == ';' || c.is_whitespace())
                .unwrap_or(rest.len());
            rest[..end].parse().ok()
        })
    }

    /// A legend label: `z = …` from the first header line, else the file name.
    pub fn z_label(&self) -> String {
        match self.after(" z = ") {
            Some(z) if !z.is_empty() => format!("z = {}", z.split(';').next().unwrap_or(&z)),
            _ => Path::new(&self.path)
                .file_stem()
                .map_or_else(|| self.path.clone(), |s| s.to_string_lossy().into_owned()),
        }
    }

    /// The values of the column `name`.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.names.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| r[j]).collect())
    }

    /// The values of the column `name`, or an error naming the table's columns.
    pub fn need(&self, name: &str) -> Result<Vec<f64>> {
        self.column(name).with_context(|| {
            format!(
                "`{}` has no column `{name}` (it has {})",
                self.path,
                self.names.join(" ")
            )
        })
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
        let t = pt_spectra::table::Table::read(path, &[0, 1, 2, 3, 4, 5, 6])
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
        let with_errors = pt_spectra::table::Table::read(path, &[0, 1, 2]);
        let t = match with_errors {
            Ok(t) => t,
            Err(_) => pt_spectra::table::Table::read(path, &[0, 1])
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

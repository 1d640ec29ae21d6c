//! [`WindowMatrix`]: a window as a matrix, P̂_ℓ(k_o) = Σ_{ℓ',k_t} W[(ℓ, k_o), (ℓ', k_t)] P_ℓ'(k_t).
//!
//! Rows are the observed (ℓ, k_o), ℓ by ℓ in the order of `ells_out` and k_o in the order given; columns
//! the theory (ℓ', k_t) likewise: the layout desilike applies (pypower's `BaseMatrix.value` is the
//! transpose, theory by observed: say so with the `layout` line below).
//!
//! Text file:
//! ```text
//! # ells_out 0 2 4
//! # k_out 0.0025 0.0075 …            (shared by every ℓ; or one line per ℓ: `# k_out_0 …`, `# k_out_2 …`)
//! # ells_theory 0 2 4
//! # k_theory 0.001 0.002 …           (or `# k_theory_0 …` per ℓ')
//! # layout observed_by_theory        (optional; `theory_by_observed` for pypower's `.value`)
//! w_11 w_12 …                        (one row per observed (ℓ, k_o))
//! ```
//! k in h/Mpc. A `.npy` file (`np.save(path, matrix)`, a 2-D float64 or float32 array) is read with the
//! same metadata lines from the sidecar text file `<path>.txt` (e.g. `w.npy.txt`).

use super::super::text::parse_table;
use super::super::{check_ells, check_increasing, check_model};
use super::npy::parse_npy;
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::table::read_text;
use std::path::Path;

/// A window matrix with its observed and theory multipoles and k (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct WindowMatrix {
    ells_out: Vec<usize>,
    k_out: Vec<Vec<f64>>,
    ells_theory: Vec<usize>,
    k_theory: Vec<Vec<f64>>,
    /// Row-major, rows = Σ |k_out|, columns = Σ |k_theory|.
    values: Vec<f64>,
    origin: String,
}

impl WindowMatrix {
    /// The matrix `values` (row-major, one row per observed (ℓ, k_o)) with its axes; `k_out[i]` are the
    /// k of `ells_out[i]`, `k_theory[j]` those of `ells_theory[j]`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for multipoles that are not distinct even ℓ ≤ 8 or axes that do not match
    /// them, [`Error::InvalidK`] or [`Error::NonIncreasingK`] for bad k, [`Error::LengthMismatch`] if
    /// `values` is not rows × columns long, [`Error::InvalidValue`] for a value that is not finite.
    pub fn new(
        ells_out: Vec<usize>,
        k_out: Vec<Vec<f64>>,
        ells_theory: Vec<usize>,
        k_theory: Vec<Vec<f64>>,
        values: Vec<f64>,
    ) -> Result<Self> {
        Self::build(
            ells_out,
            k_out,
            ells_theory,
            k_theory,
            values,
            "window matrix".into(),
        )
    }

    fn build(
        ells_out: Vec<usize>,
        k_out: Vec<Vec<f64>>,
        ells_theory: Vec<usize>,
        k_theory: Vec<Vec<f64>>,
        values: Vec<f64>,
        origin: String,
    ) -> Result<Self> {
        check_ells("window matrix observed multipoles", &ells_out)?;
        check_ells("window matrix theory multipoles", &ells_theory)?;
        for (ells, ks, what) in [
            (&ells_out, &k_out, "k_out"),
            (&ells_theory, &k_theory, "k_theory"),
        ] {
            if ells.len() != ks.len() {
                return Err(Error::InvalidChoice {
                    what: format!("window matrix `{origin}`"),
                    reason: format!("{} lists of {what} for {} multipoles", ks.len(), ells.len()),
                });
            }
            for (ell, k) in ells.iter().zip(ks) {
                check_increasing(&format!("{origin}: {what} of ℓ = {ell}"), k, false)?;
                if k.is_empty() {
                    return Err(Error::TooFewPoints {
                        origin: format!("{origin}: {what} of ℓ = {ell}"),
                        found: 0,
                        min: 1,
                    });
                }
            }
        }
        let rows: usize = k_out.iter().map(Vec::len).sum();
        let cols: usize = k_theory.iter().map(Vec::len).sum();
        if values.len() != rows * cols {
            return Err(Error::LengthMismatch {
                what: "window matrix rows × columns and its values",
                left: rows * cols,
                right: values.len(),
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidValue {
                origin,
                line: i / cols + 1,
                name: "W",
                value: values[i],
                reason: "must be finite (the line is the matrix row)",
            });
        }
        Ok(Self {
            ells_out,
            k_out,
            ells_theory,
            k_theory,
            values,
            origin,
        })
    }

    /// Reads a window matrix: a `.npy` file with its `<path>.txt` sidecar, or a text file (module docs).
    ///
    /// # Errors
    /// [`Error::Io`] if a file cannot be read, [`Error::InvalidChoice`] for missing or bad metadata, a
    /// bad `.npy` file or a matrix of the wrong shape, and those of [`parse`](Self::parse) and
    /// [`new`](Self::new).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
        {
            let bytes = std::fs::read(path).map_err(|source| Error::Io {
                path: path.to_path_buf(),
                source,
            })?;
            let array = parse_npy(&bytes, &origin)?;
            let sidecar = format!("{origin}.txt");
            let text = read_text(Path::new(&sidecar))?;
            let lines: Vec<String> = text
                .lines()
                .map(|l| l.trim().trim_start_matches('#').trim().to_string())
                .collect();
            let meta = Meta::parse(&lines, &sidecar)?;
            meta.matrix(array.rows, array.cols, array.values, origin)
        } else {
            Self::parse(&read_text(path)?, &origin)
        }
    }

    /// Parses a text window matrix; `origin` names it in messages.
    ///
    /// # Errors
    /// [`Error::Parse`] or [`Error::BadRow`] for a malformed row, [`Error::InvalidChoice`] for missing or
    /// bad metadata or a matrix of the wrong shape, and those of [`new`](Self::new).
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let table = parse_table(text, origin)?;
        let lines: Vec<String> = table.comments.iter().map(|(_, c)| c.clone()).collect();
        let meta = Meta::parse(&lines, origin)?;
        let rows = table.rows.len();
        let cols = table.rows.first().map_or(0, Vec::len);
        meta.matrix(rows, cols, table.rows.concat(), origin.into())
    }

    /// The observed multipoles.
    pub fn ells_out(&self) -> &[usize] {
        &self.ells_out
    }

    /// The theory multipoles (the model's multipoles [`apply`](Self::apply) takes, in this order).
    pub fn ells_theory(&self) -> &[usize] {
        &self.ells_theory
    }

    /// The observed k [h/Mpc] of multipole `ell`, if it is observed.
    pub fn k_out(&self, ell: usize) -> Option<&[f64]> {
        let i = self.ells_out.iter().position(|&l| l == ell)?;
        Some(&self.k_out[i])
    }

    /// The theory k [h/Mpc] of multipole `ell`, where the model must be evaluated.
    pub fn k_theory(&self, ell: usize) -> Option<&[f64]> {
        let i = self.ells_theory.iter().position(|&l| l == ell)?;
        Some(&self.k_theory[i])
    }

    /// Where the matrix came from.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The windowed multipoles, one vector per observed ℓ, from the model's multipoles `p[j]` of
    /// `ells_theory()[j]` on `k_theory(ells_theory()[j])`. The product is exact (error 0).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] unless one array per theory multipole is given,
    /// [`Error::LengthMismatch`] for an array of the wrong length, [`Error::InvalidValue`] for a value
    /// that is not finite.
    pub fn apply(&self, p: &[Vec<f64>]) -> Result<Vec<Vec<Estimate>>> {
        if p.len() != self.ells_theory.len() {
            return Err(Error::InvalidChoice {
                what: format!("window matrix `{}`", self.origin),
                reason: format!(
                    "{} model multipoles given for the theory multipoles {:?}",
                    p.len(),
                    self.ells_theory
                ),
            });
        }
        for (values, k) in p.iter().zip(&self.k_theory) {
            check_model("WindowMatrix::apply", std::slice::from_ref(values), k.len())?;
        }
        let theory: Vec<f64> = p.concat();
        let cols = theory.len();
        let mut row = 0;
        Ok(self
            .k_out
            .iter()
            .map(|k| {
                (0..k.len())
                    .map(|_| {
                        let w = &self.values[row * cols..(row + 1) * cols];
                        row += 1;
                        Estimate::exact(w.iter().zip(&theory).map(|(a, b)| a * b).sum())
                    })
                    .collect()
            })
            .collect())
    }
}

/// The metadata lines of a window matrix.
#[derive(Debug, Default)]
struct Meta {
    origin: String,
    ells_out: Vec<usize>,
    ells_theory: Vec<usize>,
    /// (suffix ℓ or None for the shared list, values).
    k_out: Vec<(Option<usize>, Vec<f64>)>,
    k_theory: Vec<(Option<usize>, Vec<f64>)>,
    transposed: bool,
}

impl Meta {
    fn parse(lines: &[String], origin: &str) -> Result<Self> {
        let mut meta = Self {
            origin: origin.into(),
            ..Self::default()
        };
        let bad = |reason: String| Error::InvalidChoice {
            what: format!("window matrix `{origin}`"),
            reason,
        };
        let mut seen: Vec<&str> = Vec::new();
        for line in lines {
            let mut fields = line.split_whitespace();
            let Some(key) = fields.next() else { continue };
            // A key given twice (two `# k_out` lines) would leave one of them unread: refused.
            let is_key = ["ells_out", "ells_theory", "layout", "k_out", "k_theory"]
                .iter()
                .any(|k| key == *k || key.strip_prefix(k).is_some_and(|t| t.starts_with('_')));
            if is_key {
                if seen.contains(&key) {
                    return Err(bad(format!("`{key}` is given twice: `{line}`")));
                }
                seen.push(key);
            }
            let rest: Vec<&str> = fields.collect();
            let numbers = || {
                rest.iter()
                    .map(|f| f.trim_matches(',').parse::<f64>())
                    .collect::<std::result::Result<Vec<f64>, _>>()
                    .map_err(|_| bad(format!("`{key}` must be followed by numbers: `{line}`")))
            };
            let ells = || {
                rest.iter()
                    .map(|f| f.trim_matches(',').parse::<usize>())
                    .collect::<std::result::Result<Vec<usize>, _>>()
                    .map_err(|_| bad(format!("`{key}` must be followed by multipoles: `{line}`")))
            };
            let suffix = |prefix: &str| -> Option<Option<usize>> {
                let tail = key.strip_prefix(prefix)?;
                if tail.is_empty() {
                    Some(None)
                } else {
                    tail.strip_prefix('_')?.parse().ok().map(Some)
                }
            };
            if key == "ells_out" {
                meta.ells_out = ells()?;
            } else if key == "ells_theory" {
                meta.ells_theory = ells()?;
            } else if key == "layout" {
                meta.transposed = match rest.first().copied() {
                    Some("observed_by_theory") => false,
                    Some("theory_by_observed") => true,
                    _ => return Err(bad(format!("unknown layout `{line}`"))),
                };
            } else if let Some(ell) = suffix("k_out") {
                meta.k_out.push((ell, numbers()?));
            } else if let Some(ell) = suffix("k_theory") {
                meta.k_theory.push((ell, numbers()?));
            }
        }
        Ok(meta)
    }

    /// The k list of each ℓ: its own line, or the shared one.
    fn lists(
        &self,
        ells: &[usize],
        lists: &[(Option<usize>, Vec<f64>)],
        what: &str,
    ) -> Result<Vec<Vec<f64>>> {
        let shared = lists.iter().find(|(l, _)| l.is_none()).map(|(_, k)| k);
        ells.iter()
            .map(|ell| {
                lists
                    .iter()
                    .find(|(l, _)| *l == Some(*ell))
                    .map(|(_, k)| k)
                    .or(shared)
                    .cloned()
                    .ok_or_else(|| Error::InvalidChoice {
                        what: format!("window matrix `{}`", self.origin),
                        reason: format!("no `# {what}` or `# {what}_{ell}` line"),
                    })
            })
            .collect()
    }

    fn matrix(
        &self,
        rows: usize,
        cols: usize,
        values: Vec<f64>,
        origin: String,
    ) -> Result<WindowMatrix> {
        for (ells, key) in [
            (&self.ells_out, "ells_out"),
            (&self.ells_theory, "ells_theory"),
        ] {
            if ells.is_empty() {
                return Err(Error::InvalidChoice {
                    what: format!("window matrix `{}`", self.origin),
                    reason: format!("no `# {key} …` line"),
                });
            }
        }
        let k_out = self.lists(&self.ells_out, &self.k_out, "k_out")?;
        let k_theory = self.lists(&self.ells_theory, &self.k_theory, "k_theory")?;
        let n_out: usize = k_out.iter().map(Vec::len).sum();
        let n_theory: usize = k_theory.iter().map(Vec::len).sum();
        let (want_rows, want_cols) = if self.transposed {
            (n_theory, n_out)
        } else {
            (n_out, n_theory)
        };
        if (rows, cols) != (want_rows, want_cols) {
            let hint = if (rows, cols) == (want_cols, want_rows) {
                " (it is the transpose: add the line `# layout theory_by_observed`, or \
                 `observed_by_theory`)"
            } else {
                ""
            };
            return Err(Error::InvalidChoice {
                what: format!("window matrix `{origin}`"),
                reason: format!(
                    "{rows} × {cols} matrix, {want_rows} × {want_cols} expected from the \
                     {n_out} observed and {n_theory} theory k{hint}"
                ),
            });
        }
        let values = if self.transposed {
            (0..n_out)
                .flat_map(|i| (0..n_theory).map(move |j| (i, j)))
                .map(|(i, j)| values[j * n_out + i])
                .collect()
        } else {
            values
        };
        WindowMatrix::build(
            self.ells_out.clone(),
            k_out,
            self.ells_theory.clone(),
            k_theory,
            values,
            origin,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::npy::write_npy;
    use super::*;

    const TEXT: &str = "# a window matrix\n# ells_out 0 2\n# k_out 0.1 0.2\n# ells_theory 0\n\
                        # k_theory_0 0.05 0.1 0.15\n1 0 0\n0 1 0\n0.5 0.5 0\n0 0 2\n";

    /// A second `# k_out` line was read as nothing before (the first one won): refused.
    #[test]
    fn repeated_metadata_is_refused() {
        let text = TEXT.replace("# k_out 0.1 0.2\n", "# k_out 0.1 0.2\n# k_out 0.1 0.3\n");
        let e = WindowMatrix::parse(&text, "w.txt").unwrap_err().to_string();
        assert!(
            e.contains("`k_out` is given twice") && e.contains("w.txt"),
            "{e}"
        );
    }

    #[test]
    fn text_matrix_applies() {
        let w = WindowMatrix::parse(TEXT, "w.txt").unwrap();
        assert_eq!(w.ells_out(), &[0, 2]);
        assert_eq!(w.k_out(2).unwrap(), &[0.1, 0.2]);
        assert_eq!(w.k_theory(0).unwrap(), &[0.05, 0.1, 0.15]);
        let out = w.apply(&[vec![1.0, 2.0, 3.0]]).unwrap();
        let v: Vec<Vec<f64>> = out
            .iter()
            .map(|r| r.iter().map(|e| e.value).collect())
            .collect();
        assert_eq!(v, vec![vec![1.0, 2.0], vec![1.5, 6.0]]);
        assert!(w.apply(&[vec![1.0, 2.0]]).is_err());
        assert!(w.apply(&[vec![1.0; 3], vec![1.0; 3]]).is_err());
    }

    #[test]
    fn transposed_and_npy_matrices() {
        let t = "# ells_out 0 2\n# k_out 0.1 0.2\n# ells_theory 0\n# k_theory 0.05 0.1 0.15\n\
                 # layout theory_by_observed\n1 0 0.5 0\n0 1 0.5 0\n0 0 0 2\n";
        let w = WindowMatrix::parse(t, "t.txt").unwrap();
        assert_eq!(
            w,
            WindowMatrix {
                origin: "t.txt".into(),
                ..WindowMatrix::parse(TEXT, "t.txt").unwrap()
            }
        );
        let dir = std::env::temp_dir().join(format!("pt-spectra-wm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("w.npy");
        let values = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.5, 0.5, 0.0, 0.0, 0.0, 2.0];
        std::fs::write(&path, write_npy(4, 3, &values)).unwrap();
        let meta = "ells_out 0 2\nk_out 0.1 0.2\nells_theory 0\nk_theory 0.05 0.1 0.15\n";
        std::fs::write(dir.join("w.npy.txt"), meta).unwrap();
        let n = WindowMatrix::from_file(&path).unwrap();
        assert_eq!(n.values, values);
        assert_eq!(n.k_theory(0).unwrap(), &[0.05, 0.1, 0.15]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_matrices_are_refused() {
        let no_k = TEXT.replace("# k_out 0.1 0.2\n", "");
        assert!(matches!(
            WindowMatrix::parse(&no_k, "x"),
            Err(Error::InvalidChoice { .. })
        ));
        let transposed =
            "# ells_out 0 2\n# k_out 0.1 0.2\n# ells_theory 0\n# k_theory 0.05 0.1 0.15\n\
                          1 0 0.5 0\n0 1 0.5 0\n0 0 0 2\n";
        let e = WindowMatrix::parse(transposed, "x").unwrap_err();
        assert!(e.to_string().contains("theory_by_observed"), "{e}");
        let odd = TEXT.replace("ells_out 0 2", "ells_out 0 1");
        assert!(WindowMatrix::parse(&odd, "x").is_err());
        let unsorted = TEXT.replace("0.05 0.1 0.15", "0.05 0.15 0.1");
        assert!(matches!(
            WindowMatrix::parse(&unsorted, "x"),
            Err(Error::NonIncreasingK { .. })
        ));
        let nan = TEXT.replace("0 0 2", "0 0 nan");
        assert!(matches!(
            WindowMatrix::parse(&nan, "x"),
            Err(Error::InvalidValue { line: 4, .. })
        ));
    }
}

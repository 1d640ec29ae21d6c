//! How a file of measured multipoles is laid out (which columns hold k, P_ℓ and σ_ℓ of which ℓ), and
//! reading the fitted multipoles and their covariance from it: the one reader both faces use.

use super::MultipoleData;
use crate::error::{Error, Result};
use crate::table::DataColumns;
use std::path::Path;

/// The columns of a multipole file: k, then P_ℓ and σ_ℓ for each of its multipoles.
#[derive(Debug, Clone, PartialEq)]
pub struct DataLayout {
    /// The multipoles the file holds, in the order of their columns.
    pub data_ells: Vec<usize>,
    /// 1-based columns: k, then (P_ℓ, σ_ℓ) for each of `data_ells`.
    pub columns: Vec<usize>,
}

impl DataLayout {
    /// The layout of `data_ells` in `columns` (1-based, `k P_ℓ σ_ℓ …`; default 1, 2, …, 1 + 2n).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a column 0, a wrong number of columns or repeated multipoles.
    pub fn new(data_ells: &[usize], columns: Option<&[usize]>) -> Result<Self> {
        let columns = columns.map_or_else(
            || (1..=1 + 2 * data_ells.len()).collect(),
            <[usize]>::to_vec,
        );
        if columns.len() != 1 + 2 * data_ells.len() || columns.contains(&0) {
            return Err(Error::InvalidChoice {
                what: format!("data columns {columns:?}"),
                reason: format!(
                    "expected {} 1-based columns (k, then P_l, sigma_l for each of the data's multipoles {data_ells:?})",
                    1 + 2 * data_ells.len()
                ),
            });
        }
        if let Some(l) = data_ells
            .iter()
            .enumerate()
            .find_map(|(i, l)| data_ells[..i].contains(l).then_some(l))
        {
            return Err(Error::InvalidChoice {
                what: format!("data multipoles {data_ells:?}"),
                reason: format!("{l} is given twice"),
            });
        }
        Ok(Self {
            data_ells: data_ells.to_vec(),
            columns,
        })
    }

    /// Reads the multipoles `ells` (a subset of the file's) from `path`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for an ℓ the file does not hold; as [`MultipoleData::read`].
    pub fn read(&self, path: impl AsRef<Path>, ells: &[usize]) -> Result<MultipoleData> {
        let mut spec = Vec::with_capacity(ells.len());
        for &l in ells {
            let j = self.position(l)?;
            spec.push((l, self.columns[1 + 2 * j] - 1, self.columns[2 + 2 * j] - 1));
        }
        MultipoleData::read(path, self.columns[0] - 1, &spec)
    }

    /// Every multipole of the file at `path`, which must have exactly the layout's columns (no
    /// more: a file of more multipoles than declared is refused rather than read in part), as a
    /// likelihood declaring its data's multipoles wants.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a row with more columns than the layout; as [`Self::read`].
    pub fn read_exact(&self, path: impl AsRef<Path>) -> Result<MultipoleData> {
        let path = path.as_ref();
        let data = self.read(path, &self.data_ells)?;
        let last = self.columns.iter().copied().max().unwrap_or(1);
        // Ask for the column after the last one: every row must lack it.
        match DataColumns::read(path, &[last]) {
            Err(Error::MissingColumn { .. }) => Ok(data),
            Err(e) => Err(e),
            Ok(_) => Err(Error::InvalidChoice {
                what: format!("the data file `{}`", path.display()),
                reason: format!(
                    "has more than the {last} columns of k and (P_l, sigma_l) for l in {:?}; \
                     declare all its multipoles",
                    self.data_ells
                ),
            }),
        }
    }

    /// Attaches to `data` (read by [`Self::read`]) the covariance in `path`: ℓ-major over either the
    /// fitted multipoles or all the file's (`data_ells`, e.g. the P0, P2, P4 blocks of a survey's
    /// covariance while P0, P2 are fitted: the fitted blocks are taken from it), every k of the file.
    ///
    /// # Errors
    /// [`Error::Io`]; as [`MultipoleData::parse_covariance`].
    pub fn read_covariance(
        &self,
        data: MultipoleData,
        path: impl AsRef<Path>,
    ) -> Result<MultipoleData> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        let text = crate::table::read_text(path)?;
        let n_k = data.k.len();
        let full = self.data_ells.len() * n_k;
        let width = first_row_width(&text);
        if data.ells == self.data_ells || width != Some(full) {
            return data.parse_covariance(&text, &origin);
        }
        let table = DataColumns::parse_exact(&text, &origin, full)?;
        if table.lines.len() != full {
            return Err(Error::BadRow {
                origin,
                line: table.lines.last().copied().unwrap_or(0),
                problem: format!(
                    "the covariance has {} rows and {full} columns: it must be square ({} multipoles × {n_k} k)",
                    table.lines.len(),
                    self.data_ells.len()
                ),
            });
        }
        let index = self.block_index(&data)?;
        let c = index
            .iter()
            .map(|&r| index.iter().map(|&s| table.columns[s][r]).collect())
            .collect();
        let lines: Vec<usize> = index.iter().map(|&r| table.lines[r]).collect();
        data.checked_covariance(c, &origin, &lines)
    }

    /// Attaches to `data` the covariance matrix `c` (rows), ℓ-major over either the fitted multipoles
    /// or all the file's (the fitted blocks are taken), every k.
    ///
    /// # Errors
    /// As [`MultipoleData::with_covariance`]; [`Error::LengthMismatch`] for a size that is neither.
    pub fn attach_covariance(
        &self,
        data: MultipoleData,
        c: Vec<Vec<f64>>,
    ) -> Result<MultipoleData> {
        let n_k = data.k.len();
        let full = self.data_ells.len() * n_k;
        if c.len() != full || data.ells == self.data_ells || c.iter().any(|r| r.len() != full) {
            return data.with_covariance(c);
        }
        let index = self.block_index(&data)?;
        let sub = index
            .iter()
            .map(|&r| index.iter().map(|&s| c[r][s]).collect())
            .collect();
        data.checked_covariance(sub, "covariance matrix", &[])
    }

    /// The positions in the full (all the file's multipoles) data vector of the fitted ones.
    pub(crate) fn block_index(&self, data: &MultipoleData) -> Result<Vec<usize>> {
        let n_k = data.k.len();
        Ok(data
            .ells
            .iter()
            .map(|&l| self.position(l))
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .flat_map(|j| (0..n_k).map(move |i| j * n_k + i))
            .collect())
    }

    fn position(&self, l: usize) -> Result<usize> {
        self.data_ells
            .iter()
            .position(|&d| d == l)
            .ok_or_else(|| Error::InvalidChoice {
                what: format!("fitted multipole {l}"),
                reason: format!("is not among the data's multipoles {:?}", self.data_ells),
            })
    }
}

/// The number of fields of the first data row of a table text (`#` comments, blank or comma separated).
fn first_row_width(text: &str) -> Option<usize> {
    text.lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .map(|l| {
            l.split(|c: char| c.is_whitespace() || c == ',')
                .filter(|f| !f.is_empty())
                .count()
        })
        .find(|&n| n > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("pt-spectra-layout-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    /// P0, P2 of a file of P0, P2, P4 with the covariance of all three: the fitted blocks are taken,
    /// element for element; the fitted-only covariance reads the same.
    #[test]
    fn fitted_blocks_of_a_full_covariance() {
        let data = scratch("d.txt", "0.1 10 1 20 2 30 3\n0.2 11 1 21 2 31 3\n");
        let layout = DataLayout::new(&[0, 2, 4], None).unwrap();
        let d = layout.read(&data, &[0, 4]).unwrap();
        assert_eq!(d.values, vec![vec![10.0, 11.0], vec![30.0, 31.0]]);
        // 6×6: element (a, b) = 1 + a + b off the diagonal, 100 + a on it.
        let mut text = String::new();
        for a in 0..6 {
            let row: Vec<String> = (0..6)
                .map(|b| {
                    if a == b {
                        100.0 + a as f64
                    } else {
                        1.0 + (a + b) as f64
                    }
                    .to_string()
                })
                .collect();
            text += &(row.join(" ") + "\n");
        }
        let cov = scratch("c.txt", &text);
        let d = layout.read_covariance(d, &cov).unwrap();
        let c = d.covariance.unwrap();
        let index = [0, 1, 4, 5];
        for (i, &a) in index.iter().enumerate() {
            for (j, &b) in index.iter().enumerate() {
                let want = if a == b {
                    100.0 + a as f64
                } else {
                    1.0 + (a + b) as f64
                };
                assert_eq!(c[i][j], want);
            }
        }
        assert!(layout
            .read(&data, &[6])
            .unwrap_err()
            .to_string()
            .contains("6"));
        assert!(DataLayout::new(&[0, 2], Some(&[1, 2, 3])).is_err());
        assert!(DataLayout::new(&[0, 0], None).is_err());
    }
}

#[cfg(test)]
mod exact_tests {
    use super::*;

    #[test]
    fn read_exact_refuses_undeclared_columns_and_reads_declared_ones() {
        let dir = std::env::temp_dir().join(format!("pt-spectra-exact-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.dat");
        std::fs::write(&path, "# k P0 s0 P2 s2\n0.1 10 1 5 1\n0.2 8 1 4 1\n").unwrap();
        let two = DataLayout::new(&[0, 2], None).unwrap();
        let data = two.read_exact(&path).unwrap();
        assert_eq!(
            (data.ells.clone(), data.values[1].clone()),
            (vec![0, 2], vec![5.0, 4.0])
        );
        let one = DataLayout::new(&[0], None).unwrap();
        let e = one.read_exact(&path).unwrap_err().to_string();
        assert!(e.contains("more than the 3 columns"), "{e}");
        // `read` takes the declared columns of a wider file (as `fit --data` does).
        assert_eq!(one.read(&path, &[0]).unwrap().values, vec![vec![10.0, 8.0]]);
    }
}

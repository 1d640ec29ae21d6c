//! Log-spaced wavenumber grids.

use super::{check_positive, invalid};
use crate::error::Result;

/// A grid of `n` logarithmically spaced wavenumbers from `k_min` to `k_max` (both included), in h/Mpc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogGrid {
    /// First wavenumber [h/Mpc].
    pub k_min: f64,
    /// Last wavenumber [h/Mpc].
    pub k_max: f64,
    /// Number of points.
    pub n: usize,
}

impl LogGrid {
    /// The grid `n` log-spaced points from `k_min` to `k_max` [h/Mpc].
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidParameter`] unless 0 < `k_min` < `k_max` < ∞ and `n` ≥ 2.
    pub fn new(k_min: f64, k_max: f64, n: usize) -> Result<Self> {
        Self::named(
            (k_min, k_max, n),
            [
                "k_min [h/Mpc]",
                "k_max [h/Mpc]",
                "must exceed k_min",
                "n (grid points)",
            ],
        )
    }

    /// `n` log-spaced separations from `s_min` to `s_max` [Mpc/h] (the grid of ξ_ℓ(s); the fields
    /// keep the names of [`LogGrid::new`]).
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidParameter`] naming s_min, s_max or ns unless 0 < `s_min` <
    /// `s_max` < ∞ and `n` ≥ 2.
    pub fn separations(s_min: f64, s_max: f64, n: usize) -> Result<Self> {
        Self::named(
            (s_min, s_max, n),
            [
                "s_min [Mpc/h]",
                "s_max [Mpc/h]",
                "must exceed s_min",
                "ns (grid points)",
            ],
        )
    }

    /// The grid with the checks of [`LogGrid::new`], the values named by `names`: lower end, upper
    /// end, the reason an upper end is too small, the number of points.
    fn named((lo, hi, n): (f64, f64, usize), names: [&'static str; 4]) -> Result<Self> {
        check_positive(names[0], lo)?;
        check_positive(names[1], hi)?;
        if hi <= lo {
            return Err(invalid(names[1], hi, names[2]));
        }
        if n < 2 {
            return Err(invalid(names[3], n as f64, "must be at least 2"));
        }
        Ok(Self {
            k_min: lo,
            k_max: hi,
            n,
        })
    }

    /// The points as a validated [`crate::table::KGrid`] (valid by construction).
    pub fn k_grid(&self) -> crate::table::KGrid {
        crate::table::KGrid::valid(self.points())
    }

    /// The wavenumbers k_i = k_min (k_max/k_min)^(i/(n−1)) [h/Mpc].
    pub fn points(&self) -> Vec<f64> {
        let (a, b) = (self.k_min.ln(), self.k_max.ln());
        let step = (b - a) / (self.n - 1) as f64;
        (0..self.n)
            .map(|i| match i {
                0 => self.k_min,
                _ if i == self.n - 1 => self.k_max,
                _ => (a + step * i as f64).exp(),
            })
            .collect()
    }
}

impl Default for LogGrid {
    /// 1200 points from 1e-4 to 50 h/Mpc, the grid of the embedded CAMB tables.
    fn default() -> Self {
        Self {
            k_min: 1e-4,
            k_max: 50.0,
            n: 1200,
        }
    }
}

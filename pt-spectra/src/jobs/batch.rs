//! Many linear spectra on one plan at once: each row's spline, the model and its table, on rayon's
//! threads (the path of `RealPlan.batch` in Python, for chains and training sets), planned against
//! the memory limit before anything per spectrum is allocated: the results are allocated once
//! (fallibly), and the spectra run in chunks whose work space fits in what the limit leaves; a batch
//! whose results alone do not fit is refused with the estimate and the limit.

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::memory;
use crate::output::Table;
use crate::progress::Silent;
use crate::real::RealPlan;
use rayon::prelude::*;

use super::real_spectra_table;

/// The results of a batch: per column of the table `real` prints (`P_lin`, `P_dd`, …; not `k`), its
/// values spectrum after spectrum (row-major `spectra` × `k.len()`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BatchColumns {
    /// The output wavenumbers \[h/Mpc\].
    pub k: Vec<f64>,
    /// The number of spectra (rows).
    pub spectra: usize,
    /// (name, values) per column, in the table's order.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl BatchColumns {
    /// The values of the column `name` (row-major `spectra` × `k.len()`).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }
}

/// How a batch runs: `chunk` spectra at a time, with the estimated peak memory \[bytes\] of the
/// batch (results and the spectra in flight, the plan not included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchMemory {
    /// Spectra evaluated at a time (≥ 1).
    pub chunk: usize,
    /// The estimated peak memory \[bytes\] of the batch besides the plan.
    pub bytes: f64,
}

/// Work space \[bytes\] of each thread besides its row and spline: the lattice samples, the
/// evaluation's per-k terms with errors, the thread's buffers (generous: ~0.1 MB at 200 k).
const WORK_PER_THREAD: f64 = 1e6;
/// Bytes of a table besides its values: names, units, vectors.
const TABLE_OVERHEAD: f64 = 1e3;

/// The memory of the spectra in flight: per spectrum of a chunk its table until it is copied into
/// the results (≈ 3 copies of its `columns` × `nk` values with the [`RealSpectra`](crate::real::RealSpectra)
/// it came from, and [`TABLE_OVERHEAD`]), and per thread a row of `n_lin` values with its spline
/// (≈ 6 copies) and [`WORK_PER_THREAD`]: (per spectrum, fixed) \[bytes\]. Measured peak growth of
/// `RealPlan.batch` (4 December 2026, 1l-spt `fast`, 300-value rows, one chunk) less its results:
/// 5.7 kB per spectrum for 22 columns on 12 k (estimate 7.3 kB), 22.7 kB for 22 columns on 200 k
/// (106 kB), 5 kB for 5 columns on 200 k (25 kB).
fn in_flight(n_lin: usize, columns: usize, nk: usize) -> (f64, f64) {
    let per_spectrum = 8.0 * (3 * columns * nk) as f64 + TABLE_OVERHEAD;
    let threads = rayon::current_num_threads() as f64;
    (
        per_spectrum,
        threads * (8.0 * (6 * n_lin) as f64 + WORK_PER_THREAD),
    )
}

/// The memory of a batch of `spectra` linear spectra of `n_lin` values on `plan` whose tables have
/// `columns` columns (k included): the results once, and the spectra in flight (`in_flight`),
/// chunked so that it fits in the limit of the plan's precision ([`memory::limit`]; `max_memory`
/// \[bytes\] instead if given) less the plan's own estimate, and in the address space the process
/// has left ([`memory::address_space_left`]).
///
/// # Errors
/// [`Error::MemoryLimit`] with the estimate (results, one spectrum in flight and the plan) and the
/// limit, if not even that fits.
pub fn batch_memory(
    plan: &RealPlan,
    spectra: usize,
    n_lin: usize,
    columns: usize,
    max_memory: Option<f64>,
) -> Result<BatchMemory> {
    let nk = plan.k().len();
    let results = 8.0 * (columns.saturating_sub(1) * nk) as f64 * spectra as f64;
    let (per_spectrum, fixed) = in_flight(n_lin, columns, nk);
    let plan_bytes = RealPlan::memory_estimate(nk, plan.model(), plan.precision());
    let mut precision = plan.precision().clone();
    precision.max_memory = max_memory.or(precision.max_memory);
    let (limit, origin) = memory::limit(&precision);
    let mut room = limit - plan_bytes;
    let mut origin = origin;
    if let Some(left) = memory::address_space_left() {
        if left < room {
            room = left;
            origin = format!(
                "the address space this process has left under its limit (ulimit -v), {}",
                memory::size(left)
            );
        }
    }
    let fits = ((room - results - fixed) / per_spectrum).floor();
    if fits < 1.0 {
        let needed = plan_bytes + results + fixed + per_spectrum;
        return Err(Error::MemoryLimit {
            what: format!(
                "a batch of {spectra} spectra on {nk} k (the results {}, {} per spectrum in \
                 flight and {} for the threads, the {} plan {})",
                memory::size(results),
                memory::size(per_spectrum),
                memory::size(fixed),
                plan.model().name(),
                memory::size(plan_bytes)
            ),
            needed: memory::size(needed),
            limit: memory::size(limit.min(room + plan_bytes)),
            origin,
        });
    }
    let chunk = (fits.min(spectra.max(1) as f64) as usize).max(1);
    Ok(BatchMemory {
        chunk,
        bytes: results + fixed + chunk as f64 * per_spectrum,
    })
}

/// The linear spectra of a batch: `spectra` rows [(Mpc/h)^3] tabulated at `k_lin` [h/Mpc], already
/// at the output redshift, `row(i)` giving the values of row `i` (a row of `name`, for messages).
pub struct BatchRows<'a> {
    /// The wavenumbers of every row [h/Mpc].
    pub k_lin: &'a [f64],
    /// The number of rows.
    pub spectra: usize,
    /// The values of row `i` [(Mpc/h)^3].
    pub row: &'a (dyn Fn(usize) -> Vec<f64> + Sync),
    /// What the rows are called in messages (`row i of <name>`), e.g. `P`.
    pub name: &'a str,
}

/// The table of `plan`'s model (with `terms` the loop terms) for each of `rows`, as columns.
/// Planned first ([`batch_memory`], against `max_memory` \[bytes\] if given, else the plan's
/// limit): the results are allocated once, fallibly, and the spectra evaluated in chunks over the
/// threads; the numbers do not depend on the chunks.
///
/// # Errors
/// [`Error::MemoryLimit`] from [`batch_memory`] or when the results cannot be allocated;
/// [`Error::InvalidChoice`] naming the first bad row (`row i of <name>`: as
/// [`LinearSpectrum::from_nodes`] and [`RealPlan::evaluate`]).
pub fn real_batch(
    plan: &RealPlan,
    rows: &BatchRows,
    terms: bool,
    max_memory: Option<f64>,
) -> Result<BatchColumns> {
    real_batch_chunked(plan, rows, terms, max_memory, None)
}

/// [`real_batch`] with the chunk given (`None`: planned): the test of chunking's invariance.
fn real_batch_chunked(
    plan: &RealPlan,
    rows: &BatchRows,
    terms: bool,
    max_memory: Option<f64>,
    chunk: Option<usize>,
) -> Result<BatchColumns> {
    let (nk, spectra) = (plan.k().len(), rows.spectra);
    let mut out = BatchColumns {
        k: plan.k().to_vec(),
        spectra,
        columns: Vec::new(),
    };
    let table = |i: usize| -> Result<Table> {
        let bad = |e: Error| Error::InvalidChoice {
            what: format!("row {i} of {}", rows.name),
            reason: e.to_string(),
        };
        let spectrum =
            LinearSpectrum::from_nodes(rows.k_lin.to_vec(), (rows.row)(i)).map_err(bad)?;
        let spectra = plan.evaluate(&spectrum, &Silent).map_err(bad)?;
        Ok(real_spectra_table(&spectra, Vec::new(), terms))
    };
    if spectra == 0 {
        return Ok(out);
    }
    // The first spectrum gives the columns; the batch is planned before anything else is allocated.
    let first = table(0)?;
    let columns = first.names().len();
    let planned = batch_memory(plan, spectra, rows.k_lin.len(), columns, max_memory)?;
    let chunk = chunk.unwrap_or(planned.chunk).max(1);
    out.columns = allocate(&first, spectra * nk)?;
    append(&mut out.columns, &first);
    drop(first);
    for start in (1..spectra).step_by(chunk) {
        let end = (start + chunk).min(spectra);
        let tables: Vec<Result<Table>> = (start..end).into_par_iter().map(table).collect();
        for t in tables {
            append(&mut out.columns, &t?);
        }
    }
    Ok(out)
}

/// The result columns of tables like `first` (its columns but `k`), each with room for `values`
/// values, allocated fallibly.
///
/// # Errors
/// [`Error::MemoryLimit`] ([`memory::allocation_failed`]) if an allocation fails.
fn allocate(first: &Table, values: usize) -> Result<Vec<(String, Vec<f64>)>> {
    let names: Vec<&str> = first.names().into_iter().filter(|&n| n != "k").collect();
    names
        .iter()
        .map(|&name| {
            let mut v = Vec::new();
            v.try_reserve_exact(values).map_err(|_| {
                memory::allocation_failed(
                    8.0 * values as f64 * names.len() as f64,
                    &format!(
                        "the batch's results ({} columns of {values} values)",
                        names.len()
                    ),
                )
            })?;
            Ok((name.to_string(), v))
        })
        .collect()
}

/// Appends the values of `table` to `columns` (by name).
fn append(columns: &mut [(String, Vec<f64>)], table: &Table) {
    for (name, values) in columns.iter_mut() {
        values.extend_from_slice(table.column(name).unwrap_or_default());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::precision::Precision;
    use crate::real::RealModel;
    use crate::store::TableStore;

    fn plan(max_memory: Option<f64>) -> RealPlan {
        let mut precision = Precision::fast();
        precision.max_memory = max_memory;
        RealPlan::new(
            &[0.05, 0.1, 0.2],
            RealModel::OneLoopSpt,
            &precision,
            &TableStore::in_memory(),
            &Silent,
        )
        .unwrap()
    }

    /// Rows of the embedded spectrum scaled by 0.5 … 1.5.
    fn rows(n: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let (k_lin, p_lin) = p.nodes();
        let rows = (0..n)
            .map(|i| {
                let a = 0.5 + i as f64 / n as f64;
                p_lin.iter().map(|x| a * x).collect()
            })
            .collect();
        (k_lin.to_vec(), rows)
    }

    #[test]
    fn every_row_is_the_single_evaluation_and_a_bad_row_is_named() {
        let plan = plan(None);
        let (k_lin, rows) = rows(3);
        let row = |i: usize| rows[i].clone();
        let batch = BatchRows {
            k_lin: &k_lin,
            spectra: 3,
            row: &row,
            name: "P",
        };
        let out = real_batch(&plan, &batch, false, None).unwrap();
        assert_eq!(out.spectra, 3);
        for (i, row) in rows.iter().enumerate() {
            let single = LinearSpectrum::from_nodes(k_lin.clone(), row.clone()).unwrap();
            let expected =
                real_spectra_table(&plan.evaluate(&single, &Silent).unwrap(), Vec::new(), false);
            let got = &out.column("P_dd").unwrap()[3 * i..3 * i + 3];
            assert_eq!(Some(got), expected.column("P_dd"), "row {i}");
        }
        let mut bad = rows.clone();
        bad[1][3] = -1.0;
        let row = |i: usize| bad[i].clone();
        let batch = BatchRows { row: &row, ..batch };
        let e = real_batch(&plan, &batch, false, None).unwrap_err();
        assert!(e.to_string().starts_with("row 1 of P: "), "{e}");
    }

    /// Chunks of 1, 2 and 7 spectra give the numbers of one chunk, bit for bit.
    #[test]
    fn chunks_give_the_same_numbers() {
        let plan = plan(None);
        let (k_lin, rows) = rows(7);
        let row = |i: usize| rows[i].clone();
        let batch = BatchRows {
            k_lin: &k_lin,
            spectra: 7,
            row: &row,
            name: "P",
        };
        let whole = real_batch_chunked(&plan, &batch, true, None, Some(7)).unwrap();
        for chunk in [1, 2, 3] {
            let part = real_batch_chunked(&plan, &batch, true, None, Some(chunk)).unwrap();
            assert_eq!(part, whole, "chunk {chunk}");
        }
    }

    /// Under a limit the batch runs in chunks that fit; a batch whose results alone exceed the
    /// limit is refused with both figures, before anything is allocated.
    #[test]
    fn batches_are_planned_against_the_limit() {
        let free = plan(None);
        let plan_bytes = RealPlan::memory_estimate(3, RealModel::OneLoopSpt, free.precision());
        // Room for the results of 20000 spectra and ~10 in flight.
        let (n_lin, columns) = (400, 8);
        let (per_spectrum, fixed) = in_flight(n_lin, columns, 3);
        let results = 8.0 * 7.0 * 3.0 * 20000.0;
        let limited = plan(Some(plan_bytes + results + fixed + 10.5 * per_spectrum));
        let m = batch_memory(&limited, 20000, n_lin, columns, None).unwrap();
        assert_eq!(m.chunk, 10);
        assert!(m.bytes <= results + fixed + 10.5 * per_spectrum);
        let e = batch_memory(&limited, 200_000, n_lin, columns, None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a batch of 200000 spectra on 3 k")
                && e.contains("needs about")
                && e.contains("above"),
            "{e}"
        );
        assert_eq!(
            batch_memory(&free, 20000, n_lin, columns, None)
                .unwrap()
                .chunk,
            20000
        );
        // RealPlan::evaluate_batch holds every result: refused above the limit, before evaluating.
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let tight = plan(Some(plan_bytes + 5e3));
        assert_eq!(
            tight
                .evaluate_batch(std::slice::from_ref(&p))
                .unwrap()
                .len(),
            1
        );
        let e = tight.evaluate_batch(&[p.clone(), p.clone()]).unwrap_err();
        assert!(e.to_string().contains("a batch of 2 spectra on 3 k"), "{e}");
    }
}

//! Many linear spectra on one plan at once: each row's spline, the model and its table, all on
//! rayon's threads (the path of `RealPlan.batch` in Python, for chains and training sets).

use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::output::Table;
use crate::progress::Silent;
use crate::real::RealPlan;
use rayon::prelude::*;

use super::real_spectra_table;

/// The table of `plan`'s model (no header; with `terms` the loop terms) for every row of `rows`, a
/// linear spectrum [(Mpc/h)^3] tabulated at `k_lin` [h/Mpc] and already at the output redshift, in
/// order. The spline of each row, its evaluation and its table are one task each over the threads,
/// so nothing per spectrum runs serially.
///
/// # Errors
/// Per row: as [`LinearSpectrum::from_nodes`] and [`RealPlan::evaluate`].
pub fn real_batch_tables(
    plan: &RealPlan,
    k_lin: &[f64],
    rows: &[Vec<f64>],
    terms: bool,
) -> Vec<Result<Table>> {
    rows.par_iter()
        .map(|row| {
            let spectrum = LinearSpectrum::from_nodes(k_lin.to_vec(), row.clone())?;
            let spectra = plan.evaluate(&spectrum, &Silent)?;
            Ok(real_spectra_table(&spectra, Vec::new(), terms))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::precision::Precision;
    use crate::real::RealModel;
    use crate::store::TableStore;

    #[test]
    fn every_row_is_the_single_evaluation_and_a_bad_row_is_its_own_error() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let (k_lin, p_lin) = p.nodes();
        let k = [0.05, 0.1, 0.2];
        let plan = RealPlan::new(
            &k,
            RealModel::OneLoopSpt,
            &Precision::fast(),
            &TableStore::in_memory(),
            &Silent,
        )
        .unwrap();
        let half: Vec<f64> = p_lin.iter().map(|x| 0.5 * x).collect();
        let mut bad = p_lin.to_vec();
        bad[3] = -1.0;
        let rows = [p_lin.to_vec(), bad, half];
        let tables = real_batch_tables(&plan, k_lin, &rows, false);
        assert_eq!(tables.len(), 3);
        assert!(tables[1].is_err());
        for (row, table) in [(0, &tables[0]), (2, &tables[2])] {
            let single = LinearSpectrum::from_nodes(k_lin.to_vec(), rows[row].clone()).unwrap();
            let expected =
                real_spectra_table(&plan.evaluate(&single, &Silent).unwrap(), Vec::new(), false);
            let table = table.as_ref().unwrap();
            assert_eq!(table.column("P_dd"), expected.column("P_dd"), "row {row}");
        }
    }
}

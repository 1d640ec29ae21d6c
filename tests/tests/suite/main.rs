//! The cross-crate tests in one integration-test binary, one module per former `tests/tests/<name>.rs`
//! file (as the CLI tests, `pt-spectra/tests/cli/main.rs`). As 27 binaries, each linked all of pt-spectra
//! and compiled its own copies of the generic code it used; one binary builds with about a third less
//! CPU time. One module's tests: `cargo test --release -p pt-spectra-tests --test suite <name>::`.
//!
//! The modules share one process: no test may set environment variables or the current directory, and
//! the files a test writes have names of their own (under `CARGO_TARGET_TMPDIR`, or in the temporary
//! directory with the process id in the name).

mod common;
mod support;

mod ap;
mod bias;
mod bins;
mod bispectrum_basis_truncation;
mod bispectrum_dilation;
mod bispectrum_galaxy;
mod bispectrum_galaxy_bins;
mod bispectrum_galaxy_ct;
mod bispectrum_galaxy_ct_rsd;
mod bispectrum_galaxy_ir;
mod bispectrum_galaxy_kernels;
mod bispectrum_galaxy_multipoles;
mod bispectrum_galaxy_poly;
mod bispectrum_multipole_tensors;
mod bispectrum_one_loop;
mod bispectrum_reference;
mod cosmology_jacobian;
mod cospt;
mod eft;
mod ept;
mod fit;
mod hankel;
mod ir;
mod kernels_codegen;
mod kernels_exact;
mod kernels_limits;
mod one_loop;
mod parsers;
mod parsers_edges;
mod pipeline;
mod readers_faults;
mod redshift_kernels;
mod regpt;
mod rsd_two_loop;
mod three_loop;
mod tns;
mod two_loop;
mod two_loop_basis;
mod window;

/// Where the proptest modules keep their failing cases: beside the module, `<name>.proptest-regressions`
/// (`readers_faults.proptest-regressions` is checked in). proptest's default looks up from the source for
/// a `main.rs`, finds this file, and would read and write `tests/tests/proptest-regressions/<name>.txt`.
fn regressions_beside_the_source() -> Option<Box<dyn proptest::test_runner::FailurePersistence>> {
    Some(Box::new(
        proptest::test_runner::FileFailurePersistence::WithSource("proptest-regressions"),
    ))
}

//! The cross-crate tests (`tests/`) and criterion benchmarks (`tests/benches/`) of the pt-spectra
//! workspace, with the reference tables from other codes they compare against (`data/`, provenance
//! and the scripts that made them in `data/README.md`). The crate has no code of its own: its tests
//! exercise the public APIs of `pt-spectra`, `pt-kernels` and `kernelgen-core` together.

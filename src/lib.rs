//! Cross-crate tests and benchmarks of the pt-spectra workspace live in `tests/` and `benches/`.

//! `kernelgen`: generates the SPT kernels F_n^s, G_n^s (n ≤ 7) at compile time as flattened,
//! exact-rational straight-line code generic over a scalar type.
//!
//! This crate is a shim; the engine is `kernelgen-core`. Input language: see `kernelgen_core::parse`.

use proc_macro::TokenStream;

/// Generates one function per configuration, `name<T: Scalar>(g: &[T; N]) -> [T; 2]`, returning
/// `[F^s, G^s]` from the Gram matrix of the configuration's basis, and a `NAME_INFO` constant.
#[proc_macro]
pub fn kernels(input: TokenStream) -> TokenStream {
    kernelgen_core::expand(input.into())
        .unwrap_or_else(|e| e.to_compile_error())
        .into()
}

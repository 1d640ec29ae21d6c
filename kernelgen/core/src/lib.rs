//! The symbolic engine behind the `kernelgen` procedural macro.
//!
//! It expands the symmetrised SPT recursion for F_n^s and G_n^s (n ≤ 7) over subsets of the arguments, in
//! exact rational arithmetic, for a fixed configuration of arguments ([`spec`]); builds a hash-consed
//! expression graph in which every constant is folded and every zero-momentum subset is removed
//! ([`dag`], [`recursion`], [`program`]); and emits it as flattened straight-line Rust generic over a scalar
//! type ([`emit`]). The same recursion, run with α → 1 and β → 1/3, gives the angle-averaged vertices
//! ν_n and μ_n exactly ([`recursion::vertices`]).
//!
//! The macro crate is a thin shim over [`expand`]; everything here is ordinary, unit-tested Rust.

pub mod dag;
pub mod emit;
pub mod graph;
pub mod modp;
pub mod paired;
pub mod pairing;
pub mod parse;
pub mod program;
pub mod recursion;
pub mod redshift;
pub mod spec;

pub use program::{OpCounts, Program};
pub use recursion::vertices;
pub use spec::{Kind, Spec};

use proc_macro2::TokenStream;

/// Version stamped into every generated function's documentation.
pub const GENERATOR_VERSION: &str = concat!(env!("CARGO_PKG_NAME"), " ", env!("CARGO_PKG_VERSION"));

/// Expands the macro input (see [`parse`]) into the generated functions and their metadata constants.
pub fn expand(input: TokenStream) -> syn::Result<TokenStream> {
    let input: parse::Input = syn::parse2(input)?;
    let mut out = TokenStream::new();
    for item in &input.items {
        let program = Program::build(&item.spec);
        if item.paired && item.spec.kind != Kind::Spt {
            return Err(syn::Error::new(
                proc_macro2::Span::call_site(),
                format!("`{}`: only F^s, G^s kernels can be paired", item.spec.name),
            ));
        }
        if item.paired {
            let paired = pairing::best_pairing(&program).ok_or_else(|| {
                syn::Error::new(
                    proc_macro2::Span::call_site(),
                    format!(
                        "`{}` has no symmetry of its arguments to pair under",
                        item.spec.name
                    ),
                )
            })?;
            out.extend(emit::emit_paired(&paired, &input.paths, &item.docs)?);
        } else {
            out.extend(emit::emit(&program, &input.paths, &item.docs)?);
        }
    }
    Ok(out)
}

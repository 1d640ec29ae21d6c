//! Emission of a [`Program`] as a Rust function generic over a scalar type.
//!
//! The function takes the Gram matrix of the configuration's basis (`&[T; N]`, upper triangle, row-major)
//! and returns `[F^s, G^s]` (or the coefficients of the redshift-space Z_n in f). Each live graph node becomes one `let`; each rational coefficient becomes a
//! visible `let cJ = T::from_ratio(p, q);` (exact in f64 since |p|, q < 2^53, checked here); sums are
//! emitted as balanced trees (shorter dependency chains, smaller rounding error). The scalar trait must
//! provide `from_ratio(i64, i64) -> Self`, `safe_recip(&self) -> Self` (1/x, and 0 at an exact 0) and the
//! four arithmetic operators; the function also requires `T: Copy`.
//!
//! `Copy` is what keeps these functions quick to compile: every node is used by value, never borrowed,
//! so rustc hands LLVM each `let` as an SSA value. Written with `.clone()`, every node is borrowed and
//! becomes a stack slot that LLVM's scalar replacement of aggregates (SROA) has to promote again, at a cost
//! superlinear in the function's size: optimising `general_7` for `f64` took ~50 s that way, ~5 s this way,
//! for essentially the same machine code. Exact arithmetic runs through a `Copy` handle to a `BigRational`
//! (`pt_kernels`' `Exact`), so one function still runs in f64 and in exact rationals.

use crate::dag::{as_i64_pair, exact_in_f64, group_by_magnitude, NodeId, Op, Value, Q};
use crate::paired::{Output, PairOp, Paired};
use crate::program::{OpCounts, Program};
use crate::recursion::RecursionStats;
use crate::spec::{Kind, Spec};
use crate::GENERATOR_VERSION;
use num_traits::{One, Signed, Zero};
use proc_macro2::{Ident, Span, TokenStream};
use quote::{format_ident, quote};

/// Paths the emitted code refers to.
pub struct Paths {
    /// The scalar trait, e.g. `crate::Scalar`.
    pub scalar: syn::Path,
    /// The metadata struct, e.g. `crate::KernelInfo`.
    pub info: syn::Path,
    /// The lane-pair trait of paired kernels, e.g. `crate::PairScalar` (see [`emit_paired`]).
    pub pair: Option<syn::Path>,
}

struct Emitter {
    constants: Vec<Q>,
}

impl Emitter {
    fn constant(&mut self, r: &Q) -> Ident {
        let i = match self.constants.iter().position(|c| c == r) {
            Some(i) => i,
            None => {
                self.constants.push(r.clone());
                self.constants.len() - 1
            }
        };
        format_ident!("c{}", i)
    }

    /// `let cJ = T::from_ratio(p, q);` for every constant used, refusing any that f64 cannot hold exactly.
    fn constant_lets(&self) -> syn::Result<Vec<TokenStream>> {
        let mut consts = Vec::new();
        for (i, c) in self.constants.iter().enumerate() {
            let Some((n, d)) = as_i64_pair(c).filter(|_| exact_in_f64(c)) else {
                return Err(syn::Error::new(
                    Span::call_site(),
                    format!("coefficient {c} is not exact in f64"),
                ));
            };
            let ci = format_ident!("c{}", i);
            consts.push(quote!(let #ci = T::from_ratio(#n, #d);));
        }
        Ok(consts)
    }

    fn node(id: NodeId) -> Ident {
        format_ident!("x{}", id)
    }

    /// `|r| * x` as tokens, with the sign returned separately.
    fn scaled(&mut self, r: &Q, x: TokenStream) -> (bool, TokenStream) {
        let negative = r.is_negative();
        let mag = r.abs();
        if mag.is_one() {
            (negative, x)
        } else {
            let c = self.constant(&mag);
            (negative, quote!(#c * #x))
        }
    }

    fn value(&mut self, v: &Value) -> TokenStream {
        let (neg, t) = match v.node {
            None => {
                let c = self.constant(&v.coef.abs());
                (v.coef.is_negative(), quote!(#c))
            }
            Some(id) => {
                let x = Self::node(id);
                self.scaled(&v.coef, quote!(#x))
            }
        };
        if neg {
            quote!(-(#t))
        } else {
            t
        }
    }

    /// Σ c_i x_i + c_0 with the terms grouped by |c_i|: one multiplication per distinct coefficient.
    fn lin(&mut self, terms: &[(Q, NodeId)], c0: &Q) -> (bool, TokenStream) {
        self.lin_of(terms, c0, |id| {
            let x = Self::node(id);
            quote!(#x)
        })
    }

    /// [`Self::lin`] with the variables named by `leaf`.
    fn lin_of(
        &mut self,
        terms: &[(Q, usize)],
        c0: &Q,
        leaf: impl Fn(usize) -> TokenStream,
    ) -> (bool, TokenStream) {
        let mut parts: Vec<(bool, TokenStream)> = Vec::new();
        for (mag, group) in group_by_magnitude(terms) {
            let signed: Vec<(bool, TokenStream)> =
                group.iter().map(|&(neg, id)| (neg, leaf(id))).collect();
            if mag.is_one() {
                parts.extend(signed);
            } else {
                let (neg, sum) = balanced_sum(signed);
                let c = self.constant(&mag);
                parts.push((neg, quote!(#c * #sum)));
            }
        }
        if !c0.is_zero() {
            let c = self.constant(&c0.abs());
            parts.push((c0.is_negative(), quote!(#c)));
        }
        balanced_sum(parts)
    }

    fn statement(&mut self, id: NodeId, op: &Op) -> TokenStream {
        let x = Self::node(id);
        let rhs = match op {
            Op::Input(i) => quote!(g[#i]),
            Op::Mul(a, b) => {
                let (a, b) = (Self::node(*a), Self::node(*b));
                quote!(#a * #b)
            }
            Op::Recip(a) => {
                let a = Self::node(*a);
                quote!(#a.safe_recip())
            }
            Op::Lin(terms, c0) => {
                let (neg, t) = self.lin(terms, c0);
                if neg {
                    quote!(-(#t))
                } else {
                    t
                }
            }
        };
        quote!(let #x = #rhs;)
    }
}

/// Sum of signed terms as a balanced tree; returns (negated, expression).
fn balanced_sum(mut parts: Vec<(bool, TokenStream)>) -> (bool, TokenStream) {
    if parts.len() == 1 {
        return parts.pop().expect("one part");
    }
    let right = parts.split_off(parts.len() / 2);
    let (ln, l) = balanced_sum(parts);
    let (rn, r) = balanced_sum(right);
    match (ln, rn) {
        (false, false) => (false, quote!((#l + #r))),
        (false, true) => (false, quote!((#l - #r))),
        (true, false) => (false, quote!((#r - #l))),
        (true, true) => (true, quote!((#l + #r))),
    }
}

/// Emits the function `name<T>(g: &[T; N]) -> [T; M]` (M = 2 for `[F, G]`, n + 1 for the coefficients of
/// Z_n) and its `NAME_INFO` metadata constant.
pub fn emit(program: &Program, paths: &Paths, docs: &[syn::Attribute]) -> syn::Result<TokenStream> {
    let spec = &program.spec;
    let mut e = Emitter {
        constants: Vec::new(),
    };
    let live = program.live();
    let mut body = Vec::new();
    for (id, op) in program.dag.ops().iter().enumerate() {
        if live[id] {
            body.push(e.statement(id, op));
        }
    }
    let outputs: Vec<TokenStream> = program.outputs.iter().map(|o| e.value(o)).collect();
    let consts = e.constant_lets()?;

    let name = Ident::new(&spec.name, Span::call_site());
    let scalar = &paths.scalar;
    let n_inputs = spec.n_inputs();
    let n_outputs = proc_macro2::Literal::usize_unsuffixed(spec.n_outputs());
    let order = spec.order();
    let counts = program.op_counts();
    let (muls, adds, recips, statements) =
        (counts.muls, counts.adds, counts.recips, counts.statements);
    let stats = program.stats;
    let (subkernels, zero_subsets, splits) =
        (stats.subkernels, stats.zero_momentum_subsets, stats.splits);
    let args = spec.arg_names().join(", ");
    let inputs = spec.input_names().join(", ");
    let info_const = info_const(&paths.info, spec, counts, stats);
    let what = match spec.kind {
        Kind::Spt => format!(
            "F_{order}^s and G_{order}^s at ({args}).\n\n Input `g`: the basis Gram matrix [{inputs}]. \
             Output: `[F, G]`."
        ),
        Kind::Redshift => format!(
            "the redshift-space kernel Z_{order}({args}; f, los) = Σ_m f^m Z^(m) (Scoccimarro, Couchman & \
             Frieman 1999) as its coefficients in the growth rate f; `los` is the line of sight, of any \
             non-zero length.\n\n Input `g`: the Gram matrix [{inputs}]. Output: `[Z^(0), …, Z^({order})]`, \
             Z^(0) = F_{order}^s."
        ),
    };
    let header = format!(
        " Generated by kernelgen {GENERATOR_VERSION}: {what}\n \
         Straight-line code: {statements} statements, {muls} multiplications, {adds} additions, \
         {recips} reciprocals; {subkernels} sub-kernels, {zero_subsets} zero-momentum subsets removed at \
         generation time, {splits} subset splits.",
    );
    Ok(quote! {
        #(#docs)*
        #[doc = ""]
        #[doc = #header]
        #[inline(never)]
        pub fn #name<T: #scalar + Copy>(g: &[T; #n_inputs]) -> [T; #n_outputs] {
            #(#consts)*
            #(#body)*
            [#(#outputs),*]
        }


        #info_const
    })
}

/// Emits the paired kernel `name<T: Pair>(g: &[T::Lane; N]) -> [T::Lane; 2]` and its `NAME_INFO` constant:
/// one evaluation in the two lanes of `T`, the second lane running the mirror image (see
/// [`crate::pairing`]). The pair trait (named by `pair = <path>;` in the macro header) must provide
/// `type Lane: Scalar + Copy`, `pair(a, b) -> Self`, `swap(self) -> Self` and `lane(self, i) -> Lane`.
pub fn emit_paired(
    paired: &Paired,
    paths: &Paths,
    docs: &[syn::Attribute],
) -> syn::Result<TokenStream> {
    let spec = &paired.spec;
    let Some(pair) = &paths.pair else {
        return Err(syn::Error::new(
            Span::call_site(),
            format!(
                "`{}` is paired: name the lane-pair trait with `pair = <path>;` in the header",
                spec.name
            ),
        ));
    };
    let mut e = Emitter {
        constants: Vec::new(),
    };
    let y = |v: usize| format_ident!("y{}", v);
    let leaf = |v: usize| {
        let x = y(v);
        quote!(#x)
    };
    let mut body = Vec::new();
    for (i, op) in paired.ops.iter().enumerate() {
        let rhs = match op {
            PairOp::Input { i, j, negated } if *negated => quote!(T::pair(g[#i], -g[#j])),
            PairOp::Input { i, j, .. } => quote!(T::pair(g[#i], g[#j])),
            PairOp::Mul { a, b, swap_b } => {
                let (a, b) = (y(*a), y(*b));
                if *swap_b {
                    quote!(#a * #b.swap())
                } else {
                    quote!(#a * #b)
                }
            }
            PairOp::Recip(a) => {
                let a = y(*a);
                quote!(#a.safe_recip())
            }
            PairOp::Lin {
                direct,
                swapped,
                c0,
            } => {
                let mut parts = Vec::new();
                if !direct.is_empty() || !c0.is_zero() {
                    parts.push(e.lin_of(direct, c0, leaf));
                }
                if !swapped.is_empty() {
                    let (neg, t) = e.lin_of(swapped, &Q::zero(), leaf);
                    parts.push((neg, quote!((#t).swap())));
                }
                let (neg, t) = balanced_sum(parts);
                if neg {
                    quote!(-(#t))
                } else {
                    t
                }
            }
        };
        let yi = y(i);
        body.push(quote!(let #yi = #rhs;));
    }
    let mut output = |o: &Output| {
        let (neg, mag) = (o.coef.is_negative(), o.coef.abs());
        let t = match o.var {
            None => {
                let c = e.constant(&mag);
                quote!(#c.lane(0))
            }
            Some((v, lane)) if mag.is_one() => {
                let x = y(v);
                quote!(#x.lane(#lane))
            }
            Some((v, lane)) => {
                let (c, x) = (e.constant(&mag), y(v));
                quote!((#c.lane(0) * #x.lane(#lane)))
            }
        };
        if neg {
            quote!(-(#t))
        } else {
            t
        }
    };
    let (f, g) = (output(&paired.f), output(&paired.g));
    let consts = e.constant_lets()?;
    let name = Ident::new(&spec.name, Span::call_site());
    let n_inputs = spec.n_inputs();
    let order = spec.order();
    let counts = paired.op_counts();
    let (muls, adds, recips, statements) =
        (counts.muls, counts.adds, counts.recips, counts.statements);
    let args = spec.arg_names();
    let inputs = spec.input_names();
    let info_const = info_const(&paths.info, spec, counts, paired.stats);
    let c = paired.counts;
    let header = format!(
        " Generated by kernelgen {GENERATOR_VERSION}: F_{order}^s and G_{order}^s at ({}), in lane pairs.\n\n \
         Input `g`: the basis Gram matrix [{}]. Output: `[F, G]`.\n \
         Lane 1 evaluates the mirror image under {}, so each of the direct program's {} statements is \
         paired ({}), mirrored ({}, free) or merged with an equal one ({}): {statements} packed statements \
         with {} lane swaps, {muls} multiplications, {adds} additions, {recips} reciprocals.",
        args.join(", "),
        inputs.join(", "),
        paired.involution.describe(spec),
        c.direct,
        c.statements,
        c.mirrored,
        c.merged,
        c.swaps,
    );
    Ok(quote! {
        #(#docs)*
        #[doc = ""]
        #[doc = #header]
        #[inline(never)]
        pub fn #name<T: #pair + Copy>(g: &[<T as #pair>::Lane; #n_inputs]) -> [<T as #pair>::Lane; 2] {
            #(#consts)*
            #(#body)*
            [#f, #g]
        }


        #info_const
    })
}

/// The `NAME_INFO` constant of a generated function: its configuration and the size of its code.
fn info_const(
    info: &syn::Path,
    spec: &Spec,
    counts: OpCounts,
    stats: RecursionStats,
) -> TokenStream {
    let name = Ident::new(&spec.name, Span::call_site());
    let info_name = format_ident!("{}_INFO", spec.name.to_uppercase());
    let order = spec.order();
    let (args, inputs) = (spec.arg_names(), spec.input_names());
    let (muls, adds, recips, statements) =
        (counts.muls, counts.adds, counts.recips, counts.statements);
    let (subkernels, zero_subsets, splits) =
        (stats.subkernels, stats.zero_momentum_subsets, stats.splits);
    quote! {
        #[doc = concat!("How `", stringify!(#name), "` was generated.")]
        pub const #info_name: #info = #info {
            name: stringify!(#name),
            order: #order,
            arguments: &[#(#args),*],
            inputs: &[#(#inputs),*],
            statements: #statements,
            multiplications: #muls,
            additions: #adds,
            reciprocals: #recips,
            subkernels: #subkernels,
            zero_momentum_subsets: #zero_subsets,
            splits: #splits,
            generator: #GENERATOR_VERSION,
        };
    }
}

//! The macro's input language.
//!
//! ```text
//! scalar = crate::Scalar;            // trait the emitted code is generic over
//! info = crate::KernelInfo;          // metadata struct the emitted constants use
//! /// docs …
//! general_3 = free(3);                            // F_3^s(q1, q2, q3) of free vectors
//! propagator_5 = propagator(2);                   // F_5^s(k, q1, −q1, q2, −q2)
//! redshift_3 = redshift(3);                       // Z_3(q1, q2, q3; f, los) as [Z^(0), …, Z^(3)] in f
//! mode_coupling_3 = basis(k, q1, q2) args(q1, q2, k - q1 - q2);
//! propagator_7_paired = propagator(3) paired;     // in lane pairs (needs `pair = <trait>;` after `info`)
//! ```
//! Arguments are integer combinations of the basis names: `k - q1`, `-q2`, `2*q1 + q2`.

use crate::emit::Paths;
use crate::spec::Spec;
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{parenthesized, BinOp, Expr, Ident, LitInt, Token, UnOp};

/// One kernel to generate, with the doc comments written above it.
pub struct KernelItem {
    /// Doc attributes.
    pub docs: Vec<syn::Attribute>,
    /// The configuration.
    pub spec: Spec,
    /// Evaluate in lane pairs under the configuration's cheapest symmetry (`… paired;`).
    pub paired: bool,
}

/// The whole macro input.
pub struct Input {
    /// Paths of the scalar trait and the info struct.
    pub paths: Paths,
    /// The kernels.
    pub items: Vec<KernelItem>,
}

fn keyed_path(input: ParseStream, key: &str) -> syn::Result<syn::Path> {
    let k: Ident = input.parse()?;
    if k != key {
        return Err(syn::Error::new(
            k.span(),
            format!("expected `{key} = <path>;`"),
        ));
    }
    input.parse::<Token![=]>()?;
    let p: syn::Path = input.parse()?;
    input.parse::<Token![;]>()?;
    Ok(p)
}

impl Parse for Input {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let scalar = keyed_path(input, "scalar")?;
        let info = keyed_path(input, "info")?;
        let pair = if input.fork().parse::<Ident>().is_ok_and(|k| k == "pair") {
            Some(keyed_path(input, "pair")?)
        } else {
            None
        };
        let mut items = Vec::new();
        while !input.is_empty() {
            items.push(input.parse()?);
        }
        Ok(Input {
            paths: Paths { scalar, info, pair },
            items,
        })
    }
}

impl Parse for KernelItem {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let docs = input.call(syn::Attribute::parse_outer)?;
        let name: Ident = input.parse()?;
        input.parse::<Token![=]>()?;
        let kind: Ident = input.parse()?;
        let fname = name.to_string();
        let err = |e: crate::spec::SpecError| syn::Error::new(name.span(), e.to_string());
        let spec = match kind.to_string().as_str() {
            "free" => Spec::free(&fname, parenthesized_int(input)?).map_err(err)?,
            "propagator" => Spec::propagator(&fname, parenthesized_int(input)?).map_err(err)?,
            "redshift" => Spec::redshift(&fname, parenthesized_int(input)?).map_err(err)?,
            "basis" => {
                let content;
                parenthesized!(content in input);
                let basis: Vec<String> = Punctuated::<Ident, Token![,]>::parse_terminated(&content)?
                    .iter()
                    .map(|i| i.to_string())
                    .collect();
                let args_kw: Ident = input.parse()?;
                if args_kw != "args" {
                    return Err(syn::Error::new(args_kw.span(), "expected `args(...)` after `basis(...)`"));
                }
                let content;
                parenthesized!(content in input);
                let exprs = Punctuated::<Expr, Token![,]>::parse_terminated(&content)?;
                let args = exprs.iter().map(|e| combination(e, &basis)).collect::<syn::Result<Vec<_>>>()?;
                Spec::new(&fname, basis, args).map_err(err)?
            }
            other => {
                return Err(syn::Error::new(
                    kind.span(),
                    format!("unknown configuration `{other}`: expected free(n), propagator(x), redshift(n) or basis(..) args(..)"),
                ))
            }
        };
        let paired = input.peek(Ident);
        if paired {
            let kw: Ident = input.parse()?;
            if kw != "paired" {
                return Err(syn::Error::new(kw.span(), "expected `paired` or `;`"));
            }
        }
        input.parse::<Token![;]>()?;
        Ok(KernelItem { docs, spec, paired })
    }
}

fn parenthesized_int(input: ParseStream) -> syn::Result<usize> {
    let content;
    parenthesized!(content in input);
    content.parse::<LitInt>()?.base10_parse()
}

/// Evaluates `k - q1 - 2*q2` to integer coefficients over the basis.
pub fn combination(e: &Expr, basis: &[String]) -> syn::Result<Vec<i64>> {
    let unsupported =
        || syn::Error::new_spanned(e, "expected an integer combination of basis vectors");
    match e {
        Expr::Path(p) => {
            let id = p.path.get_ident().ok_or_else(unsupported)?;
            let i = basis.iter().position(|b| id == b).ok_or_else(|| {
                syn::Error::new(id.span(), format!("`{id}` is not a basis vector"))
            })?;
            let mut c = vec![0; basis.len()];
            c[i] = 1;
            Ok(c)
        }
        Expr::Paren(p) => combination(&p.expr, basis),
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => Ok(combination(&u.expr, basis)?
            .into_iter()
            .map(|c| -c)
            .collect()),
        Expr::Binary(b) => match b.op {
            BinOp::Add(_) | BinOp::Sub(_) => {
                let sign = if matches!(b.op, BinOp::Sub(_)) { -1 } else { 1 };
                let (l, r) = (combination(&b.left, basis)?, combination(&b.right, basis)?);
                Ok(l.iter().zip(&r).map(|(x, y)| x + sign * y).collect())
            }
            BinOp::Mul(_) => {
                let Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(n),
                    ..
                }) = &*b.left
                else {
                    return Err(unsupported());
                };
                let n: i64 = n.base10_parse()?;
                Ok(combination(&b.right, basis)?
                    .into_iter()
                    .map(|c| n * c)
                    .collect())
            }
            _ => Err(unsupported()),
        },
        _ => Err(unsupported()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_all_three_kinds_of_configuration() {
        let input: Input = syn::parse_str(
            "scalar = crate::Scalar; info = crate::KernelInfo;
             /// doc
             a = free(3);
             b = propagator(2);
             c = basis(k, q1, q2) args(q1, q2, k - q1 - q2);
             d = basis(k, q) args(2*q - k, -(k - q));
             e = propagator(3) paired;
             z = redshift(2);",
        )
        .unwrap();
        assert_eq!(input.items.len(), 6);
        assert_eq!(input.items[5].spec.line_of_sight(), Some(2));
        assert!(input.items[4].paired && !input.items[3].paired);
        assert!(input.paths.pair.is_none());
        assert_eq!(input.items[0].docs.len(), 1);
        assert_eq!(
            input.items[1].spec.arg_names(),
            ["k", "q1", "-q1", "q2", "-q2"]
        );
        assert_eq!(
            input.items[2].spec.args,
            vec![vec![0, 1, 0], vec![0, 0, 1], vec![1, -1, -1]]
        );
        assert_eq!(input.items[3].spec.args, vec![vec![-1, 2], vec![-1, 1]]);
    }

    #[test]
    fn refuses_bad_input_with_a_message() {
        let bad = |s: &str| {
            syn::parse_str::<Input>(&format!("scalar = S; info = I; {s}"))
                .err()
                .expect("must fail")
                .to_string()
        };
        assert!(bad("a = free(8);").contains("outside 1..=7"));
        assert!(bad("a = basis(k) args(p);").contains("not a basis vector"));
        assert!(bad("a = basis(k, q) args(k - k);").contains("identically zero"));
        assert!(bad("a = spiral(3);").contains("unknown configuration"));
    }
}

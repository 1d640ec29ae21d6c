//! What a generated kernel takes: its basis vectors and its arguments as integer combinations of them.
//!
//! A kernel F_n^s(a_1, …, a_n) is generated for a fixed *configuration*: each argument a_i is an integer
//! combination of a few basis vectors (k, q1, q2, …). The generated function takes the Gram matrix of the
//! basis (all dot products e_a·e_b, a ≤ b) and nothing else, so every subset sum and every dot product is a
//! linear form in its inputs that the engine knows exactly at generation time, including which ones vanish.

use std::fmt;

/// A kernel configuration: basis names and arguments as integer coefficient vectors over the basis.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Spec {
    /// Name of the generated function.
    pub name: String,
    /// Names of the basis vectors, e.g. `["k", "q1", "q2"]`.
    pub basis: Vec<String>,
    /// The kernel's arguments; `args[i][b]` is the coefficient of basis vector `b` in argument `i`.
    pub args: Vec<Vec<i64>>,
    /// What is generated: F^s, G^s, or the redshift-space Z_n with the last basis vector as the line of
    /// sight.
    pub kind: Kind,
}

/// What a configuration generates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `[F^s, G^s]` of the arguments.
    Spt,
    /// `[Z^(0), …, Z^(n)]`, the coefficients of f^m in the redshift-space kernel Z_n of the arguments
    /// (see [`crate::redshift`]); the last basis vector is the line of sight, on which no argument depends.
    Redshift,
}

/// Largest kernel order the engine generates.
pub const MAX_ORDER: usize = 7;

/// Why a configuration cannot be generated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SpecError {
    /// No arguments, or more than [`MAX_ORDER`].
    Order(usize),
    /// An argument is the zero vector (the kernel has a 1/q_i² pole there).
    ZeroArgument(usize),
    /// An argument's coefficient vector does not match the basis.
    BasisMismatch(usize),
}

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpecError::Order(n) => write!(f, "kernel order {n} is outside 1..={MAX_ORDER}"),
            SpecError::ZeroArgument(i) => write!(f, "argument {} is identically zero", i + 1),
            SpecError::BasisMismatch(i) => {
                write!(
                    f,
                    "argument {} does not have one coefficient per basis vector",
                    i + 1
                )
            }
        }
    }
}

impl std::error::Error for SpecError {}

impl Spec {
    /// A configuration from explicit parts, validated.
    pub fn new(name: &str, basis: Vec<String>, args: Vec<Vec<i64>>) -> Result<Self, SpecError> {
        if args.is_empty() || args.len() > MAX_ORDER {
            return Err(SpecError::Order(args.len()));
        }
        for (i, a) in args.iter().enumerate() {
            if a.len() != basis.len() {
                return Err(SpecError::BasisMismatch(i));
            }
            if a.iter().all(|&c| c == 0) {
                return Err(SpecError::ZeroArgument(i));
            }
        }
        Ok(Spec {
            name: name.to_owned(),
            basis,
            args,
            kind: Kind::Spt,
        })
    }

    /// The redshift-space kernel Z_n(q1, …, qn) of n free vectors, with the line of sight `los` as an
    /// extra basis vector (its dot products with the q_i and with itself are inputs).
    pub fn redshift(name: &str, n: usize) -> Result<Self, SpecError> {
        let mut basis: Vec<String> = (1..=n).map(|i| format!("q{i}")).collect();
        basis.push("los".to_owned());
        let args = (0..n).map(|i| unit(n + 1, i)).collect();
        let mut spec = Spec::new(name, basis, args)?;
        spec.kind = Kind::Redshift;
        Ok(spec)
    }

    /// Index of the line of sight among the basis vectors, for [`Kind::Redshift`].
    pub fn line_of_sight(&self) -> Option<usize> {
        (self.kind == Kind::Redshift).then(|| self.basis.len() - 1)
    }

    /// Number of outputs: 2 (F, G), or n + 1 coefficients of Z_n.
    pub fn n_outputs(&self) -> usize {
        match self.kind {
            Kind::Spt => 2,
            Kind::Redshift => self.order() + 1,
        }
    }

    /// The general kernel F_n^s(q1, …, qn) of n free vectors.
    pub fn free(name: &str, n: usize) -> Result<Self, SpecError> {
        let basis = (1..=n).map(|i| format!("q{i}")).collect();
        let args = (0..n).map(|i| unit(n, i)).collect();
        Spec::new(name, basis, args)
    }

    /// The propagator kernel F_{2x+1}^s(k, q1, −q1, …, qx, −qx) (P13, P15, P17 for x = 1, 2, 3).
    pub fn propagator(name: &str, x: usize) -> Result<Self, SpecError> {
        let nb = x + 1;
        let mut basis = vec!["k".to_owned()];
        basis.extend((1..=x).map(|i| format!("q{i}")));
        let mut args = vec![unit(nb, 0)];
        for i in 1..=x {
            args.push(unit(nb, i));
            args.push(unit(nb, i).iter().map(|c| -c).collect());
        }
        Spec::new(name, basis, args)
    }

    /// Kernel order n (number of arguments).
    pub fn order(&self) -> usize {
        self.args.len()
    }

    /// Number of inputs: the upper triangle of the basis Gram matrix.
    pub fn n_inputs(&self) -> usize {
        let nb = self.basis.len();
        nb * (nb + 1) / 2
    }

    /// Index of the Gram entry e_a·e_b among the inputs (row-major upper triangle).
    pub fn gram_index(&self, a: usize, b: usize) -> usize {
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        let nb = self.basis.len();
        // Row a of the upper triangle starts after rows 0..a, which hold nb, nb − 1, … entries.
        a * nb - a * a.saturating_sub(1) / 2 + (b - a)
    }

    /// Names of the inputs in order, e.g. `["k.k", "k.q1", "q1.q1"]`.
    pub fn input_names(&self) -> Vec<String> {
        let nb = self.basis.len();
        let mut names = Vec::with_capacity(self.n_inputs());
        for a in 0..nb {
            for b in a..nb {
                names.push(format!("{}.{}", self.basis[a], self.basis[b]));
            }
        }
        names
    }

    /// Human-readable arguments, e.g. `["k", "q1", "-q1"]`.
    pub fn arg_names(&self) -> Vec<String> {
        self.args
            .iter()
            .map(|a| combination_name(&self.basis, a))
            .collect()
    }
}

fn unit(n: usize, i: usize) -> Vec<i64> {
    let mut v = vec![0; n];
    v[i] = 1;
    v
}

/// `k - q1 - q2` style name of an integer combination of basis vectors.
pub fn combination_name(basis: &[String], coeffs: &[i64]) -> String {
    let mut s = String::new();
    for (name, &c) in basis.iter().zip(coeffs) {
        if c == 0 {
            continue;
        }
        let sign = if c < 0 {
            "-"
        } else if s.is_empty() {
            ""
        } else {
            "+"
        };
        let mag = c.unsigned_abs();
        let sep = if s.is_empty() { "" } else { " " };
        let sign_sep = if s.is_empty() || sign.is_empty() {
            ""
        } else {
            " "
        };
        if mag == 1 {
            s.push_str(&format!("{sep}{sign}{sign_sep}{name}"));
        } else {
            s.push_str(&format!("{sep}{sign}{sign_sep}{mag}{name}"));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gram_indices_enumerate_the_upper_triangle_in_order() {
        let spec = Spec::propagator("p", 3).unwrap();
        let nb = spec.basis.len();
        let mut expected = 0;
        for a in 0..nb {
            for b in a..nb {
                assert_eq!(spec.gram_index(a, b), expected);
                assert_eq!(spec.gram_index(b, a), expected);
                expected += 1;
            }
        }
        assert_eq!(expected, spec.n_inputs());
    }

    #[test]
    fn propagator_arguments_pair_up() {
        let spec = Spec::propagator("p15", 2).unwrap();
        assert_eq!(spec.arg_names(), ["k", "q1", "-q1", "q2", "-q2"]);
        assert_eq!(
            spec.input_names(),
            ["k.k", "k.q1", "k.q2", "q1.q1", "q1.q2", "q2.q2"]
        );
    }

    #[test]
    fn redshift_configurations_carry_the_line_of_sight_last() {
        let spec = Spec::redshift("z2", 2).unwrap();
        assert_eq!(spec.arg_names(), ["q1", "q2"]);
        assert_eq!(
            spec.input_names(),
            ["q1.q1", "q1.q2", "q1.los", "q2.q2", "q2.los", "los.los"]
        );
        assert_eq!((spec.line_of_sight(), spec.n_outputs()), (Some(2), 3));
        assert_eq!(Spec::free("f", 2).unwrap().line_of_sight(), None);
    }

    #[test]
    fn bad_configurations_are_refused() {
        assert_eq!(Spec::free("f", 0), Err(SpecError::Order(0)));
        assert_eq!(Spec::free("f", 8), Err(SpecError::Order(8)));
        let basis = vec!["k".to_owned()];
        assert_eq!(
            Spec::new("z", basis, vec![vec![0]]),
            Err(SpecError::ZeroArgument(0))
        );
    }

    #[test]
    fn combination_names_read_like_algebra() {
        let basis: Vec<String> = ["k", "q1", "q2"].iter().map(|s| s.to_string()).collect();
        assert_eq!(combination_name(&basis, &[1, -1, -1]), "k - q1 - q2");
        assert_eq!(combination_name(&basis, &[0, -1, 0]), "-q1");
        assert_eq!(combination_name(&basis, &[0, 2, 1]), "2q1 + q2");
    }
}

//! The second-order kernels of the galaxy model in redshift space and their azimuthal averages:
//! the P22-type columns of [`super`] (module docs there).

use super::super::p22::f2_g2;

/// Exponents of a monomial b1^a b2^b bs^c b3^d f^e.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Monomial {
    /// Power of b1.
    pub b1: u8,
    /// Power of b2.
    pub b2: u8,
    /// Power of bs.
    pub bs: u8,
    /// Power of b3.
    pub b3: u8,
    /// Power of f.
    pub f: u8,
}

impl Monomial {
    pub(super) const fn new(b1: u8, b2: u8, bs: u8, b3: u8, f: u8) -> Self {
        Self { b1, b2, bs, b3, f }
    }

    /// The product of two monomials.
    pub const fn times(self, o: Self) -> Self {
        Self::new(
            self.b1 + o.b1,
            self.b2 + o.b2,
            self.bs + o.bs,
            self.b3 + o.b3,
            self.f + o.f,
        )
    }

    /// Its value at (b1, b2, bs, b3, f).
    pub fn eval(self, [b1, b2, bs, b3, f]: [f64; 5]) -> f64 {
        b1.powi(self.b1.into())
            * b2.powi(self.b2.into())
            * bs.powi(self.bs.into())
            * b3.powi(self.b3.into())
            * f.powi(self.f.into())
    }

    /// ∂/∂f of [`Self::eval`] (exact: the power of f lowered by one, times it).
    pub fn eval_df(self, [b1, b2, bs, b3, f]: [f64; 5]) -> f64 {
        if self.f == 0 {
            return 0.0;
        }
        f64::from(self.f)
            * b1.powi(self.b1.into())
            * b2.powi(self.b2.into())
            * bs.powi(self.bs.into())
            * b3.powi(self.b3.into())
            * f.powi(i32::from(self.f) - 1)
    }

    /// A readable name, e.g. `b1^2 f`.
    pub fn name(self) -> String {
        let mut parts = Vec::new();
        for (s, e) in [
            ("b1", self.b1),
            ("b2", self.b2),
            ("bs", self.bs),
            ("b3", self.b3),
            ("f", self.f),
        ] {
            match e {
                0 => {}
                1 => parts.push(s.to_string()),
                _ => parts.push(format!("{s}^{e}")),
            }
        }
        if parts.is_empty() {
            "1".into()
        } else {
            parts.join(" ")
        }
    }
}

/// The coefficients of the six second-order kernels K₁ … K₆ in Z₂ (module docs).
pub(super) const KERNEL_COEFFICIENTS: [Monomial; 6] = [
    Monomial::new(1, 0, 0, 0, 0),
    Monomial::new(1, 0, 0, 0, 1),
    Monomial::new(0, 0, 0, 0, 1),
    Monomial::new(0, 0, 0, 0, 2),
    Monomial::new(0, 1, 0, 0, 0),
    Monomial::new(0, 0, 1, 0, 0),
];

/// The nonzero P22-type columns: (a, b, n) for 2∫K_aK_bPP' at μ^{2n}, a ≤ b (0-based kernels).
pub const PAIR_COLUMNS: [(usize, usize, usize); 31] = [
    (0, 0, 0),
    (0, 1, 1),
    (0, 2, 1),
    (0, 3, 1),
    (0, 3, 2),
    (0, 4, 0),
    (0, 5, 0),
    (1, 1, 1),
    (1, 1, 2),
    (1, 2, 2),
    (1, 3, 1),
    (1, 3, 2),
    (1, 3, 3),
    (1, 4, 1),
    (1, 5, 1),
    (2, 2, 2),
    (2, 3, 2),
    (2, 3, 3),
    (2, 4, 1),
    (2, 5, 1),
    (3, 3, 1),
    (3, 3, 2),
    (3, 3, 3),
    (3, 3, 4),
    (3, 4, 1),
    (3, 4, 2),
    (3, 5, 1),
    (3, 5, 2),
    (4, 4, 0),
    (4, 5, 0),
    (5, 5, 0),
];
pub(crate) const NPAIR: usize = PAIR_COLUMNS.len();

/// The line-of-sight P13-type kernels (module docs) per unit of 6Z₁P(k)∫d³q/(2π)³P: the b1fμ², f²μ²
/// and f²μ⁴ parts.
pub(super) const NLOS: usize = 3;

/// A polynomial Σ c_i μ^i of degree ≤ 8.
pub(super) type Poly = [f64; 9];

/// ⟨u^j⟩_φ for j ≤ 4 as polynomials in μ (module docs), x = k̂·q̂.
pub(super) fn azimuthal_moments(x: f64) -> [Poly; 5] {
    let (x2, y2) = (x * x, 1.0 - x * x);
    let mut m = [[0.0; 9]; 5];
    m[0][0] = 1.0;
    m[1][1] = x;
    m[2][0] = 0.5 * y2;
    m[2][2] = x2 - 0.5 * y2;
    m[3][1] = 1.5 * x * y2;
    m[3][3] = x2 * x - 1.5 * x * y2;
    m[4][0] = 0.375 * y2 * y2;
    m[4][2] = 3.0 * x2 * y2 - 0.75 * y2 * y2;
    m[4][4] = x2 * x2 - 3.0 * x2 * y2 + 0.375 * y2 * y2;
    m
}

/// The kernels K₁ … K₆ of (q, p = k − q) as lists of (coefficient, power of μ, power of u).
pub(super) fn kernels(k: f64, q: f64, p: f64) -> [Vec<(f64, usize, usize)>; 6] {
    let [f2, g2] = f2_g2(k * k, q * q, p * p);
    let c = 0.5 * (k * k - q * q - p * p);
    let s2 = c * c / (q * q * p * p) - 1.0 / 3.0;
    let p2 = p * p;
    [
        vec![(f2, 0, 0)],
        vec![
            (0.5 * k * (1.0 / q - q / p2), 1, 1),
            (0.5 * k * k / p2, 2, 0),
        ],
        vec![(g2, 2, 0)],
        vec![
            (0.5 * k * k * k / (q * p2), 3, 1),
            (-0.5 * k * k / p2, 2, 2),
        ],
        vec![(0.5, 0, 0)],
        vec![(s2, 0, 0)],
    ]
}

/// ⟨K_aK_b⟩_φ as a polynomial in μ for every pair a ≤ b: `out[a][b]`.
pub(super) fn pair_polynomials(k: f64, q: f64, p: f64) -> [[Poly; 6]; 6] {
    let x = ((k * k + q * q - p * p) / (2.0 * k * q)).clamp(-1.0, 1.0);
    let moments = azimuthal_moments(x);
    let ks = kernels(k, q, p);
    let mut out = [[[0.0; 9]; 6]; 6];
    for a in 0..6 {
        for b in a..6 {
            for &(ca, ia, ja) in &ks[a] {
                for &(cb, ib, jb) in &ks[b] {
                    let (c, i, m) = (ca * cb, ia + ib, &moments[ja + jb]);
                    for (d, mv) in m.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                        out[a][b][i + d] += c * mv;
                    }
                }
            }
        }
    }
    out
}

/// The P22-type column values 2∫… per unit measure/(4π²)·(half counted twice) at one node.
pub(super) fn pair_columns(k: f64, q: f64, p: f64) -> [f64; NPAIR] {
    let polys = pair_polynomials(k, q, p);
    std::array::from_fn(|c| {
        let (a, b, n) = PAIR_COLUMNS[c];
        polys[a][b][2 * n]
    })
}

//! Forward-mode automatic differentiation: dual numbers a + Σ_j d_j ε_j with ε_i ε_j = 0, carrying
//! the exact derivatives of a computed value with respect to `N` inputs alongside it.
//!
//! Code written once over [`Real`] runs on `f64` (the value alone, at the same cost as before) and on
//! [`Dual<N>`] (value and gradient: each operation applies its derivative rule, so the gradient is
//! the exact derivative of the computed number, quadrature and ODE steps included; no finite
//! differences). The cosmology's background and growth ([`crate::cosmology`]) and the emulator's
//! spectra ([`crate::emulator`]) are written so; the pipeline's cosmological Jacobian
//! ([`crate::pipeline`]) composes them.
//!
//! ```
//! use pt_spectra::dual::{Dual, Real};
//! // d/dx [x² e^x] at x = 1 is 3e.
//! let x = Dual::<1>::seed(1.0, 0);
//! let y = x * x * x.exp();
//! assert!((y.d[0] - 3.0 * std::f64::consts::E).abs() < 1e-15);
//! ```

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real number type the derivative-carrying code is generic over: `f64` or [`Dual`].
pub trait Real:
    Copy
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// A constant (no derivative).
    fn cst(v: f64) -> Self;
    /// The value.
    fn value(self) -> f64;
    /// e^x.
    fn exp(self) -> Self;
    /// ln x.
    fn ln(self) -> Self;
    /// √x.
    fn sqrt(self) -> Self;
    /// x^p for a constant p.
    fn powf(self, p: f64) -> Self;
    /// x^n.
    fn powi(self, n: i32) -> Self;
    /// 1/x.
    fn recip(self) -> Self;
    /// sin x.
    fn sin(self) -> Self;
    /// sinh x.
    fn sinh(self) -> Self;
    /// True when the number carries no derivative (always for `f64`; all derivatives zero for
    /// [`Dual`]): code may then take a shortcut that holds at this value only, such as ρ_DE = 1 for
    /// w0 = −1, wa = 0, without losing a derivative.
    fn is_constant(&self) -> bool;
}

impl Real for f64 {
    fn cst(v: f64) -> Self {
        v
    }
    fn value(self) -> f64 {
        self
    }
    fn exp(self) -> Self {
        f64::exp(self)
    }
    fn ln(self) -> Self {
        f64::ln(self)
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn powf(self, p: f64) -> Self {
        f64::powf(self, p)
    }
    fn powi(self, n: i32) -> Self {
        f64::powi(self, n)
    }
    fn recip(self) -> Self {
        1.0 / self
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn sinh(self) -> Self {
        f64::sinh(self)
    }
    fn is_constant(&self) -> bool {
        true
    }
}

/// A value and its derivatives with respect to `N` inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<const N: usize> {
    /// The value.
    pub v: f64,
    /// The derivatives ∂v/∂x_j.
    pub d: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// The input `j` (of `N`) at `value`: derivative 1 with respect to itself, 0 to the others.
    pub fn seed(value: f64, j: usize) -> Self {
        let mut d = [0.0; N];
        d[j] = 1.0;
        Self { v: value, d }
    }

    /// A value with the given derivatives.
    pub fn new(v: f64, d: [f64; N]) -> Self {
        Self { v, d }
    }

    /// The chain rule of a function with value `v` and derivative `dv` at `self`.
    fn chain(self, v: f64, dv: f64) -> Self {
        Self {
            v,
            d: self.d.map(|d| d * dv),
        }
    }
}

impl<const N: usize> Real for Dual<N> {
    fn cst(v: f64) -> Self {
        Self { v, d: [0.0; N] }
    }
    fn value(self) -> f64 {
        self.v
    }
    fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e)
    }
    fn ln(self) -> Self {
        self.chain(self.v.ln(), 1.0 / self.v)
    }
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s)
    }
    fn powf(self, p: f64) -> Self {
        let y = self.v.powf(p);
        self.chain(y, p * self.v.powf(p - 1.0))
    }
    fn powi(self, n: i32) -> Self {
        let y = self.v.powi(n);
        let dy = if n == 0 {
            0.0
        } else {
            f64::from(n) * self.v.powi(n - 1)
        };
        self.chain(y, dy)
    }
    fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r)
    }
    fn sin(self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }
    fn sinh(self) -> Self {
        self.chain(self.v.sinh(), self.v.cosh())
    }
    fn is_constant(&self) -> bool {
        self.d.iter().all(|&d| d == 0.0)
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            d: std::array::from_fn(|j| self.d[j] + o.d[j]),
        }
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            d: std::array::from_fn(|j| self.d[j] - o.d[j]),
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)] // the product and quotient rules
impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            d: std::array::from_fn(|j| self.d[j] * o.v + self.v * o.d[j]),
        }
    }
}

#[allow(clippy::suspicious_arithmetic_impl)] // the product and quotient rules
impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let r = 1.0 / o.v;
        let v = self.v * r;
        Self {
            v,
            d: std::array::from_fn(|j| (self.d[j] - v * o.d[j]) * r),
        }
    }
}

impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            d: self.d.map(|d| -d),
        }
    }
}

impl<const N: usize> Add<f64> for Dual<N> {
    type Output = Self;
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v + o,
            d: self.d,
        }
    }
}

impl<const N: usize> Sub<f64> for Dual<N> {
    type Output = Self;
    fn sub(self, o: f64) -> Self {
        Self {
            v: self.v - o,
            d: self.d,
        }
    }
}

impl<const N: usize> Mul<f64> for Dual<N> {
    type Output = Self;
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v * o,
            d: self.d.map(|d| d * o),
        }
    }
}

impl<const N: usize> Div<f64> for Dual<N> {
    type Output = Self;
    fn div(self, o: f64) -> Self {
        self * (1.0 / o)
    }
}

impl<const N: usize> AddAssign for Dual<N> {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<const N: usize> SubAssign for Dual<N> {
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

impl<const N: usize> MulAssign for Dual<N> {
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

/// A [`Real`] seen as [`LANES`](Self::LANES) plain numbers: its value and its derivatives.
///
/// A map that is linear with constant coefficients acts on each lane alone (the map of the value is
/// the value of the map, the map of a derivative its derivative), so such a map (stored vectors
/// weighted by computed coefficients, an interpolation through computed node values) runs lane by
/// lane in plain `f64` code: vectorised, and on `f64` exactly the code without derivatives.
///
/// ```
/// use pt_spectra::dual::{Dual, Lanes};
/// let x = Dual::<2>::new(3.0, [1.0, -2.0]);
/// assert_eq!((0..Dual::<2>::LANES).map(|l| x.lane(l)).collect::<Vec<_>>(), [3.0, 1.0, -2.0]);
/// let doubled = Dual::<2>::from_lanes(|l| 2.0 * x.lane(l));
/// assert_eq!(doubled, x * 2.0);
/// ```
pub trait Lanes: Real {
    /// The number of lanes: 1 for `f64`, 1 + N for [`Dual<N>`].
    const LANES: usize;
    /// Lane `l`: the value for `l` = 0, the derivative `l` − 1 after it.
    fn lane(&self, l: usize) -> f64;
    /// The number whose lane `l` is `f(l)`, for `l` in 0..[`LANES`](Self::LANES) in order.
    fn from_lanes(f: impl FnMut(usize) -> f64) -> Self;
}

impl Lanes for f64 {
    const LANES: usize = 1;
    fn lane(&self, _: usize) -> f64 {
        *self
    }
    fn from_lanes(mut f: impl FnMut(usize) -> f64) -> Self {
        f(0)
    }
}

impl<const N: usize> Lanes for Dual<N> {
    const LANES: usize = 1 + N;
    fn lane(&self, l: usize) -> f64 {
        if l == 0 {
            self.v
        } else {
            self.d[l - 1]
        }
    }
    fn from_lanes(mut f: impl FnMut(usize) -> f64) -> Self {
        let v = f(0);
        Self {
            v,
            d: std::array::from_fn(|j| f(j + 1)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Dual, Real};

    type D2 = Dual<2>;

    /// Each rule against its closed-form derivative, on a function of two inputs.
    #[test]
    fn rules_match_closed_form_derivatives() {
        let (a, b) = (0.7, 1.9);
        let x = D2::seed(a, 0);
        let y = D2::seed(b, 1);
        // f = x y / (x + y) + sqrt(x) ln(y) − exp(−x y) + x^2.5 − y^-3 + 1/x
        let f = x * y / (x + y) + x.sqrt() * y.ln() - (-(x * y)).exp() + x.powf(2.5) - y.powi(-3)
            + x.recip();
        let s = a + b;
        let dfdx =
            b * b / (s * s) + 0.5 / a.sqrt() * b.ln() + b * (-a * b).exp() + 2.5 * a.powf(1.5)
                - 1.0 / (a * a);
        let dfdy = a * a / (s * s) + a.sqrt() / b + a * (-a * b).exp() + 3.0 * b.powi(-4);
        assert!((f.d[0] - dfdx).abs() < 1e-14, "{} {dfdx}", f.d[0]);
        assert!((f.d[1] - dfdy).abs() < 1e-14, "{} {dfdy}", f.d[1]);
        let value =
            a * b / s + a.sqrt() * b.ln() - (-a * b).exp() + a.powf(2.5) - b.powi(-3) + 1.0 / a;
        assert!((f.value() - value).abs() < 1e-15);
    }

    /// sin and sinh against their closed-form derivatives, through the chain rule of a product.
    #[test]
    fn trigonometric_and_hyperbolic_rules() {
        let (a, b) = (0.7, -1.3);
        let x = D2::seed(a, 0);
        let y = D2::seed(b, 1);
        // f = sin(x y) + sinh(x − 2y)
        let f = (x * y).sin() + (x - y * 2.0).sinh();
        let dfdx = b * (a * b).cos() + (a - 2.0 * b).cosh();
        let dfdy = a * (a * b).cos() - 2.0 * (a - 2.0 * b).cosh();
        assert!((f.d[0] - dfdx).abs() < 1e-14, "{} {dfdx}", f.d[0]);
        assert!((f.d[1] - dfdy).abs() < 1e-14, "{} {dfdy}", f.d[1]);
        assert_eq!(f.value(), (a * b).sin() + (a - 2.0 * b).sinh());
        assert_eq!(Real::sin(a), a.sin());
        assert_eq!(Real::sinh(a), a.sinh());
    }

    /// A constant has no derivative; a seeded input and anything computed from it have one.
    #[test]
    fn constants_are_recognised() {
        assert!(1.5_f64.is_constant());
        assert!(D2::cst(-1.0).is_constant());
        let x = D2::seed(-1.0, 1);
        assert!(!x.is_constant());
        assert!(!(x * 3.0).exp().is_constant());
        assert!((x - x).is_constant());
        assert!((D2::cst(2.0) * D2::cst(3.0)).is_constant());
    }

    /// The f64 implementation is the plain arithmetic.
    #[test]
    fn f64_is_the_value() {
        fn g<T: Real>(x: T) -> T {
            (x * x + 1.0).ln() * x.exp() / 3.0
        }
        let x = 0.3_f64;
        assert_eq!(g(x), (x * x + 1.0).ln() * x.exp() / 3.0);
        assert_eq!(g(Dual::<1>::seed(x, 0)).value(), g(x));
    }
}

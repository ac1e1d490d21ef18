//! Dual numbers `a + b ε` (`ε² = 0`): [`runtime::scalar::Real`] with one derivative carried
//! along, so that the runtime's evaluators, written over `Real`, differentiate themselves in
//! forward mode. The reference route of the derivative tests: exact to rounding, with no
//! step to choose and nothing shared with the generator's symbolic differentiation.

use core::ops::{Add, Div, Mul, Neg, Sub};

use runtime::scalar::{Real, Singular, Site};

/// `v + d ε`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    /// The value.
    pub v: f64,
    /// The derivative.
    pub d: f64,
}

impl Dual {
    /// `v + d ε`.
    pub fn new(v: f64, d: f64) -> Dual {
        Dual { v, d }
    }
}

/// `x + ε dx`, element by element.
pub fn seeded(x: &[f64], dx: &[f64]) -> Vec<Dual> {
    x.iter().zip(dx).map(|(&v, &d)| Dual::new(v, d)).collect()
}

/// The values and the derivatives of `y`.
pub fn split(y: &[Dual]) -> (Vec<f64>, Vec<f64>) {
    (
        y.iter().map(|a| a.v).collect(),
        y.iter().map(|a| a.d).collect(),
    )
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual::new(self.v + o.v, self.d + o.d)
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual::new(self.v - o.v, self.d - o.d)
    }
}

impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual::new(self.v * o.v, self.d * o.v + self.v * o.d)
    }
}

impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        let q = self.v / o.v;
        Dual::new(q, (self.d - q * o.d) / o.v)
    }
}

impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        Dual::new(-self.v, -self.d)
    }
}

impl Real for Dual {
    fn c(v: f64) -> Dual {
        Dual::new(v, 0.0)
    }
    fn sqrt(self) -> Dual {
        let r = self.v.sqrt();
        // The derivative of √a at a = 0 is taken as 0 when a's derivative is 0.
        let d = if self.d == 0.0 {
            0.0
        } else {
            self.d / (2.0 * r)
        };
        Dual::new(r, d)
    }
    fn atan2(self, x: Dual) -> Dual {
        let r = x.v * x.v + self.v * self.v;
        Dual::new(self.v.atan2(x.v), (x.v * self.d - self.v * x.d) / r)
    }
    fn sin_cos(self) -> (Dual, Dual) {
        let (s, c) = self.v.sin_cos();
        (Dual::new(s, c * self.d), Dual::new(c, -s * self.d))
    }
    fn select_abs_gt(a: Dual, b: Dual, x: Dual, y: Dual) -> Dual {
        if a.v.abs() > b.v.abs() { x } else { y }
    }
    fn check(
        value: Dual,
        threshold: Dual,
        scale: Dual,
        site: Site,
        two_sided: bool,
    ) -> Result<Dual, Singular> {
        f64::check(value.v, threshold.v, scale.v, site, two_sided)?;
        Ok(value)
    }
}

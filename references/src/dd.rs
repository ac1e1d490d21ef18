//! A double-double scalar (`hi + lo`, about 32 significant decimal digits) implementing
//! [`runtime::scalar::Real`], so that the parallel-manipulator evaluator
//! (`runtime::parallel::noc`, written once over `Real`) can be run in extended precision and
//! serve as the reference for the `f64` routes near singularities.
//!
//! Arithmetic follows the QD library (Hida, Li & Bailey, "Algorithms for quad-double precision
//! floating point arithmetic", ARITH-15, 2001): error-free transformations `two_sum` (Knuth) and
//! `two_prod` (with `f64::mul_add` for the rounding error of the product), accurate ("IEEE")
//! addition, multiplication and long division. Relative errors per operation are a few units
//! of `2⁻¹⁰⁶ ≈ 1.2e-32`:
//!
//! | operation | method | accuracy (measured in the unit tests) |
//! |---|---|---|
//! | `+ − × ÷` | QD accurate algorithms | ≤ ~4·2⁻¹⁰⁶ relative |
//! | `sqrt` | one Newton step on the `f64` square root | ≤ ~2·2⁻¹⁰⁶ relative |
//! | `sin`, `cos` (|t| ≤ π) | reduction by π/2 (π in double-double), Taylor series | ≤ 1e-31 absolute |
//! | `atan2` | `f64` atan2, then one Newton step with double-double sin/cos | ≤ 1e-31 absolute (rad); measured ≤ 1.3e-32 |
//!
//! Non-finite values: an operation whose leading part is not finite returns `lo = 0` and the
//! IEEE result in `hi` (so `inf` stays `inf` and NaN stays NaN instead of turning every
//! later value into NaN through `inf − inf` in the error terms).

use core::cmp::Ordering;
use core::ops::{Add, Div, Mul, Neg, Sub};

use runtime::parallel::Plan;
use runtime::parallel::noc;
use runtime::scalar::{Real, Singular, Site};

/// A double-double number `hi + lo` with `|lo| ≤ ulp(hi)/2` (normalized).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DD {
    /// Leading part (the value rounded to `f64`).
    pub hi: f64,
    /// Trailing part.
    pub lo: f64,
}

/// `a + b = s + e` exactly (Knuth's two-sum).
#[inline]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// `a + b = s + e` exactly, assuming `|a| ≥ |b|` (or `a = 0`).
#[inline]
pub fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let e = b - (s - a);
    (s, e)
}

/// `a · b = p + e` exactly (the rounding error of the product by a fused multiply-add).
#[inline]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let e = f64::mul_add(a, b, -p);
    (p, e)
}

impl DD {
    /// Zero.
    pub const ZERO: DD = DD { hi: 0.0, lo: 0.0 };
    /// One.
    pub const ONE: DD = DD { hi: 1.0, lo: 0.0 };
    /// π to double-double precision.
    pub const PI: DD = DD {
        hi: core::f64::consts::PI,
        lo: 1.224_646_799_147_353_2e-16,
    };
    /// π/2 to double-double precision.
    pub const FRAC_PI_2: DD = DD {
        hi: core::f64::consts::FRAC_PI_2,
        lo: 6.123_233_995_736_766e-17,
    };
    /// π/4 to double-double precision.
    pub const FRAC_PI_4: DD = DD {
        hi: core::f64::consts::FRAC_PI_4,
        lo: 3.061_616_997_868_383e-17,
    };

    /// The normalized sum `hi + lo` (non-finite `hi`: `lo = 0`).
    #[inline]
    fn norm(hi: f64, lo: f64) -> DD {
        let (s, e) = quick_two_sum(hi, lo);
        if s.is_finite() {
            DD { hi: s, lo: e }
        } else {
            DD { hi: s, lo: 0.0 }
        }
    }

    /// The nearest `f64` (`hi + lo` rounded).
    #[inline]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// `|self|`.
    #[inline]
    pub fn abs(self) -> DD {
        if self.hi < 0.0 || (self.hi == 0.0 && self.lo < 0.0) {
            -self
        } else {
            self
        }
    }

    /// `true` when both parts are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// `true` when the value is NaN.
    #[inline]
    pub fn is_nan(self) -> bool {
        self.hi.is_nan() || self.lo.is_nan()
    }

    /// `self · b` for an `f64` `b` (exact when `b` is a power of two).
    #[inline]
    pub fn mul_f64(self, b: f64) -> DD {
        let (p, e) = two_prod(self.hi, b);
        let e = e + self.lo * b;
        DD::norm(p, e)
    }

    /// The square root: one Newton step `s + (a − s²)/(2s)` from the `f64` root `s`.
    pub fn sqrt(self) -> DD {
        if self.hi == 0.0 {
            return DD::ZERO;
        }
        if self.hi.is_nan() || self.hi < 0.0 || !self.hi.is_finite() {
            return DD {
                hi: self.hi.sqrt(),
                lo: 0.0,
            };
        }
        let s = self.hi.sqrt();
        let sd = DD::from(s);
        let r = self - sd * sd; // exact up to DD rounding: s² is formed by two_prod
        DD::norm(s, r.hi / (2.0 * s))
    }

    /// `(sin t, cos t)` in double-double. Reduction by the nearest multiple of π/2 (π in
    /// double-double), then Taylor series on `|r| ≤ π/4` until the terms fall below 1e-34.
    /// Accurate to about 1e-31 absolute for `|t| ≤ 2π`; large arguments lose
    /// `|t|·1e-32` (no Payne–Hanek reduction).
    pub fn sin_cos(self) -> (DD, DD) {
        if !self.is_finite() {
            return (DD::from(f64::NAN), DD::from(f64::NAN));
        }
        let k = (self.hi / DD::FRAC_PI_2.hi).round();
        let r = self - DD::FRAC_PI_2.mul_f64(k);
        let r2 = r * r;
        // sin r = r − r³/3! + …, cos r = 1 − r²/2! + …
        let mut s = r;
        let mut c = DD::ONE;
        let mut ts = r; // r^(2n+1)/(2n+1)!
        let mut tc = DD::ONE; // r^(2n)/(2n)!
        for n in 1..40 {
            let a = (2 * n) as f64;
            tc = -(tc * r2) / DD::from(a * (a - 1.0));
            ts = -(ts * r2) / DD::from(a * (a + 1.0));
            c = c + tc;
            s = s + ts;
            if tc.hi.abs() < 1e-34 && ts.hi.abs() < 1e-34 {
                break;
            }
        }
        match (k as i64).rem_euclid(4) {
            0 => (s, c),
            1 => (c, -s),
            2 => (-s, -c),
            _ => (-c, s),
        }
    }

    /// The four-quadrant angle of `(x, self)`: the `f64` `atan2` as the first guess `z`, then
    /// one Newton step on `sin z = y/r` (or `cos z = x/r`, whichever is better conditioned)
    /// with double-double sine and cosine (as QD does). The first guess is within ~1e-16 rad,
    /// so one quadratic step reaches the ~1e-31 rad of the double-double sine and cosine.
    pub fn atan2(self, x: DD) -> DD {
        let y = self;
        if y.is_nan() || x.is_nan() {
            return DD::from(f64::NAN);
        }
        if !y.is_finite() || !x.is_finite() {
            return DD::from(y.hi.atan2(x.hi));
        }
        if x.hi == 0.0 && y.hi == 0.0 {
            return DD::from(y.hi.atan2(x.hi));
        }
        let r = (x * x + y * y).sqrt();
        let (xx, yy) = (x / r, y / r);
        let mut z = DD::from(y.to_f64().atan2(x.to_f64()));
        let (s, c) = z.sin_cos();
        if xx.hi.abs() > yy.hi.abs() {
            // sin z = yy: z ← z + (yy − sin z)/cos z
            z = z + (yy - s) / c;
        } else {
            // cos z = xx: z ← z − (xx − cos z)/sin z
            z = z - (xx - c) / s;
        }
        z
    }
}

impl From<f64> for DD {
    #[inline]
    fn from(v: f64) -> DD {
        DD { hi: v, lo: 0.0 }
    }
}

impl PartialOrd for DD {
    fn partial_cmp(&self, other: &DD) -> Option<Ordering> {
        match self.hi.partial_cmp(&other.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&other.lo),
            o => Some(o),
        }
    }
}

impl Neg for DD {
    type Output = DD;
    #[inline]
    fn neg(self) -> DD {
        DD {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Add for DD {
    type Output = DD;
    /// QD's accurate ("IEEE") addition.
    #[inline]
    fn add(self, b: DD) -> DD {
        let (s1, s2) = two_sum(self.hi, b.hi);
        if !s1.is_finite() {
            return DD { hi: s1, lo: 0.0 };
        }
        let (t1, t2) = two_sum(self.lo, b.lo);
        let s2 = s2 + t1;
        let (s1, s2) = quick_two_sum(s1, s2);
        let s2 = s2 + t2;
        DD::norm(s1, s2)
    }
}

impl Sub for DD {
    type Output = DD;
    #[inline]
    fn sub(self, b: DD) -> DD {
        self + (-b)
    }
}

impl Mul for DD {
    type Output = DD;
    #[inline]
    fn mul(self, b: DD) -> DD {
        let (p1, p2) = two_prod(self.hi, b.hi);
        if !p1.is_finite() {
            return DD { hi: p1, lo: 0.0 };
        }
        let p2 = p2 + (self.hi * b.lo + self.lo * b.hi);
        DD::norm(p1, p2)
    }
}

impl Div for DD {
    type Output = DD;
    /// QD's accurate division: three `f64` quotient digits.
    #[inline]
    fn div(self, b: DD) -> DD {
        let q1 = self.hi / b.hi;
        if !q1.is_finite() || !b.hi.is_finite() {
            return DD { hi: q1, lo: 0.0 };
        }
        let r = self - b.mul_f64(q1);
        let q2 = r.hi / b.hi;
        let r = r - b.mul_f64(q2);
        let q3 = r.hi / b.hi;
        let (q1, q2) = quick_two_sum(q1, q2);
        DD { hi: q1, lo: q2 } + DD::from(q3)
    }
}

impl Real for DD {
    #[inline]
    fn c(v: f64) -> Self {
        DD::from(v)
    }
    #[inline]
    fn sqrt(self) -> Self {
        DD::sqrt(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        DD::atan2(self, x)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        DD::sin_cos(self)
    }
    #[inline]
    fn select_abs_gt(a: DD, b: DD, x: DD, y: DD) -> DD {
        if a.abs() > b.abs() { x } else { y }
    }
    /// As for `f64`, with the comparison made on the double-double value; the value and the
    /// condition estimate of the `Singular` record are rounded to `f64`.
    fn check(
        value: DD,
        threshold: DD,
        scale: DD,
        site: Site,
        two_sided: bool,
    ) -> Result<DD, Singular> {
        let ok = if two_sided {
            value > threshold || value < -threshold
        } else {
            value > threshold
        };
        if ok {
            Ok(value)
        } else {
            let a = value.abs();
            Err(Singular {
                site,
                value: value.to_f64(),
                condition_estimate: if a > DD::ZERO {
                    (scale / a).to_f64()
                } else {
                    f64::INFINITY
                },
            })
        }
    }
}

/// Solve `a x = b` (`transpose`: `aᵀ x = b`) by Gaussian elimination with partial pivoting in
/// double-double. No tolerance: an exactly zero pivot gives non-finite entries (see
/// [`solve_pivots`] for the pivots).
pub fn solve(a: &[Vec<DD>], b: &[DD], transpose: bool) -> Vec<DD> {
    solve_pivots(a, b, transpose).0
}

/// [`solve`], also returning the absolute values of the pivots in elimination order.
pub fn solve_pivots(a: &[Vec<DD>], b: &[DD], transpose: bool) -> (Vec<DD>, Vec<DD>) {
    let n = b.len();
    let mut m: Vec<Vec<DD>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if transpose { a[j][i] } else { a[i][j] })
                .collect()
        })
        .collect();
    let mut x = b.to_vec();
    let mut pivots = Vec::with_capacity(n);
    for k in 0..n {
        let mut p = k;
        let mut best = m[k][k].abs();
        for (i, row) in m.iter().enumerate().skip(k + 1) {
            let v = row[k].abs();
            if v > best {
                best = v;
                p = i;
            }
        }
        m.swap(k, p);
        x.swap(k, p);
        pivots.push(best);
        let inv = DD::ONE / m[k][k];
        for i in k + 1..n {
            let f = m[i][k] * inv;
            if f != DD::ZERO {
                for j in k..n {
                    let t = f * m[k][j];
                    m[i][j] = m[i][j] - t;
                }
                let t = f * x[k];
                x[i] = x[i] - t;
            }
        }
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for j in i + 1..n {
            s = s - m[i][j] * x[j];
        }
        x[i] = s / m[i][i];
    }
    (x, pivots)
}

/// Condition data of the actuation matrix, computed in double-double on `A` with each column
/// scaled to unit 2-norm (the textbook scaling, not the runtime's unit-group references of
/// `noc::ColumnUnits`: a reference of the matrix, not of the runtime's estimate).
#[derive(Clone, Copy, Debug)]
pub struct Conditioning {
    /// Largest over smallest pivot of the partially pivoted LU (the kind of estimate
    /// `noc::lu_solve` reports, here on unit columns and without rounding error).
    pub pivot_ratio: f64,
    /// The 1-norm condition number `‖M‖₁ ‖M⁻¹‖₁` of the scaled matrix `M`.
    pub kappa1: f64,
}

/// [`Conditioning`] of `A` with its columns scaled to unit norm.
pub fn conditioning(a: &[Vec<DD>]) -> Conditioning {
    let n = a.len();
    // mᵢⱼ = a_ij, columns scaled.
    let mut m: Vec<Vec<DD>> = a.to_vec();
    for j in 0..n {
        let mut s = DD::ZERO;
        for row in m.iter() {
            s = s + row[j] * row[j];
        }
        let s = s.sqrt();
        if s > DD::ZERO {
            for row in m.iter_mut() {
                row[j] = row[j] / s;
            }
        }
    }
    let (_, piv) = solve_pivots(&m, &vec![DD::ZERO; n], false);
    let pmax = piv.iter().map(|p| p.to_f64()).fold(0.0, f64::max);
    let pmin = piv.iter().map(|p| p.to_f64()).fold(f64::INFINITY, f64::min);
    let norm1 = |mat: &[Vec<DD>]| -> f64 {
        (0..n)
            .map(|j| mat.iter().map(|row| row[j].abs().to_f64()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let mut inv = vec![vec![DD::ZERO; n]; n];
    for j in 0..n {
        let mut e = vec![DD::ZERO; n];
        e[j] = DD::ONE;
        let c = solve(&m, &e, false);
        for i in 0..n {
            inv[i][j] = c[i];
        }
    }
    let kappa1 = norm1(&m) * norm1(&inv);
    Conditioning {
        pivot_ratio: if pmin > 0.0 {
            pmax / pmin
        } else {
            f64::INFINITY
        },
        kappa1: if kappa1.is_finite() {
            kappa1
        } else {
            f64::INFINITY
        },
    }
}

fn lift(v: &[f64]) -> Vec<DD> {
    v.iter().map(|&x| DD::from(x)).collect()
}

/// The actuation matrix `A` (`q̇ = A u`) at `x`, evaluated in double-double.
pub fn actuation_dd(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<DD>>, Singular> {
    let (pl, legs) = noc::kinematics::<DD>(plan, &lift(x))?;
    Ok(noc::actuation_matrix(plan, &pl, &legs))
}

/// The high-precision reference of `noc::inverse_dynamics`: the same equations
/// (`noc::kinematics`, `noc::generalized_force` with gravity, `noc::actuation_matrix`) evaluated
/// in double-double, then `Aᵀ τ = f` solved in double-double, rounded to `f64`.
///
/// The leg and reach checks are the runtime's (thresholds compared in double-double). The
/// actuation solve has no tolerance: only an exactly singular `A` (a zero pivot, or a
/// non-finite result) is reported, as `Site::Actuation(k)` with an infinite condition estimate.
pub fn inverse_dynamics_dd(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    let (pl, legs) = noc::kinematics::<DD>(plan, &lift(x))?;
    let f = noc::generalized_force(plan, &pl, &legs, &lift(u), &lift(ud), true);
    let a = noc::actuation_matrix(plan, &pl, &legs);
    let (tau, piv) = solve_pivots(&a, &f, true);
    if let Some(k) = piv
        .iter()
        .position(|p| p.hi.is_nan() || p.hi <= 0.0 || !p.is_finite())
    {
        return Err(Singular {
            site: Site::Actuation(k),
            value: piv[k].to_f64(),
            condition_estimate: f64::INFINITY,
        });
    }
    let out: Vec<f64> = tau.iter().map(|t| t.to_f64()).collect();
    if let Some(k) = out.iter().position(|t| !t.is_finite()) {
        return Err(Singular {
            site: Site::Actuation(k),
            value: out[k],
            condition_estimate: f64::INFINITY,
        });
    }
    Ok(out)
}

/// Double-double reference of a closed loop's (or, with `closed::noc::Plan::tree`, a tree's)
/// generalized forces: the generic evaluator `runtime::closed::noc` run in double-double, the
/// loop closure not checked (the inputs are `f64` states).
pub fn closed_inverse_dynamics_dd(
    plan: &runtime::closed::noc::Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    use runtime::closed::noc as cnoc;
    let c = cnoc::configuration::<DD>(plan, &lift(x), false)?;
    let f = cnoc::generalized_force(plan, &c, &lift(u), &lift(ud), true);
    Ok(f.iter().map(|t| t.to_f64()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `|a − b|` in double-double, rounded.
    fn diff(a: DD, b: DD) -> f64 {
        (a - b).abs().to_f64()
    }

    #[test]
    fn error_free_transformations() {
        let (s, e) = two_sum(1.0, 2f64.powi(-60));
        assert_eq!((s, e), (1.0, 2f64.powi(-60)));
        let a = 1.0 + 2f64.powi(-30);
        let (p, e) = two_prod(a, a);
        // (1 + 2⁻³⁰)² = 1 + 2⁻²⁹ + 2⁻⁶⁰
        assert_eq!(p, 1.0 + 2f64.powi(-29));
        assert_eq!(e, 2f64.powi(-60));
    }

    #[test]
    fn tiny_increment_survives() {
        let one = DD::ONE;
        let eps = DD::from(2f64.powi(-60));
        let d = (one + eps) - one;
        assert_eq!(d, eps, "(1 + 2⁻⁶⁰) − 1 must be exact");
        // In f64 it is lost.
        assert_eq!((1.0 + 2f64.powi(-60)) - 1.0, 0.0);
        // Mixed signs and magnitudes: (2⁶⁰ + 1 − 2⁶⁰) = 1.
        let big = DD::from(2f64.powi(60));
        assert_eq!((big + one) - big, one);
        // Subtraction of nearly equal numbers keeps the low part.
        let a = DD::from(1.0) + DD::from(3.0 * 2f64.powi(-80));
        let b = DD::from(1.0) + DD::from(2f64.powi(-80));
        assert_eq!(a - b, DD::from(2f64.powi(-79)));
    }

    #[test]
    fn mul_div_roundtrip() {
        let third = DD::ONE / DD::from(3.0);
        let back = third * DD::from(3.0);
        assert!(diff(back, DD::ONE) < 1e-31, "{:?}", back);
        // 1/3 in double-double: hi = 0.333…, lo = 1.850371707708594e-17.
        assert_eq!(third.hi, 1.0 / 3.0);
        assert!((third.lo - 1.850_371_707_708_594e-17).abs() < 1e-32);
        let a = DD::from(7.0) / DD::from(11.0);
        let b = DD::from(13.0) / DD::from(17.0);
        let q = a / b; // = 119/143
        let exact = DD::from(119.0) / DD::from(143.0);
        assert!(diff(q, exact) < 4e-32, "{:e}", diff(q, exact));
        assert!(diff(q * b, a) < 4e-32);
    }

    #[test]
    fn square_roots() {
        let two = DD::from(2.0);
        let r = two.sqrt();
        let e = (r * r - two).abs().to_f64();
        assert!(e < 5e-32, "sqrt(2)² − 2 = {e:e}");
        // In f64 the same residual is 4.4e-16.
        assert!((2f64.sqrt() * 2f64.sqrt() - 2.0).abs() > 1e-16);
        // √2 = 1.41421356237309504880168872420969807856967…
        assert_eq!(r.hi, std::f64::consts::SQRT_2);
        assert!((r.lo - (-9.667_293_313_452_913e-17)).abs() < 1e-31);
        for v in [1e-200, 3.0, 1e10 + 1.0, 12_345.678_9] {
            let d = DD::from(v) + DD::from(v * 1e-20);
            let s = d.sqrt();
            let rel = ((s * s - d) / d).abs().to_f64();
            assert!(rel < 1e-31, "{v}: {rel:e}");
        }
        assert_eq!(DD::ZERO.sqrt(), DD::ZERO);
        assert!(DD::from(-1.0).sqrt().is_nan());
        assert_eq!(DD::from(f64::INFINITY).sqrt().hi, f64::INFINITY);
    }

    #[test]
    fn sine_and_cosine() {
        let (s, c) = DD::FRAC_PI_4.sin_cos();
        let h = DD::from(0.5).sqrt();
        assert!(diff(s, h) < 1e-31 && diff(c, h) < 1e-31);
        let (s, c) = (DD::PI / DD::from(6.0)).sin_cos();
        assert!(diff(s, DD::from(0.5)) < 1e-31);
        assert!(diff(c, DD::from(3.0).sqrt() / DD::from(2.0)) < 1e-31);
        let (s, c) = DD::PI.sin_cos();
        assert!(s.abs().to_f64() < 1e-31 && diff(c, -DD::ONE) < 1e-31);
        for t in [-3.0, -1.0, 0.1, 1e-5, 2.5, 6.0] {
            let (s, c) = DD::from(t).sin_cos();
            assert!(diff(s * s + c * c, DD::ONE) < 1e-31, "{t}");
            assert!((s.to_f64() - t.sin()).abs() < 1e-15);
            assert!((c.to_f64() - t.cos()).abs() < 1e-15);
        }
    }

    /// atan2 against known angles: worst error ≤ 1e-31 rad.
    #[test]
    fn atan2_known_values() {
        let three = DD::from(3.0);
        let cases = [
            (DD::ONE, DD::ONE, DD::FRAC_PI_4),
            (DD::ONE, three.sqrt(), DD::PI / DD::from(6.0)),
            (three.sqrt(), DD::ONE, DD::PI / three),
            (DD::ONE, -DD::ONE, DD::FRAC_PI_4 * three),
            (-DD::ONE, -DD::ONE, -(DD::FRAC_PI_4 * three)),
            (DD::ZERO, -DD::ONE, DD::PI),
            (DD::ONE, DD::ZERO, DD::FRAC_PI_2),
            (-DD::from(2.0), DD::ZERO, -DD::FRAC_PI_2),
            (DD::from(1e-20), DD::ONE, DD::from(1e-20)),
        ];
        let mut worst: f64 = 0.0;
        for (y, x, want) in cases {
            let got = y.atan2(x);
            let e = diff(got, want);
            worst = worst.max(e);
            assert!(
                e < 1e-31,
                "atan2({y:?}, {x:?}) = {got:?}, want {want:?} (error {e:e})"
            );
        }
        // Round trip: atan2(r sin t, r cos t) = t.
        for t in [-3.0, -2.0, -0.7, 0.3, 1.2, 1.57, 3.1] {
            let (s, c) = DD::from(t).sin_cos();
            let r = DD::from(2.5);
            let got = (r * s).atan2(r * c);
            let e = diff(got, DD::from(t));
            worst = worst.max(e);
            assert!(e < 1e-31, "{t}: {e:e}");
        }
        println!("atan2: worst error {worst:e} rad");
    }

    /// A Hilbert-like system against its exact rational answer: the 8 × 8 Hilbert matrix
    /// `H_ij = 1/(i + j + 1)` (κ∞ ≈ 3.4e10) times `x = 1` gives `b`; double-double Gaussian
    /// elimination recovers `x` to ~κ·1e-32, `f64` only to ~κ·1e-16.
    #[test]
    fn hilbert_solve() {
        let n = 8;
        let h: Vec<Vec<DD>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| DD::ONE / DD::from((i + j + 1) as f64))
                    .collect()
            })
            .collect();
        // b_i = Σ_j 1/(i+j+1) computed exactly as a rational then rounded to DD: the sum of
        // DD reciprocals is accurate to ~1e-32, well below what is tested.
        let b: Vec<DD> = h
            .iter()
            .map(|row| row.iter().fold(DD::ZERO, |s, v| s + *v))
            .collect();
        for transpose in [false, true] {
            let x = solve(&h, &b, transpose);
            let e = x.iter().map(|v| diff(*v, DD::ONE)).fold(0.0, f64::max);
            assert!(e < 1e-20, "transpose {transpose}: error {e:e}");
        }
        // A non-symmetric variant with an exact integer answer: a_ij = 1/(i + 2j + 1),
        // x_j = j − 3.
        let a: Vec<Vec<DD>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| DD::ONE / DD::from((i + 2 * j + 1) as f64))
                    .collect()
            })
            .collect();
        let want: Vec<DD> = (0..n).map(|j| DD::from(j as f64 - 3.0)).collect();
        let b: Vec<DD> = a
            .iter()
            .map(|row| {
                row.iter()
                    .zip(&want)
                    .fold(DD::ZERO, |s, (aij, xj)| s + *aij * *xj)
            })
            .collect();
        let x = solve(&a, &b, false);
        let e = x
            .iter()
            .zip(&want)
            .map(|(g, w)| diff(*g, *w))
            .fold(0.0, f64::max);
        assert!(e < 1e-18, "error {e:e}");
        // Aᵀ y = c with y = want.
        let c: Vec<DD> = (0..n)
            .map(|j| (0..n).fold(DD::ZERO, |s, i| s + a[i][j] * want[i]))
            .collect();
        let y = solve(&a, &c, true);
        let e = y
            .iter()
            .zip(&want)
            .map(|(g, w)| diff(*g, *w))
            .fold(0.0, f64::max);
        assert!(e < 1e-18, "transpose error {e:e}");
        // The exact inverse of the 10 × 10 Hilbert matrix (κ∞ ≈ 3.5e13) has integer entries:
        // (H⁻¹)ᵢⱼ = (−1)^(i+j) (i+j−1) C(n+i−1, n−j) C(n+j−1, n−i) C(i+j−2, i−1)² (1-based).
        // Solving H x = e_k must return column k of it; the only perturbation is the rounding
        // of the entries 1/(i+j−1) to double-double (~1e-32), amplified by κ.
        let n = 10;
        let h: Vec<Vec<DD>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| DD::ONE / DD::from((i + j + 1) as f64))
                    .collect()
            })
            .collect();
        let binom = |a: i128, b: i128| -> i128 {
            if b < 0 || b > a {
                return 0;
            }
            (0..b).fold(1i128, |acc, k| acc * (a - k) / (k + 1))
        };
        let exact_inv = |i: i128, j: i128| -> i128 {
            let nn = n as i128;
            let s = if (i + j) % 2 == 0 { 1 } else { -1 };
            s * (i + j - 1)
                * binom(nn + i - 1, nn - j)
                * binom(nn + j - 1, nn - i)
                * binom(i + j - 2, i - 1).pow(2)
        };
        let mut worst: f64 = 0.0;
        for k in 0..n {
            let mut e = vec![DD::ZERO; n];
            e[k] = DD::ONE;
            for transpose in [false, true] {
                let x = solve(&h, &e, transpose);
                for i in 0..n {
                    let want = exact_inv(i as i128 + 1, k as i128 + 1);
                    assert!(want.unsigned_abs() < 1 << 53);
                    let rel = diff(x[i], DD::from(want as f64)) / (want as f64).abs();
                    worst = worst.max(rel);
                }
            }
        }
        assert!(
            worst < 1e-16,
            "Hilbert-10 inverse: worst relative error {worst:e}"
        );
        println!("Hilbert-10 inverse in double-double: worst relative error {worst:e}");
    }

    #[test]
    fn check_compares_in_double_double() {
        // 1 + 2⁻⁸⁰ > 1 only in double-double.
        let v = DD::ONE + DD::from(2f64.powi(-80));
        assert!(DD::check(v, DD::ONE, DD::ONE, Site::Platform, false).is_ok());
        let e = DD::check(DD::ONE, v, DD::ONE, Site::Leg(2), false).unwrap_err();
        assert_eq!(e.site, Site::Leg(2));
        assert_eq!(e.value, 1.0);
        assert_eq!(e.condition_estimate, 1.0);
        let e = DD::check(DD::ZERO, DD::ZERO, DD::ONE, Site::Reach(1), true).unwrap_err();
        assert_eq!(e.condition_estimate, f64::INFINITY);
        assert!(DD::check(-DD::from(2.0), DD::ONE, DD::ONE, Site::Platform, true).is_ok());
        assert!(DD::check(DD::from(f64::NAN), DD::ZERO, DD::ONE, Site::Platform, true).is_err());
    }

    #[test]
    fn non_finite_values_stay_put() {
        let inf = DD::from(f64::INFINITY);
        assert_eq!((inf + DD::ONE).hi, f64::INFINITY);
        assert_eq!((inf * DD::from(2.0)).hi, f64::INFINITY);
        assert!((inf - inf).is_nan());
        assert_eq!((DD::ONE / inf).hi, 0.0);
        assert_eq!((DD::ONE / DD::ZERO).hi, f64::INFINITY);
        assert!((DD::from(f64::NAN) + DD::ONE).is_nan());
    }
}

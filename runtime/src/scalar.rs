//! The scalar every evaluator is written over, and the failure it reports.
//!
//! [`Real`] is implemented for `f64` (the runtime evaluates with it) and, in the generator, for a
//! symbolic scalar that records a node of the expression DAG per operation. The same source
//! therefore gives the numeric runtime and, through constant folding and hash-consing, the
//! generated code. [`Real::check`] is the one operation with control flow: a test that makes
//! the evaluation return [`Singular`] (in generated code: an early `return Err(..)`).

use core::fmt;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// Where an evaluation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Site {
    /// Pivot `i` of the generalized inertia's `LDLᵀ` factorization (forward dynamics).
    MassMatrix(usize),
    /// Leg `k`'s Jacobian `J_J` is singular (a leg, serial or type-I, singularity).
    Leg(usize),
    /// Leg `k` cannot reach the platform: the pose is outside the workspace.
    Reach(usize),
    /// Pivot `i` of the actuation matrix `A` (`q̇ = A u`): a parallel (type-II) singularity.
    Actuation(usize),
    /// The platform quaternion is zero or not finite.
    Platform,
    /// An input (`x`, `u`, `u̇`, `τ` or `q`) is NaN or infinite, or so large that a result
    /// overflows.
    Input,
    /// Closed loops in joint coordinates: loop-closure equation `k` is violated by more than
    /// its tolerance (the joint positions `x` do not close the loops).
    Closure(usize),
    /// The coordinates stop determining the mechanism. Closed loops in joint coordinates:
    /// pivot `i` of the constraint Jacobian's dependent block `Φ_d` (a change of mobility or a
    /// bifurcation). Translational and Schönflies platforms: pivot `i` of the legs' constraint
    /// couples (they no longer hold the platform's orientation, which gains a rotation).
    Constraint(usize),
    /// Spring `k` has (nearly) zero length: the direction of its force is undefined.
    Spring(usize),
}

impl Site {
    /// A compact code (for generated code and the DAG): `MassMatrix(i)` = i, `Leg(k)` = 256 + k,
    /// `Reach(k)` = 512 + k, `Actuation(i)` = 768 + i, `Platform` = 1024, `Input` = 1025,
    /// `Closure(k)` = 1280 + k, `Constraint(i)` = 1536 + i, `Spring(k)` = 1792 + k.
    pub fn code(self) -> u16 {
        match self {
            Site::MassMatrix(i) => i as u16,
            Site::Leg(k) => 256 + k as u16,
            Site::Reach(k) => 512 + k as u16,
            Site::Actuation(i) => 768 + i as u16,
            Site::Platform => 1024,
            Site::Input => 1025,
            Site::Closure(k) => 1280 + k as u16,
            Site::Constraint(i) => 1536 + i as u16,
            Site::Spring(k) => 1792 + k as u16,
        }
    }

    /// The inverse of [`Site::code`].
    pub fn from_code(c: u16) -> Site {
        match c {
            0..256 => Site::MassMatrix(c as usize),
            256..512 => Site::Leg(c as usize - 256),
            512..768 => Site::Reach(c as usize - 512),
            768..1024 => Site::Actuation(c as usize - 768),
            1024 => Site::Platform,
            1280..1536 => Site::Closure(c as usize - 1280),
            1536..1792 => Site::Constraint(c as usize - 1536),
            1792..2048 => Site::Spring(c as usize - 1792),
            _ => Site::Input,
        }
    }
}

impl fmt::Display for Site {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Site::MassMatrix(i) => write!(f, "pivot {i} of the generalized inertia"),
            Site::Leg(k) => write!(f, "the Jacobian of leg {k} (leg singularity)"),
            Site::Reach(k) => write!(
                f,
                "leg {k} cannot reach the platform (outside the workspace)"
            ),
            Site::Actuation(i) => write!(
                f,
                "pivot {i} of the actuation matrix (parallel singularity)"
            ),
            Site::Platform => write!(f, "the platform quaternion (zero or not finite)"),
            Site::Input => write!(f, "an input that is NaN or infinite"),
            Site::Closure(k) => write!(
                f,
                "loop-closure equation {k} (the joint positions do not close the loops)"
            ),
            Site::Constraint(i) => write!(
                f,
                "pivot {i} of the constraints (the loops' dependent block, or the legs' constraint couples: the coordinates do not determine the mechanism)"
            ),
            Site::Spring(k) => write!(f, "spring {k} (zero length: no direction)"),
        }
    }
}

/// A configuration where the method fails (or a non-finite input).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Singular {
    /// Which matrix, leg or pivot.
    pub site: Site,
    /// The value that failed its test (a determinant, pivot or discriminant).
    pub value: f64,
    /// An estimate of the condition number of the matrix involved (`f64::INFINITY` when the
    /// value is zero or not finite). See the thresholds in [`crate::parallel::noc`] and
    /// [`crate::closed::noc`].
    pub condition_estimate: f64,
}

impl fmt::Display for Singular {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "singular configuration at {} (value {:e}, condition estimate {:e})",
            self.site, self.value, self.condition_estimate
        )
    }
}

/// The single-precision counterpart of an `f64` threshold `t`: the same fraction of the
/// significant digits, `t^(23/52)` (the ratio of the mantissa widths), so a test that leaves
/// `f64` results `k` digits short of full precision leaves `f32` ones short by the same
/// proportion. E.g. `1e-4 → 1.7e-2`, `1e-8 → 2.9e-4`, `1e-9 → 1.0e-4`, `1e-12 → 4.9e-6`.
pub fn f32_tolerance(t: f64) -> f64 {
    if t > 0.0 && t < 1.0 {
        libm::pow(t, 23.0 / 52.0)
    } else {
        t
    }
}

/// A scalar: `f64`, or a node of the generator's expression DAG.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The constant `v`.
    fn c(v: f64) -> Self;
    /// `√self`.
    fn sqrt(self) -> Self;
    /// `atan2(self, x)` (four-quadrant angle of the point `(x, self)`).
    fn atan2(self, x: Self) -> Self;
    /// `(sin self, cos self)`.
    fn sin_cos(self) -> (Self, Self);
    /// The threshold to use for a test whose `f64` threshold is `t`: `t` itself, except when
    /// the generator targets `f32` code, where it is [`f32_tolerance`]`(t)`.
    fn tolerance(t: f64) -> f64 {
        t
    }
    /// `x` when `|a| > |b|`, else `y` (NaN compares false): the one data-dependent choice,
    /// for partial pivoting.
    fn select_abs_gt(a: Self, b: Self, x: Self, y: Self) -> Self;
    /// `Ok(value)` when `value > threshold` (or `|value| > threshold` when `two_sided`), else
    /// `Err(Singular { site, value, condition_estimate })` with `scale / value` (`scale / |value|`
    /// when two-sided), infinite when that is not positive. NaN fails.
    fn check(
        value: Self,
        threshold: Self,
        scale: Self,
        site: Site,
        two_sided: bool,
    ) -> Result<Self, Singular>;
}

impl Real for f64 {
    #[inline]
    fn c(v: f64) -> Self {
        v
    }
    #[inline]
    fn sqrt(self) -> Self {
        crate::math::sqrt(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        crate::math::atan2(self, x)
    }
    #[inline]
    fn sin_cos(self) -> (f64, f64) {
        crate::math::sin_cos(self)
    }
    #[inline]
    fn select_abs_gt(a: f64, b: f64, x: f64, y: f64) -> f64 {
        if a.abs() > b.abs() { x } else { y }
    }
    #[inline]
    fn check(
        value: f64,
        threshold: f64,
        scale: f64,
        site: Site,
        two_sided: bool,
    ) -> Result<f64, Singular> {
        let ok = if two_sided {
            value > threshold || value < -threshold
        } else {
            value > threshold
        };
        if ok {
            Ok(value)
        } else {
            // As the generated code reports it: a one-sided test's non-positive value has no
            // finite estimate.
            let a = if two_sided && value < 0.0 {
                -value
            } else {
                value
            };
            Err(Singular {
                site,
                value,
                condition_estimate: if a > 0.0 { scale / a } else { f64::INFINITY },
            })
        }
    }
}

//! A firmware-like control loop on nocdyn's generated dynamics: computed-torque control of the
//! PUMA 560 ([`puma`]) and of the Gough–Stewart platform ([`gough_stewart`]) at a fixed
//! 1 kHz step, in single precision, each fed by a simulated plant ([`mod@bench`]).
//!
//! The controllers are `#![no_std]` and use no heap: every quantity is a fixed-size array, every
//! generated function returns its result by value, and a singular configuration is an `Err`,
//! never a panic. They are generic over the scalar ([`Real`]): `f32` runs on
//! `mechanisms::f32::*` (what a microcontroller with a single-precision FPU would run), `f64` on
//! the `f64` modules, for comparison. The part that would run on a microcontroller is
//! `Controller::step`.
//!
//! [`mod@bench`] (feature `bench`, on by default; std and heap) is the test bench: the plant is the
//! *runtime's* generic `f64` evaluation of the same spec (`runtime::noc`,
//! `runtime::parallel::noc`), integrated by RK4 at a finer step with the torque held between
//! control ticks, as a zero-order hold does. Sensor readings are rounded to the controller's
//! scalar, the torques widened back to `f64`.
//!
//! # Why the tracking error is what it is
//!
//! The plant is the controller's model (the same spec, evaluated by another route), so with a
//! continuous-time controller in exact arithmetic the error would obey `ë + kd·ė + kp·e = 0`
//! and stay at zero from a start on the reference. Two sources remain.
//!
//! * The zero-order hold: during a period `h` the torque is the one computed at the tick, while
//!   the ideal torque `τ_d(t)` moves on. The acceleration the plant misses is
//!   `∂FD/∂τ · τ̇_d · (t − t_k)`, a sawtooth whose mean over a period is
//!   `(h/2) · ∂FD/∂τ · τ̇_d`. The reference is slow next to the loop's natural frequency, so
//!   the error follows this forcing quasi-statically: `e ≈ (h / 2) · ∂FD/∂τ · τ̇_d / kp`
//!   ([`bench::puma::predicted_max_error`], [`bench::gough_stewart::predicted_max_error`]).
//! * Rounding (`f32`): the controller's torque differs from the exact one by `δτ` (sensor
//!   readings, reference and arithmetic in `f32`), an acceleration error `d = M⁻¹ δτ`. With an
//!   exact model the computed-torque loop decouples, `ëᵢ + kd·ėᵢ + kp·eᵢ = −dᵢ(t)`, and the
//!   critically damped impulse response `t·e^{−ωt}` is non-negative with integral `1/ω² = 1/kp`,
//!   so `|eᵢ| ≤ sup |dᵢ| / kp` whatever the sequence of rounding errors. The bench measures
//!   `sup ‖M⁻¹ δτ‖∞` along the reference ([`bench::puma::rounding_floor`],
//!   [`bench::gough_stewart::rounding_floor`]); the tests check the simulated `f32`−`f64`
//!   error difference against it. Two approximations: `δτ` is measured on the reference, where
//!   the loop runs within ~1e-5 of it, not on the loop's own states; and the loop is sampled
//!   (`ω·h` = 0.05 at 8 Hz and 1 kHz), not continuous. The bound is a worst case (every rounding
//!   error of one sign), so the measured difference sits well inside it.
//!
//! In `f32` two position-level roundings dominate `δτ`, both multiplied by `kp`: the reference
//! evaluated at an absolute time `t` (its phase `ω·t` loses precision in proportion to `t`, so
//! the PUMA 560's floor grows over a run), and the Gough–Stewart's pose estimate (see
//! [`gough_stewart`]).
#![no_std]

#[cfg(feature = "bench")]
extern crate std;

#[cfg(feature = "bench")]
pub mod bench;
pub mod gough_stewart;
pub mod puma;

use core::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// The controller's scalar: `f32` (firmware) or `f64`.
pub trait Real:
    Copy
    + Default
    + PartialOrd
    + core::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
{
    /// `0`.
    const ZERO: Self;
    /// `1`.
    const ONE: Self;
    /// The nearest value of this type (`as`).
    fn from_f64(x: f64) -> Self;
    /// Exact widening to `f64`.
    fn to_f64(self) -> f64;
    /// `(sin x, cos x)` (`runtime::math`: `libm` without std).
    fn sin_cos(self) -> (Self, Self);
    /// `√x`.
    fn sqrt(self) -> Self;
    /// `|x|`.
    fn abs(self) -> Self;
}

impl Real for f64 {
    const ZERO: f64 = 0.0;
    const ONE: f64 = 1.0;
    fn from_f64(x: f64) -> f64 {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn sin_cos(self) -> (f64, f64) {
        runtime::math::sin_cos(self)
    }
    fn sqrt(self) -> f64 {
        runtime::math::sqrt(self)
    }
    fn abs(self) -> f64 {
        f64::abs(self)
    }
}

impl Real for f32 {
    const ZERO: f32 = 0.0;
    const ONE: f32 = 1.0;
    fn from_f64(x: f64) -> f32 {
        x as f32
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn sin_cos(self) -> (f32, f32) {
        runtime::math::sin_cos_f32(self)
    }
    fn sqrt(self) -> f32 {
        runtime::math::sqrt_f32(self)
    }
    fn abs(self) -> f32 {
        f32::abs(self)
    }
}

/// Every element converted to another scalar (`from_f64` of the exact `f64` value).
pub fn cast<S: Real, T: Real, const N: usize>(v: &[S; N]) -> [T; N] {
    core::array::from_fn(|i| T::from_f64(v[i].to_f64()))
}

/// Proportional and derivative gains of the computed-torque law (the same on every axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains<S> {
    /// `kp` (1/s²).
    pub kp: S,
    /// `kd` (1/s).
    pub kd: S,
}

impl<S: Real> Gains<S> {
    /// Critically damped error dynamics with natural frequency `hz`: `kp = ω²`, `kd = 2ω`.
    pub fn critically_damped(hz: f64) -> Gains<S> {
        let w = 2.0 * core::f64::consts::PI * hz;
        Gains {
            kp: S::from_f64(w * w),
            kd: S::from_f64(2.0 * w),
        }
    }
}

/// Timing of the loop: the control period and the plant's RK4 substeps per period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Control period (s); 1 kHz is `0.001`.
    pub period: f64,
    /// RK4 steps of the plant per control period.
    pub substeps: u32,
}

impl Timing {
    /// 1 kHz control, plant at 10 kHz.
    pub const KHZ: Timing = Timing {
        period: 0.001,
        substeps: 10,
    };
}

/// Running maximum and root mean square of a non-negative error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// The largest value seen.
    pub max: f64,
    sum_sq: f64,
    count: u32,
}

impl Stats {
    /// Add one sample.
    pub fn add(&mut self, e: f64) {
        // A NaN sticks, so a diverging run cannot look good.
        if e > self.max || e.is_nan() {
            self.max = e;
        }
        self.sum_sq += e * e;
        self.count += 1;
    }
    /// Root mean square of the samples (0 with none).
    pub fn rms(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            runtime::math::sqrt(self.sum_sq / self.count as f64)
        }
    }
    /// Number of samples.
    pub fn count(&self) -> u32 {
        self.count
    }
}

/// `a (1 − cos ω t)` and its first two derivatives: a smooth excursion that starts at rest.
pub fn raised_cosine<S: Real>(a: S, w: S, t: S) -> [S; 3] {
    let (s, c) = (w * t).sin_cos();
    [a * (S::ONE - c), a * w * s, a * w * w * c]
}

/// `∞`-norm of a vector.
pub fn norm_inf<S: Real>(v: &[S]) -> S {
    v.iter()
        .fold(S::ZERO, |m, x| if x.abs() > m { x.abs() } else { m })
}

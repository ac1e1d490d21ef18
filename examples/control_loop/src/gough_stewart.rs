//! Task-space computed-torque control of the Gough–Stewart platform
//! (`mechanisms::f32::gough_stewart`, or `mechanisms::gough_stewart` in `f64`):
//! `x = [p; quaternion]`, `u = [ω; v]` (base frame).
//!
//! The controller reads the six leg lengths (encoders) and the platform twist, and estimates the
//! pose by the generated forward kinematics (Newton), warm-started from the previous tick.
//!
//! In `f32` this estimate, not the arithmetic, sets the rounding floor: Newton stops as soon as
//! the leg-length residual is within the rescaled tolerance (`FK_TOLERANCE` rescaled to `f32`,
//! times the longest leg: a few µm here), and returns a warm start that is already that close
//! unchanged. Along the demo
//! reference the `f32` estimate is off by a few µm and µrad (the example prints it), where half
//! an `f32` ulp of the pose is 6e-8 m. (A guess moved on by `h·u` makes it worse: every guess
//! passes the test, and the estimate drifts by dead reckoning up to the tolerance.)

use runtime::Dynamics;

use crate::{Gains, Real, raised_cosine};

/// Degrees of freedom (= actuators).
pub const N: usize = mechanisms::gough_stewart::DOF;
/// Pose coordinates.
pub const NX: usize = mechanisms::gough_stewart::NX;

/// A scalar with a generated Gough–Stewart module: `f32` (`mechanisms::f32::gough_stewart`) or
/// `f64` (`mechanisms::gough_stewart`), reached through the module's implementation of
/// `runtime::Dynamics` (the same methods every generated module has).
pub trait Scalar: Real {
    /// The module in this precision.
    type Module: Dynamics<NX, N, Scalar = Self>;
    /// Its value (a unit struct).
    const MODULE: Self::Module;
}

impl Scalar for f64 {
    type Module = mechanisms::gough_stewart::Module;
    const MODULE: Self::Module = mechanisms::gough_stewart::Module;
}

impl Scalar for f32 {
    type Module = mechanisms::f32::gough_stewart::Module;
    const MODULE: Self::Module = mechanisms::f32::gough_stewart::Module;
}

/// The module's `Singular` (a leg or parallel singularity, an unreachable pose).
pub type Singular<S> = <<S as Scalar>::Module as Dynamics<NX, N>>::Singular;
/// The module's `NoConvergence` (forward kinematics).
pub type NoConvergence<S> = <<S as Scalar>::Module as Dynamics<NX, N>>::NoConvergence;

/// Why a control tick failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fault<S: Scalar> {
    /// A leg or parallel singularity (from the generated inverse dynamics).
    Singular(Singular<S>),
    /// Forward kinematics did not converge from the previous estimate.
    NoConvergence(NoConvergence<S>),
}

/// The home pose of `mechanisms/specs/gough_stewart.toml` (`[platform] home`): 1 m above the
/// base centre's offset `(-1.5, 0)`, level.
pub const HOME: [f64; NX] = [-1.5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0];

/// A pose trajectory: the origin moves by `a_p ⊙ (1 − cos(ω_p t))` from `x0`, and the
/// platform turns by `a_θ (1 − cos(ω_θ t))` about the fixed unit axis `axis` (base frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference<S> {
    /// Start pose (at rest).
    pub x0: [S; NX],
    /// Translation amplitudes (m).
    pub amplitude: [S; 3],
    /// Translation angular frequencies (rad/s).
    pub omega: [S; 3],
    /// Rotation axis (unit, base frame).
    pub axis: [S; 3],
    /// Rotation amplitude (rad).
    pub angle: S,
    /// Rotation angular frequency (rad/s).
    pub angle_omega: S,
}

impl Reference<f64> {
    /// Up to 8 cm and 0.16 rad from home, 0.4–0.7 Hz.
    pub const DEMO: Reference<f64> = {
        const TAU: f64 = 2.0 * core::f64::consts::PI;
        // (1, 2, 3) / √14
        const S: f64 = 0.267_261_241_912_424_4;
        Reference {
            x0: HOME,
            amplitude: [0.04, 0.03, 0.04],
            omega: [TAU * 0.5, TAU * 0.7, TAU * 0.4],
            axis: [S, 2.0 * S, 3.0 * S],
            angle: 0.08,
            angle_omega: TAU * 0.6,
        }
    };
}

impl<S: Real> Reference<S> {
    /// The same trajectory with its parameters rounded to another scalar.
    pub fn cast<T: Real>(&self) -> Reference<T> {
        Reference {
            x0: crate::cast(&self.x0),
            amplitude: crate::cast(&self.amplitude),
            omega: crate::cast(&self.omega),
            axis: crate::cast(&self.axis),
            angle: T::from_f64(self.angle.to_f64()),
            angle_omega: T::from_f64(self.angle_omega.to_f64()),
        }
    }

    /// `(x_d, u_d, u̇_d)` at `t`.
    pub fn at(&self, t: S) -> ([S; NX], [S; N], [S; N]) {
        let (mut x, mut u, mut ud) = (self.x0, [S::ZERO; N], [S::ZERO; N]);
        for i in 0..3 {
            let r = raised_cosine(self.amplitude[i], self.omega[i], t);
            x[i] += r[0];
            u[3 + i] = r[1];
            ud[3 + i] = r[2];
        }
        let th = raised_cosine(self.angle, self.angle_omega, t);
        let half = S::from_f64(0.5);
        let (s, c) = (half * th[0]).sin_cos();
        let turn = [c, s * self.axis[0], s * self.axis[1], s * self.axis[2]];
        let q = quat_mul(&turn, &[self.x0[3], self.x0[4], self.x0[5], self.x0[6]]);
        x[3..7].copy_from_slice(&q);
        for i in 0..3 {
            u[i] = th[1] * self.axis[i];
            ud[i] = th[2] * self.axis[i];
        }
        (x, u, ud)
    }
}

/// Hamilton product `a ⊗ b` of `[w, x, y, z]` quaternions.
pub fn quat_mul<S: Real>(a: &[S; 4], b: &[S; 4]) -> [S; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Pose error `[δθ; δp]` of `x` against `x_d` (base frame): the rotation `q_d ⊗ q*` as
/// `2·vec` (its rotation vector to second order; the short way round), and `p_d − p`.
pub fn pose_error<S: Real>(x_d: &[S; NX], x: &[S; NX]) -> [S; N] {
    let qd = [x_d[3], x_d[4], x_d[5], x_d[6]];
    let qc = [x[3], -x[4], -x[5], -x[6]];
    let d = quat_mul(&qd, &qc);
    let two = S::from_f64(2.0);
    let s = if d[0] < S::ZERO { -two } else { two };
    [
        s * d[1],
        s * d[2],
        s * d[3],
        x_d[0] - x[0],
        x_d[1] - x[1],
        x_d[2] - x[2],
    ]
}

/// The firmware side: gains, reference and the pose estimate carried between ticks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller<S> {
    /// Gains (every axis of `[δθ; δp]`).
    pub gains: Gains<S>,
    /// The trajectory to track.
    pub reference: Reference<S>,
    /// The last pose estimate (the next forward kinematics starts from it).
    pub estimate: [S; NX],
}

impl<S: Scalar> Controller<S> {
    /// A controller whose pose estimate starts at the reference's start.
    pub fn new(gains: Gains<S>, reference: Reference<S>) -> Controller<S> {
        Controller {
            gains,
            reference,
            estimate: reference.x0,
        }
    }

    /// One control tick at time `t` (s) from the leg lengths `q` (m) and the twist `u`
    /// (rad/s, m/s): pose by forward kinematics, then
    /// `τ = ID(x, u, u̇_d + kd (u_d − u) + kp [δθ; δp])` (N; one generated call: the platform's
    /// Newton–Euler equations, the legs' dynamics and the `A⁻ᵀ` mapping to actuator forces).
    pub fn step(&mut self, t: S, q: &[S; N], u: &[S; N]) -> Result<[S; N], Fault<S>> {
        let x = S::MODULE
            .forward_kinematics(q, &self.estimate)
            .map_err(Fault::NoConvergence)?;
        self.estimate = x;
        let (x_d, u_d, ud_d) = self.reference.at(t);
        let e = pose_error(&x_d, &x);
        let mut a = [S::ZERO; N];
        for i in 0..N {
            a[i] = ud_d[i] + self.gains.kd * (u_d[i] - u[i]) + self.gains.kp * e[i];
        }
        S::MODULE
            .inverse_dynamics(&x, u, &a)
            .map_err(Fault::Singular)
    }
}

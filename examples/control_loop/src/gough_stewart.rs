//! Task-space computed-torque control of the Gough–Stewart platform
//! (`mechanisms::gough_stewart`): `x = [p; quaternion]`, `u = [ω; v]` (base frame).
//!
//! The controller reads the six leg lengths (encoders) and the platform twist, and estimates the
//! pose by the generated forward kinematics (Newton), warm-started from the previous tick.

use crate::{F, Gains, Stats, Timing, math, raised_cosine};
use mechanisms::gough_stewart as m;

/// Degrees of freedom (= actuators).
pub const N: usize = m::DOF;
/// Pose coordinates.
pub const NX: usize = m::NX;

/// The home pose of `mechanisms/specs/gough_stewart.toml` (`[platform] home`): 1 m above the
/// base centre's offset `(-1.5, 0)`, level.
pub const HOME: [F; NX] = [-1.5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0];

/// Why a tick or a plant step failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fault {
    /// A leg or parallel singularity (from the generated code).
    Singular(m::Singular),
    /// Forward kinematics did not converge from the previous estimate.
    NoConvergence(m::NoConvergence),
}

impl From<m::Singular> for Fault {
    fn from(e: m::Singular) -> Fault {
        Fault::Singular(e)
    }
}

/// A pose trajectory: the origin moves by `a_p ⊙ (1 − cos(ω_p t))` from `x0`, and the
/// platform turns by `a_θ (1 − cos(ω_θ t))` about the fixed unit axis `axis` (base frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Start pose (at rest).
    pub x0: [F; NX],
    /// Translation amplitudes (m).
    pub amplitude: [F; 3],
    /// Translation angular frequencies (rad/s).
    pub omega: [F; 3],
    /// Rotation axis (unit, base frame).
    pub axis: [F; 3],
    /// Rotation amplitude (rad).
    pub angle: F,
    /// Rotation angular frequency (rad/s).
    pub angle_omega: F,
}

impl Reference {
    /// Up to 8 cm and 0.16 rad from home, 0.4–0.7 Hz.
    pub const DEMO: Reference = {
        const TAU: F = 2.0 * core::f64::consts::PI as F;
        // (1, 2, 3) / √14
        const S: F = 0.267_261_241_912_424_4;
        Reference {
            x0: HOME,
            amplitude: [0.04, 0.03, 0.04],
            omega: [TAU * 0.5, TAU * 0.7, TAU * 0.4],
            axis: [S, 2.0 * S, 3.0 * S],
            angle: 0.08,
            angle_omega: TAU * 0.6,
        }
    };

    /// `(x_d, u_d, u̇_d)` at `t`.
    pub fn at(&self, t: F) -> ([F; NX], [F; N], [F; N]) {
        let (mut x, mut u, mut ud) = (self.x0, [0.0; N], [0.0; N]);
        for i in 0..3 {
            let r = raised_cosine(self.amplitude[i], self.omega[i], t);
            x[i] += r[0];
            u[3 + i] = r[1];
            ud[3 + i] = r[2];
        }
        let th = raised_cosine(self.angle, self.angle_omega, t);
        let (s, c) = math::sin_cos(0.5 * th[0]);
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
pub fn quat_mul(a: &[F; 4], b: &[F; 4]) -> [F; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Pose error `[δθ; δp]` of `x` against `x_d` (base frame): the rotation `q_d ⊗ q*` as
/// `2·vec` (its rotation vector to second order; the short way round), and `p_d − p`.
pub fn pose_error(x_d: &[F; NX], x: &[F; NX]) -> [F; N] {
    let qd = [x_d[3], x_d[4], x_d[5], x_d[6]];
    let qc = [x[3], -x[4], -x[5], -x[6]];
    let d = quat_mul(&qd, &qc);
    let s = if d[0] < 0.0 { -2.0 } else { 2.0 };
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
pub struct Controller {
    /// Gains (every axis of `[δθ; δp]`).
    pub gains: Gains,
    /// The trajectory to track.
    pub reference: Reference,
    /// The last pose estimate (the next forward kinematics starts from it).
    pub estimate: [F; NX],
}

impl Controller {
    /// A controller whose pose estimate starts at the reference's start.
    pub fn new(gains: Gains, reference: Reference) -> Controller {
        Controller {
            gains,
            reference,
            estimate: reference.x0,
        }
    }

    /// One control tick from the leg lengths `q` and the twist `u`: pose by forward kinematics,
    /// then `τ = ID(x, u, u̇_d + kd (u_d − u) + kp [δθ; δp])` (one generated call: the platform's
    /// Newton–Euler equations, the legs' dynamics and the `A⁻ᵀ` mapping to actuator forces).
    pub fn step(&mut self, t: F, q: &[F; N], u: &[F; N]) -> Result<[F; N], Fault> {
        let x = m::forward_kinematics(q, &self.estimate).map_err(Fault::NoConvergence)?;
        self.estimate = x;
        let (x_d, u_d, ud_d) = self.reference.at(t);
        let e = pose_error(&x_d, &x);
        let mut a = [0.0; N];
        for i in 0..N {
            a[i] = ud_d[i] + self.gains.kd * (u_d[i] - u[i]) + self.gains.kp * e[i];
        }
        Ok(m::inverse_dynamics(&x, u, &a)?)
    }
}

/// The simulated platform: pose and twist.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant {
    /// Pose `[p; quaternion]`.
    pub x: [F; NX],
    /// Twist `[ω; v]` (base frame).
    pub u: [F; N],
}

/// `ẋ` of the pose for the twist `u`: `ṗ = v`, `q̇ = ½ [0, ω] ⊗ q`.
fn pose_rate(x: &[F; NX], u: &[F; N]) -> [F; NX] {
    let w = [0.0, u[0], u[1], u[2]];
    let qd = quat_mul(&w, &[x[3], x[4], x[5], x[6]]);
    [
        u[3],
        u[4],
        u[5],
        0.5 * qd[0],
        0.5 * qd[1],
        0.5 * qd[2],
        0.5 * qd[3],
    ]
}

/// `x + a·dx` with the quaternion renormalized.
fn pose_axpy(x: &[F; NX], a: F, dx: &[F; NX]) -> [F; NX] {
    let mut out = *x;
    for i in 0..NX {
        out[i] += a * dx[i];
    }
    let n = math::sqrt(out[3] * out[3] + out[4] * out[4] + out[5] * out[5] + out[6] * out[6]);
    for v in &mut out[3..7] {
        *v /= n;
    }
    out
}

fn axpy(x: &[F; N], a: F, y: &[F; N]) -> [F; N] {
    let mut out = *x;
    for i in 0..N {
        out[i] += a * y[i];
    }
    out
}

impl Plant {
    /// Integrates `u̇ = FD(x, u, τ)` (the generated forward dynamics) and the pose kinematics
    /// over `period` by `substeps` classical RK4 steps with `tau` held.
    pub fn advance(&mut self, tau: &[F; N], period: F, substeps: u32) -> Result<(), m::Singular> {
        let h = period / substeps as F;
        for _ in 0..substeps {
            let (x, u) = (self.x, self.u);
            let (k1, a1) = (pose_rate(&x, &u), m::forward_dynamics(&x, &u, tau)?);
            let (x2, u2) = (pose_axpy(&x, 0.5 * h, &k1), axpy(&u, 0.5 * h, &a1));
            let (k2, a2) = (pose_rate(&x2, &u2), m::forward_dynamics(&x2, &u2, tau)?);
            let (x3, u3) = (pose_axpy(&x, 0.5 * h, &k2), axpy(&u, 0.5 * h, &a2));
            let (k3, a3) = (pose_rate(&x3, &u3), m::forward_dynamics(&x3, &u3, tau)?);
            let (x4, u4) = (pose_axpy(&x, h, &k3), axpy(&u, h, &a3));
            let (k4, a4) = (pose_rate(&x4, &u4), m::forward_dynamics(&x4, &u4, tau)?);
            let mut dx = [0.0; NX];
            for i in 0..NX {
                dx[i] = (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0;
            }
            self.x = pose_axpy(&x, h, &dx);
            for i in 0..N {
                self.u[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
            }
        }
        Ok(())
    }
}

/// Tracking statistics of a run: rotation (rad) and translation (m), `∞`-norms per tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tracking {
    /// `‖δθ‖∞` (rad).
    pub rotation: Stats,
    /// `‖δp‖∞` (m).
    pub translation: Stats,
}

/// Runs the loop for `seconds` from rest on the reference. The error is of the plant's true
/// pose (not of the controller's estimate).
pub fn run(
    gains: Gains,
    reference: &Reference,
    timing: Timing,
    seconds: F,
) -> Result<Tracking, Fault> {
    let (x0, u0, _) = reference.at(0.0);
    let mut plant = Plant { x: x0, u: u0 };
    let mut controller = Controller::new(gains, *reference);
    let mut out = Tracking::default();
    let ticks = (seconds / timing.period) as u32;
    for k in 0..ticks {
        let t = k as F * timing.period;
        // Sensors: leg lengths (the plant's inverse kinematics) and the twist.
        let q = m::inverse_kinematics(&plant.x)?;
        let (x_d, _, _) = reference.at(t);
        let e = pose_error(&x_d, &plant.x);
        out.rotation.add(crate::norm_inf(&e[..3]));
        out.translation.add(crate::norm_inf(&e[3..]));
        let tau = controller.step(t, &q, &plant.u)?;
        plant.advance(&tau, timing.period, timing.substeps)?;
    }
    Ok(out)
}

/// `∂FD/∂τ · τ̇_d` at `t` along the reference (`τ̇_d` by a central difference over ±`dt`).
pub fn forcing(reference: &Reference, t: F, dt: F) -> Result<[F; N], m::Singular> {
    let tau_at = |t: F| {
        let (x, u, ud) = reference.at(t);
        m::inverse_dynamics(&x, &u, &ud)
    };
    let (lo, hi) = (tau_at(t - dt)?, tau_at(t + dt)?);
    let (x, u, _) = reference.at(t);
    let tau = tau_at(t)?;
    let mut pushed = tau;
    for i in 0..N {
        pushed[i] += (hi[i] - lo[i]) / (2.0 * dt);
    }
    let a = m::forward_dynamics(&x, &u, &tau)?;
    let b = m::forward_dynamics(&x, &u, &pushed)?;
    let mut out = [0.0; N];
    for i in 0..N {
        out[i] = b[i] - a[i];
    }
    Ok(out)
}

/// Predicted largest errors `(rotation, translation)`: `(h/2) · max |∂FD/∂τ · τ̇_d| / kp`
/// over the rotation and the translation components (see the crate docs).
pub fn predicted_max_error(
    gains: Gains,
    reference: &Reference,
    timing: Timing,
    seconds: F,
) -> Result<(F, F), m::Singular> {
    let f = crate::zoh_forcing(seconds, timing.period, |t| forcing(reference, t, 1e-4))?;
    let k = 0.5 * timing.period / gains.kp;
    Ok((k * crate::norm_inf(&f[..3]), k * crate::norm_inf(&f[3..])))
}

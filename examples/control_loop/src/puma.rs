//! Joint-space computed-torque control of the PUMA 560 (`mechanisms::f32::puma560`, or
//! `mechanisms::puma560` in `f64`).

use crate::{Gains, Real, raised_cosine};

/// Joints.
pub const N: usize = mechanisms::puma560::DOF;

/// A scalar with a generated PUMA 560 module: `f32` (`mechanisms::f32::puma560`) or `f64`
/// (`mechanisms::puma560`).
pub trait Scalar: Real {
    /// The generated inverse dynamics `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)`.
    fn inverse_dynamics(q: &[Self; N], qd: &[Self; N], qdd: &[Self; N]) -> [Self; N];
}

impl Scalar for f64 {
    fn inverse_dynamics(q: &[f64; N], qd: &[f64; N], qdd: &[f64; N]) -> [f64; N] {
        mechanisms::puma560::inverse_dynamics(q, qd, qdd)
    }
}

impl Scalar for f32 {
    fn inverse_dynamics(q: &[f32; N], qd: &[f32; N], qdd: &[f32; N]) -> [f32; N] {
        mechanisms::f32::puma560::inverse_dynamics(q, qd, qdd)
    }
}

/// A joint trajectory `q_d(t) = q0 + a ⊙ (1 − cos(ω t))`: starts at rest at `q0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference<S> {
    /// Start (rad).
    pub q0: [S; N],
    /// Amplitudes (rad).
    pub amplitude: [S; N],
    /// Angular frequencies (rad/s).
    pub omega: [S; N],
}

const TAU: f64 = 2.0 * core::f64::consts::PI;

impl Reference<f64> {
    /// Every joint moving at once, 0.2–0.45 Hz, up to 0.6 rad away from a bent-elbow start.
    pub const DEMO: Reference<f64> = Reference {
        q0: [0.0, -0.6, 0.4, 0.0, 0.8, 0.0],
        amplitude: [0.5, 0.3, 0.4, 0.6, 0.5, 0.6],
        omega: [
            TAU * 0.20,
            TAU * 0.25,
            TAU * 0.30,
            TAU * 0.35,
            TAU * 0.40,
            TAU * 0.45,
        ],
    };
}

impl<S: Real> Reference<S> {
    /// The same trajectory with its parameters rounded to another scalar.
    pub fn cast<T: Real>(&self) -> Reference<T> {
        Reference {
            q0: crate::cast(&self.q0),
            amplitude: crate::cast(&self.amplitude),
            omega: crate::cast(&self.omega),
        }
    }

    /// `(q_d, q̇_d, q̈_d)` at `t`.
    pub fn at(&self, t: S) -> ([S; N], [S; N], [S; N]) {
        let (mut q, mut qd, mut qdd) = ([S::ZERO; N], [S::ZERO; N], [S::ZERO; N]);
        for i in 0..N {
            let r = raised_cosine(self.amplitude[i], self.omega[i], t);
            q[i] = self.q0[i] + r[0];
            qd[i] = r[1];
            qdd[i] = r[2];
        }
        (q, qd, qdd)
    }
}

/// The firmware side: gains and reference, no state, no heap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller<S> {
    /// Gains (every joint).
    pub gains: Gains<S>,
    /// The trajectory to track.
    pub reference: Reference<S>,
}

impl<S: Scalar> Controller<S> {
    /// One control tick at time `t` (s) from the joint positions `q` (rad) and speeds `qd`
    /// (rad/s): `τ = ID(q, q̇, q̈_d + kd (q̇_d − q̇) + kp (q_d − q))` (N·m). The whole
    /// computed-torque law (`M(q) a + C(q, q̇) q̇ + g(q)`) is one call of the generated inverse
    /// dynamics: fixed time, no branch, cannot fail.
    pub fn step(&self, t: S, q: &[S; N], qd: &[S; N]) -> [S; N] {
        let (q_d, qd_d, qdd_d) = self.reference.at(t);
        let mut a = [S::ZERO; N];
        for i in 0..N {
            a[i] = qdd_d[i] + self.gains.kd * (qd_d[i] - qd[i]) + self.gains.kp * (q_d[i] - q[i]);
        }
        S::inverse_dynamics(q, qd, &a)
    }
}

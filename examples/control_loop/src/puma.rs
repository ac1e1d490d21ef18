//! Joint-space computed-torque control of the PUMA 560 (`mechanisms::puma560`).

use crate::{F, Gains, Stats, Timing, raised_cosine};
use mechanisms::puma560 as m;

/// Joints.
pub const N: usize = m::DOF;
/// The generated module's error (a singular mass matrix in forward dynamics).
pub type Singular = m::Singular;

/// A joint trajectory `q_d(t) = q0 + a ⊙ (1 − cos(ω t))`: starts at rest at `q0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Start (rad).
    pub q0: [F; N],
    /// Amplitudes (rad).
    pub amplitude: [F; N],
    /// Angular frequencies (rad/s).
    pub omega: [F; N],
}

impl Reference {
    /// Every joint moving at once, 0.2–0.45 Hz, up to 0.6 rad away from a bent-elbow start.
    pub const DEMO: Reference = {
        const TAU: F = 2.0 * core::f64::consts::PI as F;
        Reference {
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
        }
    };

    /// `(q_d, q̇_d, q̈_d)` at `t`.
    pub fn at(&self, t: F) -> ([F; N], [F; N], [F; N]) {
        let (mut q, mut qd, mut qdd) = ([0.0; N], [0.0; N], [0.0; N]);
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
pub struct Controller {
    /// Gains (every joint).
    pub gains: Gains,
    /// The trajectory to track.
    pub reference: Reference,
}

impl Controller {
    /// One control tick: `τ = ID(q, q̇, q̈_d + kd (q̇_d − q̇) + kp (q_d − q))`. The whole
    /// computed-torque law (`M(q) a + C(q, q̇) q̇ + g(q)`) is one call of the generated inverse
    /// dynamics: fixed time, no branch, cannot fail.
    pub fn step(&self, t: F, q: &[F; N], qd: &[F; N]) -> [F; N] {
        let (q_d, qd_d, qdd_d) = self.reference.at(t);
        let mut a = [0.0; N];
        for i in 0..N {
            a[i] = qdd_d[i] + self.gains.kd * (qd_d[i] - qd[i]) + self.gains.kp * (q_d[i] - q[i]);
        }
        m::inverse_dynamics(q, qd, &a)
    }
}

/// The simulated robot: joint positions and speeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant {
    /// Joint positions (rad).
    pub q: [F; N],
    /// Joint speeds (rad/s).
    pub qd: [F; N],
}

impl Plant {
    /// Integrates `q̈ = FD(q, q̇, τ)` (the generated forward dynamics) over `period` by
    /// `substeps` classical RK4 steps with `tau` held.
    pub fn advance(&mut self, tau: &[F; N], period: F, substeps: u32) -> Result<(), Singular> {
        let h = period / substeps as F;
        for _ in 0..substeps {
            let (q, v) = (self.q, self.qd);
            let a1 = m::forward_dynamics(&q, &v, tau)?;
            let (q2, v2) = (axpy(&q, 0.5 * h, &v), axpy(&v, 0.5 * h, &a1));
            let a2 = m::forward_dynamics(&q2, &v2, tau)?;
            let (q3, v3) = (axpy(&q, 0.5 * h, &v2), axpy(&v, 0.5 * h, &a2));
            let a3 = m::forward_dynamics(&q3, &v3, tau)?;
            let (q4, v4) = (axpy(&q, h, &v3), axpy(&v, h, &a3));
            let a4 = m::forward_dynamics(&q4, &v4, tau)?;
            for i in 0..N {
                self.q[i] += h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
                self.qd[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
            }
        }
        Ok(())
    }
}

fn axpy(x: &[F; N], a: F, y: &[F; N]) -> [F; N] {
    let mut out = *x;
    for i in 0..N {
        out[i] += a * y[i];
    }
    out
}

/// Runs the loop for `seconds` from rest on the reference; the error statistics are of
/// `‖q_d − q‖∞` (rad) at every tick.
pub fn run(controller: &Controller, timing: Timing, seconds: F) -> Result<Stats, Singular> {
    let (q0, qd0, _) = controller.reference.at(0.0);
    let mut plant = Plant { q: q0, qd: qd0 };
    let mut stats = Stats::default();
    let ticks = (seconds / timing.period) as u32;
    for k in 0..ticks {
        let t = k as F * timing.period;
        // Sensors: encoders and speeds.
        let (q, qd) = (plant.q, plant.qd);
        let (q_d, _, _) = controller.reference.at(t);
        let mut e: F = 0.0;
        for i in 0..N {
            e = e.max((q_d[i] - q[i]).abs());
        }
        stats.add(e);
        let tau = controller.step(t, &q, &qd);
        plant.advance(&tau, timing.period, timing.substeps)?;
    }
    Ok(stats)
}

/// `∂FD/∂τ · τ̇_d` at `t` along the reference (`τ_d = ID(q_d, q̇_d, q̈_d)`, `τ̇_d` by a central
/// difference over ±`dt`). FD is linear in τ, so the product is a difference of two FD calls.
pub fn forcing(reference: &Reference, t: F, dt: F) -> Result<[F; N], Singular> {
    let tau_at = |t: F| {
        let (q, qd, qdd) = reference.at(t);
        m::inverse_dynamics(&q, &qd, &qdd)
    };
    let (lo, hi) = (tau_at(t - dt), tau_at(t + dt));
    let (q, qd, qdd) = reference.at(t);
    let tau = m::inverse_dynamics(&q, &qd, &qdd);
    let mut pushed = tau;
    for i in 0..N {
        pushed[i] += (hi[i] - lo[i]) / (2.0 * dt);
    }
    let a = m::forward_dynamics(&q, &qd, &tau)?;
    let b = m::forward_dynamics(&q, &qd, &pushed)?;
    let mut out = [0.0; N];
    for i in 0..N {
        out[i] = b[i] - a[i];
    }
    Ok(out)
}

/// The predicted largest tracking error `(h/2) · max ‖∂FD/∂τ · τ̇_d‖∞ / kp` over `seconds`
/// (see the crate docs).
pub fn predicted_max_error(
    controller: &Controller,
    timing: Timing,
    seconds: F,
) -> Result<F, Singular> {
    let f = crate::zoh_forcing(seconds, timing.period, |t| {
        forcing(&controller.reference, t, 1e-4)
    })?;
    Ok(0.5 * timing.period * crate::norm_inf(&f) / controller.gains.kp)
}

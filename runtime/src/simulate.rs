//! Forward-dynamics simulation of any mechanism the runtime evaluates, with its energy: the
//! stability test of the charter ("test stability where methods fail").
//!
//! Any [`Evaluator`]: the state is `(x, u)` as it defines them. A closed loop is integrated in
//! its independent coordinates and reassembled by Newton after every stage (coordinate
//! partitioning, its `advance`): its loops cannot drift open.
//!
//! Two fixed-step schemes: classical Runge–Kutta 4 (on a manifold: every stage moves `x` by
//! `h·c·u` through the retraction) and semi-implicit (symplectic) Euler,
//! `u' = u + h u̇(x, u)`, `x' = x ⊕ h u'`.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use crate::evaluator::Evaluator;

/// The integration scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Classical fourth-order Runge–Kutta.
    Rk4,
    /// Semi-implicit (symplectic) Euler.
    SymplecticEuler,
}

/// The outcome of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Simulated time reached (s): the full duration unless `stopped` says why not.
    pub time: f64,
    /// Total energy `T + V` at the start (J; `V` is zero at the base origin).
    pub energy0: f64,
    /// Largest kinetic energy along the run (J): the energy exchanged with gravity.
    pub max_kinetic: f64,
    /// Largest `|E(t) − E(0)|` (J).
    pub max_drift: f64,
    /// Largest loop-closure residual (closed loops: scaled as in
    /// `closed::noc::closure_residual`; zero otherwise).
    pub max_closure: f64,
    /// Why the run stopped early (a singular configuration, a failed assembly), if it did.
    pub stopped: Option<String>,
}

impl Report {
    /// `max |E − E0| / max T`: the drift relative to the energy in motion.
    pub fn relative_drift(&self) -> f64 {
        if self.max_kinetic > 0.0 {
            self.max_drift / self.max_kinetic
        } else {
            self.max_drift
        }
    }
}

/// Simulate from `(x0, u0)` with no actuation for `steps` steps of `dt` s.
pub fn simulate(
    mech: &dyn Evaluator,
    x0: &[f64],
    u0: &[f64],
    dt: f64,
    steps: usize,
    method: Method,
) -> Result<Report, String> {
    simulate_driven(mech, x0, u0, &vec![0.0; u0.len()], dt, steps, method).map(|d| d.report)
}

/// The end of a driven run: its report and the last state reached.
#[derive(Clone, Debug, PartialEq)]
pub struct Driven {
    /// The run's figures. Under efforts the energy changes by their work, so `max_drift` is
    /// then the energy exchanged, not an error.
    pub report: Report,
    /// Positions at the end (at `report.time`; where the run stopped, the last good step).
    pub x: Vec<f64>,
    /// Speeds at the end.
    pub u: Vec<f64>,
}

/// [`simulate`] under constant actuator efforts `tau` (N or N·m, one per speed), returning the
/// last state too: e.g. a benchmark driven by a motor torque.
pub fn simulate_driven(
    mech: &dyn Evaluator,
    x0: &[f64],
    u0: &[f64],
    tau: &[f64],
    dt: f64,
    steps: usize,
    method: Method,
) -> Result<Driven, String> {
    if tau.len() != u0.len() {
        return Err(format!("{} efforts for {} speeds", tau.len(), u0.len()));
    }
    let (t0, v0) = mech.energy(x0, u0)?;
    let mut r = Report {
        time: 0.0,
        energy0: t0 + v0,
        max_kinetic: t0,
        max_drift: 0.0,
        max_closure: mech.closure(x0),
        stopped: None,
    };
    let (mut x, mut u) = (x0.to_vec(), u0.to_vec());
    let axpy = |a: &[f64], s: f64, b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(p, q)| p + s * q).collect()
    };
    let scale = |s: f64, a: &[f64]| -> Vec<f64> { a.iter().map(|v| s * v).collect() };
    for n in 0..steps {
        let step = || -> Result<(Vec<f64>, Vec<f64>), String> {
            match method {
                Method::SymplecticEuler => {
                    let a = mech.forward_dynamics(&x, &u, tau)?;
                    let un = axpy(&u, dt, &a);
                    let xn = mech.advance(&x, &scale(dt, &un))?;
                    Ok((xn, un))
                }
                Method::Rk4 => {
                    let a1 = mech.forward_dynamics(&x, &u, tau)?;
                    let u1 = u.clone();
                    let x2 = mech.advance(&x, &scale(0.5 * dt, &u1))?;
                    let u2 = axpy(&u, 0.5 * dt, &a1);
                    let a2 = mech.forward_dynamics(&x2, &u2, tau)?;
                    let x3 = mech.advance(&x, &scale(0.5 * dt, &u2))?;
                    let u3 = axpy(&u, 0.5 * dt, &a2);
                    let a3 = mech.forward_dynamics(&x3, &u3, tau)?;
                    let x4 = mech.advance(&x, &scale(dt, &u3))?;
                    let u4 = axpy(&u, dt, &a3);
                    let a4 = mech.forward_dynamics(&x4, &u4, tau)?;
                    let dx: Vec<f64> = (0..u.len())
                        .map(|i| dt / 6.0 * (u1[i] + 2.0 * u2[i] + 2.0 * u3[i] + u4[i]))
                        .collect();
                    let du: Vec<f64> = (0..u.len())
                        .map(|i| dt / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]))
                        .collect();
                    Ok((mech.advance(&x, &dx)?, axpy(&u, 1.0, &du)))
                }
            }
        };
        let (xn, un) = match step() {
            Ok(s) => s,
            Err(e) => {
                r.stopped = Some(e);
                return Ok(Driven { report: r, x, u });
            }
        };
        x = xn;
        u = un;
        r.time = (n + 1) as f64 * dt;
        match mech.energy(&x, &u) {
            Ok((t, v)) => {
                r.max_kinetic = r.max_kinetic.max(t);
                r.max_drift = r.max_drift.max((t + v - r.energy0).abs());
            }
            Err(e) => {
                r.stopped = Some(e);
                return Ok(Driven { report: r, x, u });
            }
        }
        r.max_closure = r.max_closure.max(mech.closure(&x));
    }
    Ok(Driven { report: r, x, u })
}

//! The test bench (feature `bench`; std, heap): simulated plants, the closed loops, and the
//! figures the crate docs derive: the zero-order-hold error estimate, the `f32` rounding floor
//! and the `f32`-vs-`f64` torque agreement.
//!
//! The plants are the runtime's generic `f64` evaluation of the bundled specs
//! (`runtime::noc::forward_dynamics` for the PUMA 560, `runtime::parallel::noc` for the
//! Gough–Stewart platform; the specs are parsed by `codegen::spec`), not the generated code the
//! controllers call. Each control period the plant is integrated by `substeps` classical RK4
//! steps with the torque held. The sensors are exact `f64` values rounded to the controller's
//! scalar; the controller's torques are widened back to `f64`.
//!
//! The estimates ([`puma::predicted_max_error`], [`puma::rounding_floor`] and the
//! Gough–Stewart ones) use the generated `f64` modules, a third route.

use std::string::String;

/// Why a run stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// The plant (runtime) met a singular configuration.
    Plant(String),
    /// The controller returned an error.
    Controller(String),
}

/// `max over ticks of ‖δτ‖∞ / ‖τ‖∞` and `max ‖M⁻¹ δτ‖∞` (see [`puma::rounding_floor`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rounding {
    /// Largest relative torque difference `‖τ₃₂ − τ₆₄‖∞ / ‖τ₆₄‖∞` over the ticks.
    pub torque_relative: f64,
    /// Largest absolute torque difference `‖τ₃₂ − τ₆₄‖∞` (N·m or N).
    pub torque_absolute: f64,
    /// Largest `‖M⁻¹ (τ₃₂ − τ₆₄)‖∞` over the ticks (rad/s², or per component group for the
    /// platform: see [`gough_stewart::rounding_floor`]).
    pub acceleration: f64,
    /// Platform only: the largest error of the `f32` controller's pose estimate (forward
    /// kinematics) against the true pose (rad or m; 0 for the PUMA 560).
    pub estimate: f64,
}

/// `max(‖a − b‖∞, …)` helper: `‖a − b‖∞`.
fn diff_inf(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0, |m: f64, (x, y)| m.max((x - y).abs()))
}

/// Max over the ticks `t_k = k·period ≤ seconds` of `|f(t_k)|`, componentwise.
fn max_over_ticks<const N: usize, E>(
    seconds: f64,
    period: f64,
    mut f: impl FnMut(f64) -> Result<[f64; N], E>,
) -> Result<[f64; N], E> {
    let mut out = [0.0f64; N];
    let steps = (seconds / period) as u32;
    for k in 0..=steps {
        let v = f(k as f64 * period)?;
        for i in 0..N {
            out[i] = out[i].max(v[i].abs());
        }
    }
    Ok(out)
}

/// The PUMA 560 on the bench.
pub mod puma {
    use super::{Error, Rounding, diff_inf, max_over_ticks};
    use crate::puma::{Controller, N, Reference, Scalar};
    use crate::{Stats, Timing, cast, norm_inf};
    use mechanisms::puma560 as g;
    use runtime::model::Model;
    use std::format;

    /// The runtime model of `mechanisms/specs/puma560.toml`.
    pub fn model() -> Model {
        let src = include_str!("../../../mechanisms/specs/puma560.toml");
        match codegen::spec::load_mechanism("puma560.toml", src) {
            Ok((codegen::spec::Mechanism::Tree(m), _)) => m,
            Ok(_) => panic!("puma560.toml is a tree"),
            Err(d) => panic!("{d}"),
        }
    }

    /// The simulated robot: the runtime's model, joint positions and speeds.
    #[derive(Clone, Debug)]
    pub struct Plant {
        /// The model (`runtime::model::Model`).
        pub model: Model,
        /// Joint positions (rad).
        pub q: [f64; N],
        /// Joint speeds (rad/s).
        pub qd: [f64; N],
    }

    impl Plant {
        /// `q̈ = FD(q, q̇, τ)` by the runtime.
        fn acceleration(
            &self,
            q: &[f64; N],
            qd: &[f64; N],
            tau: &[f64; N],
        ) -> Result<[f64; N], Error> {
            let a = runtime::noc::forward_dynamics(&self.model, q, qd, tau)
                .map_err(|e| Error::Plant(format!("{e:?}")))?;
            Ok(core::array::from_fn(|i| a[i]))
        }

        /// Integrates `q̈ = FD(q, q̇, τ)` over `period` by `substeps` classical RK4 steps with
        /// `tau` held.
        pub fn advance(&mut self, tau: &[f64; N], period: f64, substeps: u32) -> Result<(), Error> {
            let h = period / substeps as f64;
            for _ in 0..substeps {
                let (q, v) = (self.q, self.qd);
                let a1 = self.acceleration(&q, &v, tau)?;
                let (q2, v2) = (axpy(&q, 0.5 * h, &v), axpy(&v, 0.5 * h, &a1));
                let a2 = self.acceleration(&q2, &v2, tau)?;
                let (q3, v3) = (axpy(&q, 0.5 * h, &v2), axpy(&v, 0.5 * h, &a2));
                let a3 = self.acceleration(&q3, &v3, tau)?;
                let (q4, v4) = (axpy(&q, h, &v3), axpy(&v, h, &a3));
                let a4 = self.acceleration(&q4, &v4, tau)?;
                for i in 0..N {
                    self.q[i] += h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
                    self.qd[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
                }
            }
            Ok(())
        }
    }

    fn axpy(x: &[f64; N], a: f64, y: &[f64; N]) -> [f64; N] {
        core::array::from_fn(|i| x[i] + a * y[i])
    }

    /// A closed loop: a controller in scalar `S`, the plant, the tick count.
    #[derive(Clone, Debug)]
    pub struct Loop<S> {
        /// The firmware side.
        pub controller: Controller<S>,
        /// The robot.
        pub plant: Plant,
        /// Control period and plant substeps.
        pub timing: Timing,
        /// The exact reference (the plant's error is measured against it).
        pub reference: Reference<f64>,
        ticks: u32,
    }

    impl<S: Scalar> Loop<S> {
        /// The controller `gains`/`reference` rounded to `S`, the plant at rest on the reference.
        pub fn new(gains: crate::Gains<f64>, reference: Reference<f64>, timing: Timing) -> Loop<S> {
            let (q, qd, _) = reference.at(0.0);
            Loop {
                controller: Controller {
                    gains: crate::Gains {
                        kp: S::from_f64(gains.kp),
                        kd: S::from_f64(gains.kd),
                    },
                    reference: reference.cast(),
                },
                plant: Plant {
                    model: model(),
                    q,
                    qd,
                },
                timing,
                reference,
                ticks: 0,
            }
        }

        /// One control period: read the sensors (rounded to `S`), compute the torque, hold it
        /// over the period. Returns the tracking error `q_d − q` (rad) at the tick.
        pub fn tick(&mut self) -> Result<[f64; N], Error> {
            let t = self.ticks as f64 * self.timing.period;
            let (q_d, _, _) = self.reference.at(t);
            let e = core::array::from_fn(|i| q_d[i] - self.plant.q[i]);
            let tau =
                self.controller
                    .step(S::from_f64(t), &cast(&self.plant.q), &cast(&self.plant.qd));
            self.plant
                .advance(&cast(&tau), self.timing.period, self.timing.substeps)?;
            self.ticks += 1;
            Ok(e)
        }
    }

    /// Runs the loop in scalar `S` for `seconds` from rest on the reference: statistics of
    /// `‖q_d − q‖∞` (rad) at every tick.
    pub fn run<S: Scalar>(
        gains: crate::Gains<f64>,
        reference: Reference<f64>,
        timing: Timing,
        seconds: f64,
    ) -> Result<Stats, Error> {
        let mut l = Loop::<S>::new(gains, reference, timing);
        let mut stats = Stats::default();
        for _ in 0..(seconds / timing.period) as u32 {
            stats.add(norm_inf(&l.tick()?));
        }
        Ok(stats)
    }

    /// `∂FD/∂τ · τ̇_d` at `t` along the reference (`τ_d = ID(q_d, q̇_d, q̈_d)`, `τ̇_d` by a
    /// central difference over ±`dt`; generated `f64` code). FD is linear in τ, so the product
    /// is a difference of two FD calls.
    pub fn forcing(reference: &Reference<f64>, t: f64, dt: f64) -> Result<[f64; N], g::Singular> {
        let tau_at = |t: f64| {
            let (q, qd, qdd) = reference.at(t);
            g::inverse_dynamics(&q, &qd, &qdd)
        };
        let (lo, hi) = (tau_at(t - dt), tau_at(t + dt));
        let (q, qd, _) = reference.at(t);
        let tau = tau_at(t);
        let pushed = core::array::from_fn(|i| tau[i] + (hi[i] - lo[i]) / (2.0 * dt));
        let a = g::forward_dynamics(&q, &qd, &tau)?;
        let b = g::forward_dynamics(&q, &qd, &pushed)?;
        Ok(core::array::from_fn(|i| b[i] - a[i]))
    }

    /// The predicted largest tracking error from the hold alone,
    /// `(h/2) · max ‖∂FD/∂τ · τ̇_d‖∞ / kp` over `seconds` (see the crate docs).
    pub fn predicted_max_error(
        gains: crate::Gains<f64>,
        reference: &Reference<f64>,
        timing: Timing,
        seconds: f64,
    ) -> Result<f64, g::Singular> {
        let f = max_over_ticks(seconds, timing.period, |t| forcing(reference, t, 1e-4))?;
        Ok(0.5 * timing.period * norm_inf(&f) / gains.kp)
    }

    /// The `f32` controller against the `f64` one at every tick along the reference (state on
    /// the reference, sensors rounded to `f32`): `δτ = τ₃₂ − τ₆₄` and `M⁻¹ δτ`
    /// (`FD(τ₆₄ + δτ) − FD(τ₆₄)`, generated `f64` code). `acceleration / kp` bounds how far the
    /// `f32` loop can drift from the `f64` one (see the crate docs).
    pub fn rounding_floor(
        gains: crate::Gains<f64>,
        reference: &Reference<f64>,
        timing: Timing,
        seconds: f64,
    ) -> Result<Rounding, Error> {
        let c64 = Controller {
            gains,
            reference: *reference,
        };
        let c32 = Controller::<f32> {
            gains: crate::Gains {
                kp: gains.kp as f32,
                kd: gains.kd as f32,
            },
            reference: reference.cast(),
        };
        let mut out = Rounding::default();
        for k in 0..=(seconds / timing.period) as u32 {
            let t = k as f64 * timing.period;
            let (q, qd, _) = reference.at(t);
            let tau64 = c64.step(t, &q, &qd);
            let tau32: [f64; N] = cast(&c32.step(t as f32, &cast(&q), &cast(&qd)));
            let dtau = diff_inf(&tau32, &tau64);
            out.torque_absolute = out.torque_absolute.max(dtau);
            out.torque_relative = out.torque_relative.max(dtau / norm_inf(&tau64));
            let fd = |tau: &[f64; N]| {
                g::forward_dynamics(&q, &qd, tau).map_err(|e| Error::Plant(format!("{e:?}")))
            };
            out.acceleration = out.acceleration.max(diff_inf(&fd(&tau32)?, &fd(&tau64)?));
        }
        Ok(out)
    }
}

/// The Gough–Stewart platform on the bench.
pub mod gough_stewart {
    use super::{Error, Rounding, diff_inf, max_over_ticks};
    use crate::gough_stewart::{Controller, N, NX, Reference, Scalar, pose_error, quat_mul};
    use crate::{Gains, Real, Stats, Timing, cast, norm_inf};
    use mechanisms::gough_stewart as g;
    use runtime::parallel::noc::{self as rt, Plan};
    use std::format;

    /// The runtime plan of `mechanisms/specs/gough_stewart.toml`.
    pub fn plan() -> Plan {
        let src = include_str!("../../../mechanisms/specs/gough_stewart.toml");
        match codegen::spec::load_mechanism("gough_stewart.toml", src) {
            Ok((codegen::spec::Mechanism::Parallel(m), _)) => {
                Plan::new(&m).unwrap_or_else(|e| panic!("{e}"))
            }
            Ok(_) => panic!("gough_stewart.toml is a parallel mechanism"),
            Err(d) => panic!("{d}"),
        }
    }

    /// The simulated platform: the runtime's plan, pose and twist.
    #[derive(Clone, Debug)]
    pub struct Plant {
        /// The runtime's plan of the mechanism.
        pub plan: Plan,
        /// Pose `[p; quaternion]`.
        pub x: [f64; NX],
        /// Twist `[ω; v]` (base frame).
        pub u: [f64; N],
    }

    /// `ẋ` of the pose for the twist `u`: `ṗ = v`, `q̇ = ½ [0, ω] ⊗ q`.
    fn pose_rate(x: &[f64; NX], u: &[f64; N]) -> [f64; NX] {
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
    fn pose_axpy(x: &[f64; NX], a: f64, dx: &[f64; NX]) -> [f64; NX] {
        let mut out: [f64; NX] = core::array::from_fn(|i| x[i] + a * dx[i]);
        let n = norm2(&out[3..7]);
        for v in &mut out[3..7] {
            *v /= n;
        }
        out
    }

    fn norm2(v: &[f64]) -> f64 {
        v.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    fn axpy(x: &[f64; N], a: f64, y: &[f64; N]) -> [f64; N] {
        core::array::from_fn(|i| x[i] + a * y[i])
    }

    impl Plant {
        /// `u̇ = FD(x, u, τ)` by the runtime.
        fn acceleration(
            &self,
            x: &[f64; NX],
            u: &[f64; N],
            tau: &[f64; N],
        ) -> Result<[f64; N], Error> {
            let a = rt::forward_dynamics(&self.plan, x, u, tau)
                .map_err(|e| Error::Plant(format!("{e}")))?;
            Ok(core::array::from_fn(|i| a[i]))
        }

        /// The leg lengths (m): the runtime's inverse kinematics.
        pub fn leg_lengths(&self) -> Result<[f64; N], Error> {
            let q = rt::inverse_kinematics(&self.plan, &self.x)
                .map_err(|e| Error::Plant(format!("{e}")))?;
            Ok(core::array::from_fn(|i| q[i]))
        }

        /// Integrates `u̇ = FD(x, u, τ)` and the pose kinematics over `period` by `substeps`
        /// classical RK4 steps with `tau` held.
        pub fn advance(&mut self, tau: &[f64; N], period: f64, substeps: u32) -> Result<(), Error> {
            let h = period / substeps as f64;
            for _ in 0..substeps {
                let (x, u) = (self.x, self.u);
                let (k1, a1) = (pose_rate(&x, &u), self.acceleration(&x, &u, tau)?);
                let (x2, u2) = (pose_axpy(&x, 0.5 * h, &k1), axpy(&u, 0.5 * h, &a1));
                let (k2, a2) = (pose_rate(&x2, &u2), self.acceleration(&x2, &u2, tau)?);
                let (x3, u3) = (pose_axpy(&x, 0.5 * h, &k2), axpy(&u, 0.5 * h, &a2));
                let (k3, a3) = (pose_rate(&x3, &u3), self.acceleration(&x3, &u3, tau)?);
                let (x4, u4) = (pose_axpy(&x, h, &k3), axpy(&u, h, &a3));
                let (k4, a4) = (pose_rate(&x4, &u4), self.acceleration(&x4, &u4, tau)?);
                let dx =
                    core::array::from_fn(|i| (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0);
                self.x = pose_axpy(&x, h, &dx);
                for i in 0..N {
                    self.u[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
                }
            }
            Ok(())
        }
    }

    /// A closed loop: a controller in scalar `S`, the plant, the tick count.
    #[derive(Clone, Debug)]
    pub struct Loop<S> {
        /// The firmware side.
        pub controller: Controller<S>,
        /// The platform.
        pub plant: Plant,
        /// Control period and plant substeps.
        pub timing: Timing,
        /// The exact reference (the plant's error is measured against it).
        pub reference: Reference<f64>,
        ticks: u32,
    }

    /// `gains` rounded to `S`.
    fn gains_in<S: Real>(gains: Gains<f64>) -> Gains<S> {
        Gains {
            kp: S::from_f64(gains.kp),
            kd: S::from_f64(gains.kd),
        }
    }

    impl<S: Scalar> Loop<S> {
        /// The controller `gains`/`reference` rounded to `S`, the plant at rest on the reference.
        pub fn new(gains: Gains<f64>, reference: Reference<f64>, timing: Timing) -> Loop<S> {
            let (x, u, _) = reference.at(0.0);
            Loop {
                controller: Controller::new(gains_in(gains), reference.cast()),
                plant: Plant { plan: plan(), x, u },
                timing,
                reference,
                ticks: 0,
            }
        }

        /// One control period: read the leg lengths and the twist (rounded to `S`), compute the
        /// leg forces, hold them over the period. Returns the error `[δθ; δp]` (rad, m) of the
        /// plant's true pose at the tick.
        pub fn tick(&mut self) -> Result<[f64; N], Error> {
            let t = self.ticks as f64 * self.timing.period;
            let (x_d, _, _) = self.reference.at(t);
            let e = pose_error(&x_d, &self.plant.x);
            let q = self.plant.leg_lengths()?;
            let tau = self
                .controller
                .step(S::from_f64(t), &cast(&q), &cast(&self.plant.u))
                .map_err(|f| Error::Controller(format!("{f:?}")))?;
            self.plant
                .advance(&cast(&tau), self.timing.period, self.timing.substeps)?;
            self.ticks += 1;
            Ok(e)
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

    impl Tracking {
        /// Add one tick's error `[δθ; δp]`.
        pub fn add(&mut self, e: &[f64; N]) {
            self.rotation.add(norm_inf(&e[..3]));
            self.translation.add(norm_inf(&e[3..]));
        }
    }

    /// Runs the loop in scalar `S` for `seconds` from rest on the reference.
    pub fn run<S: Scalar>(
        gains: Gains<f64>,
        reference: Reference<f64>,
        timing: Timing,
        seconds: f64,
    ) -> Result<Tracking, Error> {
        let mut l = Loop::<S>::new(gains, reference, timing);
        let mut out = Tracking::default();
        for _ in 0..(seconds / timing.period) as u32 {
            out.add(&l.tick()?);
        }
        Ok(out)
    }

    /// `∂FD/∂τ · τ̇_d` at `t` along the reference (`τ̇_d` by a central difference over ±`dt`;
    /// generated `f64` code).
    pub fn forcing(reference: &Reference<f64>, t: f64, dt: f64) -> Result<[f64; N], g::Singular> {
        let tau_at = |t: f64| {
            let (x, u, ud) = reference.at(t);
            g::inverse_dynamics(&x, &u, &ud)
        };
        let (lo, hi) = (tau_at(t - dt)?, tau_at(t + dt)?);
        let (x, u, _) = reference.at(t);
        let tau = tau_at(t)?;
        let pushed = core::array::from_fn(|i| tau[i] + (hi[i] - lo[i]) / (2.0 * dt));
        let a = g::forward_dynamics(&x, &u, &tau)?;
        let b = g::forward_dynamics(&x, &u, &pushed)?;
        Ok(core::array::from_fn(|i| b[i] - a[i]))
    }

    /// Predicted largest errors `(rotation, translation)` from the hold alone:
    /// `(h/2) · max |∂FD/∂τ · τ̇_d| / kp` over the rotation and the translation components (see
    /// the crate docs).
    pub fn predicted_max_error(
        gains: Gains<f64>,
        reference: &Reference<f64>,
        timing: Timing,
        seconds: f64,
    ) -> Result<(f64, f64), g::Singular> {
        let f = max_over_ticks(seconds, timing.period, |t| forcing(reference, t, 1e-4))?;
        let k = 0.5 * timing.period / gains.kp;
        Ok((k * norm_inf(&f[..3]), k * norm_inf(&f[3..])))
    }

    /// The `f32` controller against the `f64` one at every tick along the reference (pose and
    /// twist on the reference, leg lengths from the generated `f64` inverse kinematics, sensors
    /// rounded to `f32`; each controller's forward kinematics warm-started from its previous
    /// tick, as in the loop). Returns `(rotation, translation)`: the torque figures are the same
    /// in both, `acceleration` is `max ‖M⁻¹ δτ‖∞` over the rotation (rad/s²) and the translation
    /// (m/s²) components of `u̇`, `estimate` the `f32` pose estimate's error in each.
    pub fn rounding_floor(
        gains: Gains<f64>,
        reference: &Reference<f64>,
        timing: Timing,
        seconds: f64,
    ) -> Result<(Rounding, Rounding), Error> {
        let mut c64 = Controller::new(gains, *reference);
        let mut c32 = Controller::<f32>::new(gains_in(gains), reference.cast());
        let (mut rot, mut trans) = (Rounding::default(), Rounding::default());
        let plant = |e: g::Singular| Error::Plant(format!("{e:?}"));
        let ctl = |e: std::string::String| Error::Controller(e);
        for k in 0..=(seconds / timing.period) as u32 {
            let t = k as f64 * timing.period;
            let (x, u, _) = reference.at(t);
            let q = g::inverse_kinematics(&x).map_err(plant)?;
            let tau64 = c64.step(t, &q, &u).map_err(|f| ctl(format!("{f:?}")))?;
            let tau32: [f64; N] = cast(
                &c32.step(t as f32, &cast(&q), &cast(&u))
                    .map_err(|f| ctl(format!("{f:?}")))?,
            );
            let est = pose_error(&x, &cast(&c32.estimate));
            let dtau = diff_inf(&tau32, &tau64);
            let rel = dtau / norm_inf(&tau64);
            let a32 = g::forward_dynamics(&x, &u, &tau32).map_err(plant)?;
            let a64 = g::forward_dynamics(&x, &u, &tau64).map_err(plant)?;
            for (r, range) in [(&mut rot, 0..3), (&mut trans, 3..6)] {
                r.estimate = r.estimate.max(norm_inf(&est[range.clone()]));
                r.torque_absolute = r.torque_absolute.max(dtau);
                r.torque_relative = r.torque_relative.max(rel);
                r.acceleration = r
                    .acceleration
                    .max(diff_inf(&a32[range.clone()], &a64[range]));
            }
        }
        Ok((rot, trans))
    }
}

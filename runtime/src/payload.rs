//! A rigid body whose mass properties are inputs of the evaluator (a run-time payload).

use crate::algebra::{M, V, cm, cv};
use crate::model::{Mat3, Vec3};
use crate::scalar::Real;

/// A rigid body carried by the platform whose mass properties are scalars of the evaluator, not
/// constants of the plan: a generated module's run-time payload (`[scene] parameters =
/// "runtime"`), where they are symbolic inputs. The platform's own mass properties stay in the
/// plan ([`crate::parallel::Plan`]).
#[derive(Clone, Copy, Debug)]
pub struct Payload<R> {
    /// Mass (kg).
    pub mass: R,
    /// Mass centre in the platform frame (m). Ignored by a planar point platform (a point).
    pub com: V<R>,
    /// Inertia about the mass centre, platform axes (kg·m²), symmetric. Ignored by a planar
    /// point platform.
    pub inertia: M<R>,
}

impl<R: Real> Payload<R> {
    /// A payload of `f64` values.
    pub fn from_f64(mass: f64, com: Vec3, inertia: Mat3) -> Payload<R> {
        Payload {
            mass: R::c(mass),
            com: cv(&com),
            inertia: cm(&inertia),
        }
    }
}

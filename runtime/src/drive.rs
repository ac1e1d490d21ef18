//! The drive law (viscous and regularized Coulomb friction, reflected rotor inertia) over
//! [`Real`], with its coefficients as constants of a plan or as scalars of the evaluator.

use alloc::vec::Vec;

use crate::scalar::Real;

/// The drive coefficients of a mechanism's joints as scalars of the evaluator, in place of the
/// constants of its plan: a generated module's run-time drive parameters, where they are
/// symbolic inputs. Entry `i` is the mechanism's `i`-th driven joint: joint `k` of leg `leg` at
/// `3·leg + k` for a parallel mechanism, tree joint `i` for closed loops. An effect that is
/// `None` is absent. The effort law is [`drive_effort`]'s.
#[derive(Clone, Debug)]
pub struct DriveInputs<R> {
    /// Viscous coefficients (N·m·s/rad or N·s/m).
    pub viscous: Option<Vec<R>>,
    /// Coulomb levels (N·m or N).
    pub coulomb: Option<Vec<R>>,
    /// Reflected rotor inertias (kg·m² or kg).
    pub armature: Option<Vec<R>>,
    /// The speed scale `v_s` of the regularized Coulomb law.
    pub coulomb_velocity: f64,
}

impl<R: Real> DriveInputs<R> {
    /// The drive effort of joint `i` at the rate `qd` and acceleration `qdd`.
    pub fn effort(&self, i: usize, qd: R, qdd: R) -> R {
        let mut e = R::c(0.0);
        if let Some(a) = &self.armature {
            e = e + a[i] * qdd;
        }
        if let Some(b) = &self.viscous {
            e = e + b[i] * qd;
        }
        if let Some(c) = &self.coulomb {
            let vs = self.coulomb_velocity;
            e = e + c[i] * qd / (qd * qd + R::c(vs * vs)).sqrt();
        }
        e
    }
}

impl<R: Clone> DriveInputs<R> {
    /// The rotor inertias alone: the drives of the velocity-dependent efforts (`coriolis`),
    /// which leave out friction.
    pub fn without_friction(&self) -> DriveInputs<R> {
        DriveInputs {
            viscous: None,
            coulomb: None,
            ..self.clone()
        }
    }
    /// The friction alone (viscous and Coulomb): the drives of `friction`.
    pub fn friction_only(&self) -> DriveInputs<R> {
        DriveInputs {
            armature: None,
            ..self.clone()
        }
    }
}

impl crate::model::Drive {
    /// This drive without its friction (viscous and Coulomb), its rotor inertia kept.
    pub fn without_friction(&self) -> crate::model::Drive {
        crate::model::Drive {
            viscous: 0.0,
            coulomb: 0.0,
            ..*self
        }
    }
    /// This drive's friction alone (no rotor inertia).
    pub fn friction_only(&self) -> crate::model::Drive {
        crate::model::Drive {
            armature: 0.0,
            ..*self
        }
    }
    /// Whether the drive has friction (viscous or Coulomb).
    pub fn has_friction(&self) -> bool {
        self.viscous != 0.0 || self.coulomb != 0.0
    }
}

/// [`Drive::effort`](crate::model::Drive::effort) over [`Real`]: `I_a q̈ + b q̇ + c q̇ / √(q̇² + v_s²)`
/// (terms with zero coefficients are not formed).
pub fn drive_effort<R: Real>(d: &crate::model::Drive, qd: R, qdd: R) -> R {
    let mut e = R::c(0.0);
    if d.armature != 0.0 {
        e = e + R::c(d.armature) * qdd;
    }
    if d.viscous != 0.0 {
        e = e + R::c(d.viscous) * qd;
    }
    if d.coulomb != 0.0 {
        let vs = d.coulomb_velocity;
        e = e + R::c(d.coulomb) * qd / (qd * qd + R::c(vs * vs)).sqrt();
    }
    e
}

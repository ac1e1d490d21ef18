//! Step 1: the platform's pose from `x` ([`Platform`]: its rotation from the quaternion,
//! normalized on the fly, and its origin).

use super::parasitic::{Parasitic, parasitic};
use super::plan::Plan;
use crate::algebra::{M, V, cm, cv, ident};
use crate::parallel::PlatformMotion;
use crate::scalar::{Real, Singular, Site};

/// The platform's pose from `x`.
#[derive(Clone, Copy, Debug)]
pub struct Platform<R> {
    /// Rotation (platform → base).
    pub rot: M<R>,
    /// Origin of the platform frame (base frame).
    pub origin: V<R>,
    /// A 1T2R platform's parasitic components and twist map `t = S u` (`HeaveTilt`); `None`
    /// for every other motion, whose `u` shapes the twist directly.
    pub parasitic: Option<Parasitic<R>>,
    /// A Schönflies platform's tool angle `(sin θ, cos θ)` (`Schoenflies`); `None` for every
    /// other motion.
    pub tool: Option<(R, R)>,
}

/// The platform pose from `x` (`Pose`: `[p; q]`, `Orientation`: `q`, `Translation`: `p` with
/// the fixed rotation, `PlanarPose`: `[px, py, φ]`, the home rotation turned by `φ` about `z`);
/// the quaternion need not
/// be unit (it is normalized), but it must not be zero (`Err(Site::Platform)`).
pub fn platform<R: Real>(plan: &Plan, x: &[R]) -> Result<Platform<R>, Singular> {
    let (origin, q) = match plan.motion {
        PlatformMotion::Pose => ([x[0], x[1], x[2]], [x[3], x[4], x[5], x[6]]),
        PlatformMotion::Orientation { centre } => (cv(&centre), [x[0], x[1], x[2], x[3]]),
        PlatformMotion::PlanarPoint { height } => {
            return Ok(Platform {
                rot: ident(),
                origin: [x[0], x[1], R::c(height)],
                parasitic: None,
                tool: None,
            });
        }
        PlatformMotion::Translation { rotation } => {
            return Ok(Platform {
                rot: cm(&rotation),
                origin: [x[0], x[1], x[2]],
                parasitic: None,
                tool: None,
            });
        }
        PlatformMotion::PlanarPose { height, rotation } => {
            // Rz(φ)·rotation: the home rotation turned about the base z axis.
            let (s, c) = x[2].sin_cos();
            let h = cm::<R>(&rotation);
            let rot = core::array::from_fn(|i| {
                if i == 0 {
                    core::array::from_fn(|j| c * h[0][j] - s * h[1][j])
                } else if i == 1 {
                    core::array::from_fn(|j| s * h[0][j] + c * h[1][j])
                } else {
                    h[2]
                }
            });
            return Ok(Platform {
                rot,
                origin: [x[0], x[1], R::c(height)],
                parasitic: None,
                tool: None,
            });
        }
        PlatformMotion::Schoenflies { rotation } => {
            // The carrier translates; the tool's angle goes to the shaft.
            return Ok(Platform {
                rot: cm(&rotation),
                origin: [x[0], x[1], x[2]],
                parasitic: None,
                tool: Some(x[3].sin_cos()),
            });
        }
        PlatformMotion::HeaveTilt { .. } => {
            let (rot, origin, par) = parasitic(plan, x)?;
            return Ok(Platform {
                rot,
                origin,
                parasitic: Some(par),
                tool: None,
            });
        }
    };
    // Divided by its largest component first, so that no square under- or overflows: any
    // finite non-zero multiple of a unit quaternion is the same rotation (the sign of the
    // largest component may flip the quaternion, which is the same rotation too).
    let [w, a, b, c] = q;
    let big = R::select_abs_gt(w, a, w, a);
    let big = R::select_abs_gt(big, b, big, b);
    let big = R::select_abs_gt(big, c, big, c);
    let big = R::check(big, R::c(0.0), R::c(1.0), Site::Platform, true)?;
    // Divided, not multiplied by `1/big`, which overflows for a subnormal `big`.
    let [w, a, b, c] = [w / big, a / big, b / big, c / big];
    let n = w * w + a * a + b * b + c * c;
    let s = R::c(2.0) / n;
    let one = R::c(1.0);
    let rot = [
        [
            one - s * (b * b + c * c),
            s * (a * b - w * c),
            s * (a * c + w * b),
        ],
        [
            s * (a * b + w * c),
            one - s * (a * a + c * c),
            s * (b * c - w * a),
        ],
        [
            s * (a * c - w * b),
            s * (b * c + w * a),
            one - s * (a * a + b * b),
        ],
    ];
    Ok(Platform {
        rot,
        origin,
        parasitic: None,
        tool: None,
    })
}

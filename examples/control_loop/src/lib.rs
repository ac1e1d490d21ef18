//! A firmware-like control loop on nocdyn's generated dynamics: computed-torque control of the
//! PUMA 560 ([`puma`]) and of the Gough–Stewart platform ([`gough_stewart`]) at a fixed
//! 1 kHz step, each fed by a simulated plant.
//!
//! The crate is `#![no_std]` and uses no heap: every quantity is a fixed-size array, every
//! generated function returns its result by value, and a singular configuration is an `Err`,
//! never a panic. The part that would run on a microcontroller is `Controller::step`; `Plant`
//! and `run` are the test bench (the plant integrates the *generated* forward dynamics by RK4
//! at a finer step with the torque held between control ticks, as a zero-order hold does).
//!
//! # Why the tracking error is what it is
//!
//! The plant here is the controller's own model, so with a continuous-time controller the error
//! would obey `ë + kd·ė + kp·e = 0` and stay at zero from a start on the reference. The only
//! error source is the zero-order hold: during a period `h` the torque is the one computed at the
//! tick, while the ideal torque `τ_d(t)` moves on. The acceleration the plant misses is
//! `∂FD/∂τ · τ̇_d · (t − t_k)`, a sawtooth whose mean over a period is
//! `(h/2) · ∂FD/∂τ · τ̇_d`. The reference is slow next to the loop's natural frequency, so the
//! error follows this forcing quasi-statically: `e ≈ (h / 2) · ∂FD/∂τ · τ̇_d / kp`
//! ([`zoh_forcing`] gives `∂FD/∂τ · τ̇_d` along a reference). The tests check the simulated
//! error against this figure.
//!
//! The scalar type is [`F`]; an `f32` build changes it and the `mechanisms` module paths.
#![no_std]

pub mod gough_stewart;
pub mod puma;

/// The scalar of the generated code and of the loop.
pub type F = f64;

/// The math the loop needs beyond `core` (through `runtime::math`: `libm` without std).
pub mod math {
    use super::F;
    /// `(sin x, cos x)`.
    pub fn sin_cos(x: F) -> (F, F) {
        runtime::math::sin_cos(x)
    }
    /// `√x`.
    pub fn sqrt(x: F) -> F {
        runtime::math::sqrt(x)
    }
}

/// Proportional and derivative gains of the computed-torque law (the same on every axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// `kp` (1/s²).
    pub kp: F,
    /// `kd` (1/s).
    pub kd: F,
}

impl Gains {
    /// Critically damped error dynamics with natural frequency `hz`: `kp = ω²`, `kd = 2ω`.
    pub fn critically_damped(hz: F) -> Gains {
        let w = 2.0 * core::f64::consts::PI as F * hz;
        Gains {
            kp: w * w,
            kd: 2.0 * w,
        }
    }
}

/// Timing of the loop: the control period and the plant's RK4 substeps per period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Control period (s); 1 kHz is `0.001`.
    pub period: F,
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
    pub max: F,
    sum_sq: F,
    count: u32,
}

impl Stats {
    /// Add one sample.
    pub fn add(&mut self, e: F) {
        // A NaN sticks, so a diverging run cannot look good.
        if e > self.max || e.is_nan() {
            self.max = e;
        }
        self.sum_sq += e * e;
        self.count += 1;
    }
    /// Root mean square of the samples (0 with none).
    pub fn rms(&self) -> F {
        if self.count == 0 {
            0.0
        } else {
            math::sqrt(self.sum_sq / self.count as F)
        }
    }
    /// Number of samples.
    pub fn count(&self) -> u32 {
        self.count
    }
}

/// `a (1 − cos ω t)` and its first three derivatives: a smooth excursion that starts at rest.
pub fn raised_cosine(a: F, w: F, t: F) -> [F; 4] {
    let (s, c) = math::sin_cos(w * t);
    [a * (1.0 - c), a * w * s, a * w * w * c, -a * w * w * w * s]
}

/// `∞`-norm of a vector.
pub fn norm_inf(v: &[F]) -> F {
    v.iter()
        .fold(0.0, |m: F, x| if x.abs() > m { x.abs() } else { m })
}

/// Max over `[0, seconds]` (sampled every `dt`) of `|∂FD/∂τ · τ̇_d|`, componentwise, given
/// `forcing(t)`, which returns that vector at `t`. See the crate docs.
pub fn zoh_forcing<const N: usize, E>(
    seconds: F,
    dt: F,
    mut forcing: impl FnMut(F) -> Result<[F; N], E>,
) -> Result<[F; N], E> {
    let mut out = [0.0; N];
    let steps = (seconds / dt) as u32;
    for k in 0..=steps {
        let f = forcing(k as F * dt)?;
        for i in 0..N {
            if f[i].abs() > out[i] {
                out[i] = f[i].abs();
            }
        }
    }
    Ok(out)
}

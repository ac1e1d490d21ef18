//! `excite`'s bounds on a tree's joints (docs/identification.md, "Exciting trajectories"):
//! where the spec gives a joint limits (TOML `limit`, URDF `<limit>`), its series is centred in
//! the range and its excursion kept inside it less a margin, its speed under the velocity
//! limit; `--q-max` and `--qd-max`, when given, bound further; joints without limits are
//! bounded by the flags (defaults 1 and 2) about zero, as before limits were read.

use codegen::spec::JointLimit;

/// The default `--q-max` (rad or m) for joints without limits.
pub const Q_MAX: f64 = 1.0;
/// The default `--qd-max` (rad/s or m/s) for joints without a velocity limit.
pub const QD_MAX: f64 = 2.0;

/// Per joint: the series' offset `c_i`, its bound on `|q_i − c_i|`, its bound on `|q̇_i|`.
#[derive(Clone, Debug, PartialEq)]
pub struct Bounds {
    /// Offsets `c_i` (0 for a joint without limits).
    pub centre: Vec<f64>,
    /// Bounds on `|q_i − c_i|`.
    pub q: Vec<f64>,
    /// Bounds on `|q̇_i|`.
    pub qd: Vec<f64>,
    /// What was used, for one line on standard error.
    pub line: String,
}

/// The bounds of `n` joints with `limits` (one per joint, `None`: none), the flags' values
/// (`q_max`, `qd_max`: one per joint when given on the command line, `None` when not) and the
/// margin (a fraction of the half range kept free at each end, in `[0, 1)`).
///
/// A joint with limits `[lower, upper]`: `c = (lower + upper) / 2` and
/// `|q − c| ≤ min((1 − margin)(upper − lower)/2, q_max)`; `|q̇| ≤ min(velocity, qd_max)`
/// (either alone when the other is absent, [`QD_MAX`] when both are). A joint without limits:
/// `c = 0`, `|q| ≤ q_max` ([`Q_MAX`] by default), `|q̇| ≤ qd_max` ([`QD_MAX`]).
pub fn tree(
    limits: &[Option<JointLimit>],
    q_max: Option<&[f64]>,
    qd_max: Option<&[f64]>,
    margin: f64,
) -> Bounds {
    let n = limits.len();
    let mut b = Bounds {
        centre: vec![0.0; n],
        q: vec![0.0; n],
        qd: vec![0.0; n],
        line: String::new(),
    };
    let mut parts = Vec::with_capacity(n);
    for (i, l) in limits.iter().enumerate() {
        let (qf, qdf) = (q_max.map(|v| v[i]), qd_max.map(|v| v[i]));
        let (q_src, qd_src);
        match l {
            None => {
                b.q[i] = qf.unwrap_or(Q_MAX);
                q_src = if qf.is_some() { "--q-max" } else { "default" };
            }
            Some(l) => {
                b.centre[i] = 0.5 * (l.lower + l.upper);
                let room = (1.0 - margin) * 0.5 * (l.upper - l.lower);
                (b.q[i], q_src) = match qf {
                    Some(f) if f < room => (f, "--q-max about the centre"),
                    _ => (room, "limit"),
                };
            }
        }
        let v = l.as_ref().and_then(|l| l.velocity);
        (b.qd[i], qd_src) = match (v, qdf) {
            (Some(v), Some(f)) if f < v => (f, "--qd-max"),
            (Some(v), _) => (v, "limit"),
            (None, Some(f)) => (f, "--qd-max"),
            (None, None) => (QD_MAX, "default"),
        };
        let name = l
            .as_ref()
            .map_or(String::new(), |l| format!(" ({})", l.joint));
        parts.push(format!(
            "q{}{name} in [{}, {}] ({q_src}), |qd| <= {} ({qd_src})",
            i + 1,
            b.centre[i] - b.q[i],
            b.centre[i] + b.q[i],
            b.qd[i]
        ));
    }
    let limited = limits.iter().filter(|l| l.is_some()).count();
    b.line = format!(
        "excite: bounds ({limited} of {n} joints with limits, margin {} of the half range): {}",
        margin,
        parts.join("; ")
    );
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lim(lower: f64, upper: f64, velocity: Option<f64>) -> Option<JointLimit> {
        Some(JointLimit {
            joint: "j".into(),
            lower,
            upper,
            velocity,
        })
    }

    #[test]
    fn limits_centre_and_flags_bound_further() {
        let l = [lim(0.2, 1.4, Some(0.5)), None, lim(-3.0, 1.0, None)];
        let b = tree(&l, None, None, 0.1);
        assert!((b.centre[0] - 0.8).abs() < 1e-15 && b.centre[1] == 0.0 && b.centre[2] == -1.0);
        assert!((b.q[0] - 0.54).abs() < 1e-15 && b.q[1] == 1.0 && b.q[2] == 1.8);
        assert_eq!(b.qd, [0.5, 2.0, 2.0]);
        let b = tree(&l, Some(&[0.3, 0.7, 5.0]), Some(&[0.4, 3.0, 1.5]), 0.1);
        assert_eq!(b.q[..2], [0.3, 0.7]);
        assert!((b.q[2] - 1.8).abs() < 1e-15);
        assert_eq!(b.qd, [0.4, 3.0, 1.5]);
        assert!(b.line.contains("2 of 3 joints"), "{}", b.line);
    }
}

//! A platform's speeds from positions-only data (`identify` with `t, x, tau`;
//! docs/identification.md, "Platforms"): the file's `x` columns are filtered and
//! differentiated as a tree's joint positions ([`super::filter`]), which gives `ẋ` and `ẍ`;
//! this turns them into the module's `(x, u, u̇)`. A platform whose `x ⊕ δ` is a sum
//! (translations, planar poses, 1T2R heads, Schönflies; docs/method.md, "nocdyn's
//! formulation") has `u = ẋ`, `u̇ = ẍ`. A turning platform's unit quaternion `q` (platform →
//! base) has `q̇ = ½ (0, ω) ⊗ q`, so `(0, ω) = 2 q̇ ⊗ q̄` (base frame) and, since
//! `q̇ ⊗ conj(q̇) = |q̇|²` is real, `(·, ω̇) = 2 q̈ ⊗ q̄`; the filtered `q` is normalized first and
//! the products divided by `|q|²`. A pose's `v` is `ṗ`.

use runtime::parallel::PlatformMotion;

use super::samples::Samples;

/// What the report's data note adds for a platform.
pub const NOTE: &str = "; u and ud from the rates of x (a quaternion's: omega = 2 vec(qd (x) conj(q)), its rate 2 vec(qdd (x) conj(q)))";

/// `q₁ ⊗ q₂` (`[w, x, y, z]`).
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// `2 vec(r ⊗ q̄) / |q|²`.
fn rate(r: [f64; 4], q: [f64; 4], n2: f64) -> [f64; 3] {
    let p = mul(r, [q[0], -q[1], -q[2], -q[3]]);
    [2.0 * p[1] / n2, 2.0 * p[2] / n2, 2.0 * p[3] / n2]
}

/// Where `motion`'s quaternion starts in `x`, if it turns.
fn quaternion_at(motion: PlatformMotion) -> Option<usize> {
    match motion {
        PlatformMotion::Pose => Some(3),
        PlatformMotion::Orientation { .. } => Some(0),
        _ => None,
    }
}

/// Replace the rates of `x` in `data` (`qd` = `ẋ`, `qdd` = `ẍ`, as the filter left them) by
/// the platform's speeds `u` and their rates, normalizing a turning platform's quaternion.
/// `Err` (at the line) where the filtered quaternion is far from unit length: the file's
/// quaternion changes sign between rows (`q` and `−q` are one orientation) or is not one.
pub fn speeds(motion: PlatformMotion, file: &str, data: &mut Samples) -> Result<(), String> {
    let Some(qi) = quaternion_at(motion) else {
        return Ok(());
    };
    for s in 0..data.q.len() {
        let x = &mut data.q[s];
        let q = [x[qi], x[qi + 1], x[qi + 2], x[qi + 3]];
        let n2 = q.iter().map(|v| v * v).sum::<f64>();
        if !(0.81..=1.21).contains(&n2) {
            return Err(format!(
                "error: {file}:{}: the filtered quaternion x{}..x{} has length {:.3}, not 1: the file's quaternion jumps (a sign change between rows: q and -q are one orientation, write it continuous) or is not a unit quaternion",
                data.lines[s],
                qi + 1,
                qi + 4,
                n2.sqrt()
            ));
        }
        let n = n2.sqrt();
        for k in 0..4 {
            x[qi + k] = q[k] / n;
        }
        let (xd, xdd) = (&data.qd[s], &data.qdd[s]);
        let qd = [xd[qi], xd[qi + 1], xd[qi + 2], xd[qi + 3]];
        let qdd = [xdd[qi], xdd[qi + 1], xdd[qi + 2], xdd[qi + 3]];
        let (w, wd) = (rate(qd, q, n2), rate(qdd, q, n2));
        let (mut u, mut ud) = (w.to_vec(), wd.to_vec());
        if qi == 3 {
            u.extend(&xd[..3]);
            ud.extend(&xdd[..3]);
        }
        data.qd[s] = u;
        data.qdd[s] = ud;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pose along a smooth path: `ω` and `ω̇` from the quaternion's exact rates against the
    /// angular velocity of the rotation matrix, `[ω]× = Ṙ Rᵀ` (central differences of `R`).
    #[test]
    fn angular_velocity_from_quaternion_rates_is_the_rotations() {
        let path = |t: f64| -> [f64; 4] {
            let a = [0.3 * t.sin(), 0.5 * t, -0.2 * (2.0 * t).cos()];
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            let (s, c) = (0.5 * n).sin_cos();
            [c, s * a[0] / n, s * a[1] / n, s * a[2] / n]
        };
        let matrix = |q: [f64; 4]| runtime::model::quaternion_matrix(&q);
        let h = 1e-4;
        let omega = |t: f64| -> [f64; 3] {
            let (rp, rm, r) = (matrix(path(t + h)), matrix(path(t - h)), matrix(path(t)));
            let rd = |i: usize, j: usize| (rp[i][j] - rm[i][j]) / (2.0 * h);
            let w = |i: usize, j: usize| (0..3).map(|k| rd(i, k) * r[j][k]).sum::<f64>();
            [w(2, 1), w(0, 2), w(1, 0)]
        };
        let t = 0.8;
        let q = path(t);
        let d = |f: &dyn Fn(f64) -> [f64; 4], t: f64| -> [f64; 4] {
            let (p, m) = (f(t + h), f(t - h));
            std::array::from_fn(|i| (p[i] - m[i]) / (2.0 * h))
        };
        let qd = d(&path, t);
        let qdd = d(&|t| d(&path, t), t);
        let mut data = Samples {
            q: vec![[&[0.1, 0.2, 0.3][..], &q].concat()],
            qd: vec![[&[1.0, 2.0, 3.0][..], &qd].concat()],
            qdd: vec![[&[4.0, 5.0, 6.0][..], &qdd].concat()],
            lines: vec![2],
            ..Default::default()
        };
        speeds(PlatformMotion::Pose, "d.csv", &mut data).unwrap();
        let (w, wp, wm) = (omega(t), omega(t + 1e-3), omega(t - 1e-3));
        for i in 0..3 {
            assert!(
                (data.qd[0][i] - w[i]).abs() < 1e-6,
                "{:?} {w:?}",
                data.qd[0]
            );
            let wd = (wp[i] - wm[i]) / 2e-3;
            assert!((data.qdd[0][i] - wd).abs() < 1e-4, "{:?} {wd}", data.qdd[0]);
        }
        assert_eq!(&data.qd[0][3..], &[1.0, 2.0, 3.0]);
        assert_eq!(&data.qdd[0][3..], &[4.0, 5.0, 6.0]);
        // A quaternion that flips sign is smeared to near zero by the filter: an error.
        data.q[0][3..].copy_from_slice(&[0.1, 0.0, 0.0, 0.1]);
        let e = speeds(PlatformMotion::Pose, "d.csv", &mut data).unwrap_err();
        assert!(e.contains("d.csv:2:") && e.contains("sign"), "{e}");
    }
}

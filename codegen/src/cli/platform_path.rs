//! A platform's state `(x, u, u̇)` from coordinates `d` around home and their first two time
//! derivatives, for `excite` (docs/identification.md, "Platforms"). Every motion whose `x ⊕ δ`
//! is a sum (translations, planar poses, 1T2R heads, Schönflies) has `x = x_home + d`,
//! `u = ḋ`, `u̇ = d̈` ([`runtime::parallel::noc::retract`]). A turning platform (`pose`,
//! `orientation`) takes its three angular coordinates as Z-Y-X angles `(a, b, c)` about the
//! base axes, composed on the left of the home orientation, `R = Rz(a) Ry(b) Rx(c) R_home`:
//! then `ω = ȧ e_z + ḃ Rz e_y + ċ Rz Ry e_x` (base frame) and its derivative are exact.

use runtime::parallel::PlatformMotion;

/// `q₁ ⊗ q₂` (`[w, x, y, z]`).
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The rotation by `angle` about axis `k` (0 x, 1 y, 2 z) as a quaternion.
fn about(k: usize, angle: f64) -> [f64; 4] {
    let (s, c) = (0.5 * angle).sin_cos();
    let mut q = [c, 0.0, 0.0, 0.0];
    q[k + 1] = s;
    q
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The orientation `Rz(a) Ry(b) Rx(c) q_home`, `ω` and `ω̇` from the angles `e = (a, b, c)`
/// and their rates.
fn turn(q_home: [f64; 4], e: &[f64], ed: &[f64], edd: &[f64]) -> ([f64; 4], [f64; 3], [f64; 3]) {
    let q = mul(
        about(2, e[0]),
        mul(about(1, e[1]), mul(about(0, e[2]), q_home)),
    );
    let (sa, ca) = e[0].sin_cos();
    let (sb, cb) = e[1].sin_cos();
    let z = [0.0, 0.0, 1.0];
    let y = [-sa, ca, 0.0];
    let x = [ca * cb, sa * cb, -sb];
    let w_zy: [f64; 3] = std::array::from_fn(|i| ed[0] * z[i] + ed[1] * y[i]);
    let w: [f64; 3] = std::array::from_fn(|i| w_zy[i] + ed[2] * x[i]);
    let dy = cross(z, y);
    let dx = cross(w_zy, x);
    let wd: [f64; 3] = std::array::from_fn(|i| {
        edd[0] * z[i] + edd[1] * y[i] + ed[1] * ed[0] * dy[i] + edd[2] * x[i] + ed[2] * dx[i]
    });
    (q, w, wd)
}

/// Whether speed `j` of `motion` is a rate of turn (rad/s).
pub fn angular(motion: PlatformMotion, j: usize) -> bool {
    match motion {
        PlatformMotion::Pose | PlatformMotion::Orientation { .. } => j < 3,
        PlatformMotion::PlanarPoint { .. } | PlatformMotion::Translation { .. } => false,
        PlatformMotion::PlanarPose { .. } => j == 2,
        PlatformMotion::HeaveTilt { .. } => j > 0,
        PlatformMotion::Schoenflies { .. } => j == 3,
    }
}

/// `(x, u, u̇)` at coordinates `d` (rates `dd`, `ddd`) around `home`.
pub fn state(
    motion: PlatformMotion,
    home: &[f64],
    d: &[f64],
    dd: &[f64],
    ddd: &[f64],
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let qi = match motion {
        PlatformMotion::Pose => 3,
        PlatformMotion::Orientation { .. } => 0,
        _ => {
            let x = home.iter().zip(d).map(|(a, b)| a + b).collect();
            return (x, dd.to_vec(), ddd.to_vec());
        }
    };
    let q_home = [home[qi], home[qi + 1], home[qi + 2], home[qi + 3]];
    let (q, w, wd) = turn(q_home, &d[..3], &dd[..3], &ddd[..3]);
    let mut x = home.to_vec();
    x[qi..qi + 4].copy_from_slice(&q);
    let (mut u, mut ud) = (w.to_vec(), wd.to_vec());
    if qi == 3 {
        for i in 0..3 {
            x[i] += d[3 + i];
        }
        u.extend(&dd[3..6]);
        ud.extend(&ddd[3..6]);
    }
    (x, u, ud)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ω` against the quaternion's rate `q̇ = ½ (0, ω) ⊗ q` (central differences), and `ω̇`
    /// against the differences of `ω`, along a smooth path of the angles.
    #[test]
    fn angular_velocity_and_acceleration_are_the_paths() {
        let home = [0.9f64, 0.1, -0.3, 0.2];
        let n = home.iter().map(|v| v * v).sum::<f64>().sqrt();
        let home = home.map(|v| v / n);
        let path = |t: f64| {
            let e = [0.3 * t.sin(), -0.2 * (2.0 * t).cos(), 0.4 * t * t];
            let ed = [0.3 * t.cos(), 0.4 * (2.0 * t).sin(), 0.8 * t];
            let edd = [-0.3 * t.sin(), 0.8 * (2.0 * t).cos(), 0.8];
            turn(home, &e, &ed, &edd)
        };
        let (t, h) = (0.7, 1e-5);
        let (q, w, wd) = path(t);
        let (qp, wp, _) = path(t + h);
        let (qm, wm, _) = path(t - h);
        let qd: [f64; 4] = std::array::from_fn(|i| (qp[i] - qm[i]) / (2.0 * h));
        let want = mul([0.0, w[0], w[1], w[2]], q).map(|v| 0.5 * v);
        for i in 0..4 {
            assert!((qd[i] - want[i]).abs() < 1e-8, "{qd:?} {want:?}");
        }
        for i in 0..3 {
            assert!(((wp[i] - wm[i]) / (2.0 * h) - wd[i]).abs() < 1e-8);
        }
    }
}

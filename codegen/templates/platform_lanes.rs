// Template: the `_lanes` functions of a platform module that solve with the actuation matrix
// `A`, around the kernels' `_lanes` versions (`id_parts_lanes`, …: the parts lane last and
// each lane's status, lane `k` what the scalar kernel returns for state `k`). The kernels'
// arithmetic runs over the lanes, and so do the solves (`lu_solve_t_lanes`,
// `lu_inverse_lanes`: each lane the scalar LU's operations, its pivots its own), so each lane
// is bit for bit the scalar function. With them
// the per-lane helpers (`lane_of`, `put_lane`, `flag_non_finite`) of every module whose
// `_lanes` functions can fail. Specialized by `codegen/src/template.rs`; compiled and tested
// as a module by `tests/tests/templates.rs`.

/// `inverse_dynamics` of `LANES` states at once: entry `[i][k]` of an argument or of the
/// result is entry `i` of state `k`, bit for bit what `inverse_dynamics` gives for that state.
///
/// The second part is each lane's status: `Err` where the scalar function returns that `Err`
/// for the lane's state (that lane's values are then not to be read); the other lanes are not
/// affected.
#[inline]
pub fn inverse_dynamics_lanes(
    x: &[[f64; LANES]; NX],
    u: &[[f64; LANES]; DOF],
    ud: &[[f64; LANES]; DOF],
    p: &Params,
) -> ([[f64; LANES]; DOF], [Result<(), Singular>; LANES]) {
    solve_t_lanes(id_parts_lanes(x, u, ud, p))
}

/// `gravity` of `LANES` states at once, lane by lane as `inverse_dynamics_lanes`.
#[inline]
pub fn gravity_lanes(
    x: &[[f64; LANES]; NX],
    p: &Params,
) -> ([[f64; LANES]; DOF], [Result<(), Singular>; LANES]) {
    solve_t_lanes(gravity_parts_lanes(x, p))
}

/// `coriolis` of `LANES` states at once, lane by lane as `inverse_dynamics_lanes`.
#[inline]
pub fn coriolis_lanes(
    x: &[[f64; LANES]; NX],
    u: &[[f64; LANES]; DOF],
    p: &Params,
) -> ([[f64; LANES]; DOF], [Result<(), Singular>; LANES]) {
    solve_t_lanes(coriolis_parts_lanes(x, u, p))
}

/// Lane `k` of a lane-last array.
#[inline]
fn lane_of<const N: usize>(v: &[[f64; LANES]; N], k: usize) -> [f64; N] {
    let mut out = [0.0; N];
    for (o, row) in out.iter_mut().zip(v) {
        if let Some(x) = row.get(k) {
            *o = *x;
        }
    }
    out
}

/// Writes `v` into lane `k` of a lane-last array.
#[inline]
fn put_lane<const N: usize>(out: &mut [[f64; LANES]; N], k: usize, v: [f64; N]) {
    for (o, x) in out.iter_mut().zip(v) {
        if let Some(o) = o.get_mut(k) {
            *o = x;
        }
    }
}

/// Marks each lane of `bad` where a lane-last array has a non-finite entry.
#[inline]
fn flag_non_finite<const N: usize>(bad: &mut [bool; LANES], v: &[[f64; LANES]; N]) {
    for row in v {
        for (b, x) in bad.iter_mut().zip(row) {
            *b |= !x.is_finite();
        }
    }
}

/// `Aᵀ τ = f` over the lanes by `lu_solve_t_lanes` (each lane the scalar `lu_solve_t`'s
/// operations); a lane it marks (a failed pivot, a non-finite result) and that the kernel
/// left `Ok` is solved again by `lu_solve_t`, whose `Err` it takes.
#[inline]
#[allow(clippy::type_complexity)]
fn solve_t_lanes(
    ((a, f), mut status): (
        ([[[f64; LANES]; DOF]; DOF], [[f64; LANES]; DOF]),
        [Result<(), Singular>; LANES],
    ),
) -> ([[f64; LANES]; DOF], [Result<(), Singular>; LANES]) {
    let mut bad = [false; LANES];
    let mut out = lu_solve_t_lanes(&a, &f, &mut bad);
    for (k, (st, bad)) in status.iter_mut().zip(bad).enumerate() {
        if !bad || st.is_err() {
            continue;
        }
        match lu_solve_t(&a.map(|row| lane_of(&row, k)), &lane_of(&f, k)) {
            Ok(t) => put_lane(&mut out, k, t),
            Err(e) => *st = Err(e),
        }
    }
    (out, status)
}

/// `actuator_mass_matrix` of `LANES` states at once, lane by lane as
/// `inverse_dynamics_lanes`: `A⁻¹` over the lanes by `lu_inverse_lanes` (a lane it marks
/// again by `lu_inverse`, for its `Err`), then `A⁻ᵀ I A⁻¹` over the lanes in the scalar
/// function's order of operations.
#[inline]
#[allow(clippy::type_complexity)]
pub fn actuator_mass_matrix_lanes(
    x: &[[f64; LANES]; NX],
    p: &Params,
) -> ([[[f64; LANES]; DOF]; DOF], [Result<(), Singular>; LANES]) {
    let ((a, i), mut status) = inertia_parts_lanes(x, p);
    let mut bad = [false; LANES];
    let mut ai = lu_inverse_lanes(&a, &mut bad);
    let im = i.map(|row| row.map(Lanes));
    for (k, (st, bad)) in status.iter_mut().zip(bad).enumerate() {
        if !bad || st.is_err() {
            continue;
        }
        match lu_inverse(&a.map(|row| lane_of(&row, k))) {
            Ok(inv) => {
                for (to, from) in ai.iter_mut().zip(inv) {
                    for (t, f) in to.iter_mut().zip(from) {
                        if let Some(t) = t.0.get_mut(k) {
                            *t = f;
                        }
                    }
                }
            }
            Err(e) => *st = Err(e),
        }
    }
    // B = I A⁻¹, then A⁻ᵀ B (upper triangle, mirrored).
    let mut b = [[Lanes::splat(0.0); DOF]; DOF];
    for r in 0..DOF {
        for c in 0..DOF {
            let mut s = Lanes::splat(0.0);
            for k in 0..DOF {
                s = s + im[r][k] * ai[k][c];
            }
            b[r][c] = s;
        }
    }
    let mut out = [[[0.0; LANES]; DOF]; DOF];
    for r in 0..DOF {
        for c in r..DOF {
            let mut s = Lanes::splat(0.0);
            for k in 0..DOF {
                s = s + ai[k][r] * b[k][c];
            }
            // The scalar function's first non-finite entry, in this order, per lane.
            for (v, st) in s.0.iter().zip(status.iter_mut()) {
                if st.is_ok() && !v.is_finite() {
                    *st = Err(Singular {
                        site: Site::Input,
                        value: *v,
                        condition_estimate: f64::INFINITY,
                    });
                }
            }
            out[r][c] = s.0;
            out[c][r] = s.0;
        }
    }
    (out, status)
}

//! The least squares of the spec update (docs/identification.md, "The updated spec"): the
//! map `P` from the update's unknowns to the base parameters, and the minimum-norm change of
//! the unknowns towards the identified base parameters, the late unknowns (crosses, a payload)
//! taking only what the others cannot reach.

use nalgebra::{DMatrix, DVector};

/// The minimum-norm change of the unknowns and the map it was found on.
pub(super) struct Change {
    /// `P`: base parameters per unit of each unknown.
    pub p: DMatrix<f64>,
    /// The unknowns changed.
    pub z: Vec<f64>,
    /// The change.
    pub dz: DVector<f64>,
    /// The base parameters that no unknown moves.
    pub unreachable: Vec<usize>,
}

/// The base parameters of the spec with its unknowns set to the values given.
type BaseOf<'a> = dyn FnMut(&[f64]) -> Result<Vec<f64>, String> + 'a;

/// `Δ = P⁺ (π̂ − π0)` over the `fit` base parameters, `P` by moving each unknown by one from
/// `reference` (`base` gives the base parameters of the spec with the unknowns set). The `late`
/// unknowns (a payload, the crosses) take only what the others cannot reach, with their own
/// minimum-norm change; the others' minimum-norm change takes the rest.
#[allow(clippy::too_many_arguments)]
pub(super) fn minimum_norm_change(
    nbp: usize,
    z0: &[f64],
    reference: &[f64],
    pi0: &[f64],
    target: &[f64],
    fit: &[bool],
    late: &[bool],
    base: &mut BaseOf<'_>,
) -> Result<Change, String> {
    let mut p = DMatrix::zeros(nbp, z0.len());
    let pi_ref = base(reference)?;
    for c in 0..z0.len() {
        let mut z = reference.to_vec();
        z[c] += 1.0;
        let pi = base(&z)?;
        for r in 0..nbp {
            p[(r, c)] = pi[r] - pi_ref[r];
        }
    }
    // Rounding noise of the differences (the exact entries are sums of grouping coefficients).
    let pmax = p.amax();
    p.apply(|x| {
        if x.abs() <= 1e-12 * pmax {
            *x = 0.0
        }
    });
    let unreachable: Vec<usize> = (0..nbp)
        .filter(|&r| p.row(r).iter().all(|x| *x == 0.0))
        .collect();
    let d = DVector::from_fn(nbp, |k, _| {
        if fit[k] && !unreachable.contains(&k) {
            target[k] - pi0[k]
        } else {
            0.0
        }
    });
    // Lexicographic: the late unknowns (crosses, the payload) take what the others cannot
    // reach, `Q d` with `Q = 1 − P_e P_e⁺` the projection off the others' range, with their
    // minimum-norm change (`(Q P_l)⁺ Q d`, so they change only as much as that needs); the
    // others then take the rest, `P_e⁺ (d − P_l Δ_l)`. The residual is the least any change
    // leaves, and a late unknown moves nothing its neighbours can.
    let tol = 1e-12 * p.norm().max(f64::MIN_POSITIVE);
    let stage = |late_stage: bool| {
        let mut ps = p.clone();
        for (c, &l) in late.iter().enumerate() {
            if l != late_stage {
                ps.column_mut(c).fill(0.0);
            }
        }
        ps
    };
    let pinv = |m: DMatrix<f64>| {
        m.pseudo_inverse(tol)
            .map_err(|e| format!("error: the update's least squares failed: {e}"))
    };
    let (pe, pl) = (stage(false), stage(true));
    let pe_pinv = pinv(pe.clone())?;
    let mut dz = DVector::zeros(z0.len());
    if pl.amax() == 0.0 {
        dz += &pe_pinv * &d;
    } else {
        // `Q` from an orthonormal basis of the others' range (left singular vectors), which
        // keeps what `Q` removes at rounding size however ill-conditioned `P_e` is.
        let svd = pe.clone().svd(true, false);
        let u = svd
            .u
            .ok_or("error: the update's least squares failed: no SVD")?;
        let keep: Vec<usize> = (0..svd.singular_values.len())
            .filter(|&k| svd.singular_values[k] > tol)
            .collect();
        let ur = u.select_columns(&keep);
        let q = |m: &DMatrix<f64>| m - &ur * (ur.transpose() * m);
        let mut qpl = q(&pl);
        // A late unknown whose column the others' range holds (to rounding) moves nothing
        // they cannot: it stays (else rounding would give it a step, e.g. a cross's inertia).
        for mut c in qpl.column_iter_mut() {
            if c.norm() <= tol {
                c.fill(0.0);
            }
        }
        let qpl_pinv = pinv(qpl)?;
        let tiny = 1e-10 * d.amax();
        // The late unknowns' step towards `rest`: what the others leave to rounding is nothing
        // for them to take up; a row the others cannot move keeps its target whole, however
        // small (a cross's first moment identified near zero). The SVD's rounding in the
        // entries the step does not use (a cross's inertia when only its first moment moves)
        // is none, so that no cross gets a noise-sized inertia.
        let late_step = |rest: &DVector<f64>| {
            let mut qd = q(&DMatrix::from_column_slice(nbp, 1, rest.as_slice()))
                .column(0)
                .into_owned();
            for r in 0..nbp {
                if qd[r].abs() <= tiny && pe.row(r).iter().any(|x| *x != 0.0) {
                    qd[r] = 0.0;
                }
            }
            let mut step = &qpl_pinv * qd;
            let big = step.amax();
            step.apply(|x| {
                if x.abs() <= 1e-12 * big {
                    *x = 0.0
                }
            });
            step
        };
        dz += late_step(&d);
        dz += &pe_pinv * (&d - &p * &dz);
        // The others' rounding on the rows only the late unknowns reach.
        dz += late_step(&(&d - &p * &dz));
    }
    // An unknown that moves no base parameter stays as written (the SVD leaves rounding
    // noise there).
    for c in 0..z0.len() {
        if p.column(c).iter().all(|x| *x == 0.0) {
            dz[c] = 0.0;
        }
    }
    let z: Vec<f64> = z0.iter().zip(dz.iter()).map(|(a, b)| a + b).collect();
    Ok(Change {
        p,
        z,
        dz,
        unreachable,
    })
}

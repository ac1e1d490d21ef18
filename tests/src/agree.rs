//! Two modules of one mechanism generated with different options (`Config::fma`,
//! `Config::batch_sin_cos`) agree: the largest relative difference of their dynamics functions
//! on random states.

use mechanisms::Dynamics;
use rand::Rng;

use crate::pkm::rel;

/// A matrix's entries, row by row.
pub fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// The largest relative difference of every dynamics function (inverse and forward dynamics,
/// mass matrix, the derivatives of inverse dynamics where the module has them) between two
/// modules of one mechanism, `plain` and `other` (generated with different options), at
/// `states` random states near home (actuated joints moved by up to `spread`, then the
/// configuration found by forward kinematics; `x = q` for a tree).
pub fn worst<A, B, const NX: usize, const N: usize>(
    plain: &A,
    other: &B,
    states: usize,
    spread: f64,
    seed: u64,
) -> f64
where
    A: Dynamics<NX, N, Scalar = f64>,
    B: Dynamics<NX, N, Scalar = f64>,
{
    let mut r = crate::rng(seed);
    let q0 = plain.inverse_kinematics(&A::HOME).expect("home is regular");
    let mut worst = 0.0_f64;
    let mut n = 0;
    while n < states {
        let q: [f64; N] = core::array::from_fn(|i| q0[i] + r.random_range(-spread..spread));
        let u: [f64; N] = core::array::from_fn(|_| r.random_range(-1.0..1.0));
        let ud: [f64; N] = core::array::from_fn(|_| r.random_range(-2.0..2.0));
        let Ok(x) = plain.forward_kinematics(&q, &A::HOME) else {
            continue;
        };
        let (Ok(tau), Ok(m)) = (plain.inverse_dynamics(&x, &u, &ud), plain.mass_matrix(&x)) else {
            continue;
        };
        n += 1;
        let tau_o = other.inverse_dynamics(&x, &u, &ud).expect("other ID");
        worst = worst.max(rel(&tau_o, &tau));
        worst = worst.max(rel(
            &flat(&other.mass_matrix(&x).expect("other M")),
            &flat(&m),
        ));
        let fd = plain.forward_dynamics(&x, &u, &tau).expect("FD");
        let fd_o = other.forward_dynamics(&x, &u, &tau).expect("other FD");
        worst = worst.max(rel(&fd_o, &fd));
        if let (Some(Ok((a, b))), Some(Ok((ao, bo)))) = (
            plain.inverse_dynamics_derivatives(&x, &u, &ud),
            other.inverse_dynamics_derivatives(&x, &u, &ud),
        ) {
            worst = worst.max(rel(&flat(&ao), &flat(&a)));
            worst = worst.max(rel(&flat(&bo), &flat(&b)));
        }
    }
    worst
}

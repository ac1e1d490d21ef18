//! Base (identifiable) parameters from the standard regressor (docs/method.md,
//! "Identification: the regressor and base parameters"): the standard columns are evaluated at
//! deterministic pseudo-random states and scanned in order (bodies from the base outwards, each
//! body's `XX … M`, then its joint's drive parameters). A column that is a combination of the
//! columns kept before it is dropped and its parameter grouped into theirs with the
//! coefficients of that combination, found by least squares and snapped to exact integers
//! (zero, ±1) when they are within rounding of one; a column that is zero at every state
//! drops out. This is Khalil & Kleinfinger's regrouping where it applies (the child's mass,
//! axial first moment and one transverse inertia into the parent; the rotor inertia of the
//! first joint into its body's `ZZ`) and finds, in the same pass, the special cases their
//! rules leave to inspection (parallel axes, joints near the base).

use crate::sym::{Arg, ExprId, Graph};

use super::regressor::Standard;

/// The base parameters of a tree: the kept standard columns and what each groups.
#[derive(Clone, Debug)]
pub struct Base {
    /// Per base parameter: the index of the standard column it keeps.
    pub kept: Vec<usize>,
    /// Per base parameter: `(standard index, coefficient)` of the parameters it groups, the
    /// kept one first with coefficient 1.
    pub groups: Vec<Vec<(usize, f64)>>,
    /// The spec's values: `Σ coefficient · standard value` per group.
    pub values: Vec<f64>,
    /// Human-readable groups, e.g. `"ZZ_link2 + 0.0432*M_link3"`.
    pub names: Vec<String>,
}

/// A column whose norm is at most this times the largest column norm is zero.
const ZERO: f64 = 1e-10;
/// A column whose part outside the kept columns' span is at most this times its norm depends
/// on them.
const DEPENDENT: f64 = 1e-7;
/// A coefficient whose distance to an integer, times its column's norm, is at most this times
/// the grouped column's norm is that integer.
const SNAP: f64 = 1e-10;

/// Deterministic pseudo-random numbers in `[-1, 1)` (SplitMix64).
pub struct Stream(u64);

impl Stream {
    /// The next number.
    pub fn draw(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// One state's inputs, drawn from the stream: `(argument, values)` pairs.
pub type State = Vec<(Arg, Vec<f64>)>;

/// The standard columns evaluated at `states` states drawn by `draw`: `cols[k][row]`, rows
/// state-major (`n` rows per state). A state where a column is not finite (a failed guard:
/// out of reach, singular) is drawn again, at most `20 · states` draws in all.
fn sample(
    g: &Graph,
    std: &Standard,
    n: usize,
    states: usize,
    draw: &mut dyn FnMut(&mut Stream) -> State,
) -> Vec<Vec<f64>> {
    let roots: Vec<ExprId> = std.columns.iter().flatten().copied().collect();
    let mut cols = vec![Vec::with_capacity(states * n); std.columns.len()];
    let mut r = Stream(0x6e6f_6364_796e);
    let mut taken = 0;
    for _ in 0..20 * states {
        if taken == states {
            break;
        }
        let state = draw(&mut r);
        let input = |a: Arg, i: usize| {
            state
                .iter()
                .find(|(b, _)| *b == a)
                .map_or(f64::NAN, |(_, v)| v[i])
        };
        let v = g.eval(&roots, &input);
        if !v.iter().all(|x| x.is_finite()) {
            continue;
        }
        for (k, col) in cols.iter_mut().enumerate() {
            col.extend_from_slice(&v[k * n..(k + 1) * n]);
        }
        taken += 1;
    }
    cols
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Modified Gram–Schmidt of the kept columns, with the triangular factor `R`.
struct Qr {
    q: Vec<Vec<f64>>,
    r: Vec<Vec<f64>>,
}

impl Qr {
    /// `Qᵀ c` (twice, for orthogonality to rounding) and what is left of `c`.
    fn project(&self, c: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut rest = c.to_vec();
        let mut coef = vec![0.0; self.q.len()];
        for _ in 0..2 {
            for (k, qk) in self.q.iter().enumerate() {
                let t = dot(qk, &rest);
                coef[k] += t;
                rest.iter_mut().zip(qk).for_each(|(x, y)| *x -= t * y);
            }
        }
        (coef, rest)
    }

    /// The least-squares coefficients of `c` on the kept columns, `R⁻¹ Qᵀ c`.
    fn solve(&self, c: &[f64]) -> Vec<f64> {
        let (mut y, _) = self.project(c);
        for i in (0..y.len()).rev() {
            let s: f64 = (i + 1..y.len()).map(|k| self.r[i][k] * y[k]).sum();
            y[i] = (y[i] - s) / self.r[i][i];
        }
        y
    }
}

/// The base parameters of a tree's standard regressor `std` (built on `g`) at random states:
/// joint `i` within `±q_scale[i]` (π for revolute joints), speeds and accelerations in
/// `[-2, 2)`.
pub fn base_parameters(g: &Graph, std: &Standard, q_scale: &[f64]) -> Base {
    let n = q_scale.len();
    base_parameters_with(g, std, n, &mut |r| {
        let q: Vec<f64> = q_scale.iter().map(|s| s * r.draw()).collect();
        let qd: Vec<f64> = (0..n).map(|_| 2.0 * r.draw()).collect();
        let qdd: Vec<f64> = (0..n).map(|_| 2.0 * r.draw()).collect();
        vec![(Arg::Q, q), (Arg::Qd, qd), (Arg::Qdd, qdd)]
    })
}

/// The base parameters of the standard regressor `std` (built on `g`, `n` rows per state) at
/// the states `draw` gives.
pub fn base_parameters_with(
    g: &Graph,
    std: &Standard,
    n: usize,
    draw: &mut dyn FnMut(&mut Stream) -> State,
) -> Base {
    let ncols = std.columns.len();
    let states = 3 * ncols / n.max(1) + 12;
    let cols = sample(g, std, n, states, draw);
    let norms: Vec<f64> = cols.iter().map(|c| norm(c)).collect();
    let largest = norms.iter().copied().fold(0.0, f64::max);
    let mut qr = Qr {
        q: Vec::new(),
        r: Vec::new(),
    };
    let mut kept: Vec<usize> = Vec::new();
    let mut dependent: Vec<usize> = Vec::new();
    for (k, c) in cols.iter().enumerate() {
        if norms[k] <= ZERO * largest {
            continue;
        }
        let (coef, rest) = qr.project(c);
        let left = norm(&rest);
        if left > DEPENDENT * norms[k] {
            for (row, &x) in qr.r.iter_mut().zip(&coef) {
                row.push(x);
            }
            let mut row = vec![0.0; kept.len()];
            row.push(left);
            qr.r.push(row);
            qr.q.push(rest.iter().map(|x| x / left).collect());
            kept.push(k);
        } else {
            dependent.push(k);
        }
    }
    let mut groups: Vec<Vec<(usize, f64)>> = kept.iter().map(|&k| vec![(k, 1.0)]).collect();
    for &d in &dependent {
        let mut beta = qr.solve(&cols[d]);
        // One step of refinement on the residual.
        let mut res = cols[d].clone();
        for (b, &k) in beta.iter().zip(&kept) {
            res.iter_mut().zip(&cols[k]).for_each(|(x, y)| *x -= b * y);
        }
        let delta = qr.solve(&res);
        beta.iter_mut().zip(&delta).for_each(|(b, e)| *b += e);
        for (i, b) in beta.into_iter().enumerate() {
            let round = b.round();
            let b = if (b - round).abs() * norms[kept[i]] <= SNAP * norms[d] {
                round
            } else {
                b
            };
            if b != 0.0 {
                groups[i].push((d, b));
            }
        }
    }
    let values = groups
        .iter()
        .map(|gr| gr.iter().map(|&(k, c)| c * std.values[k]).sum())
        .collect();
    let names = groups.iter().map(|gr| group_name(std, gr)).collect();
    Base {
        kept,
        groups,
        values,
        names,
    }
}

/// `"ZZ_link2 + 0.0432*M_link3 - MX_link3"`: coefficients to six significant digits.
fn group_name(std: &Standard, group: &[(usize, f64)]) -> String {
    let mut s = String::new();
    for (i, &(k, c)) in group.iter().enumerate() {
        let name = &std.names[k];
        let sign = if c < 0.0 { "-" } else { "+" };
        if i == 0 {
            s.push_str(name);
            continue;
        }
        let a = c.abs();
        if a == 1.0 {
            s.push_str(&format!(" {sign} {name}"));
        } else {
            let short: f64 = format!("{a:.5e}").parse().unwrap_or(a);
            s.push_str(&format!(" {sign} {short}*{name}"));
        }
    }
    s
}

/// The regressor of a tree over its base parameters, in the DAG.
#[derive(Clone, Debug)]
pub struct Regressor {
    /// `Y_b(q, q̇, q̈)`, `DOF × NBP` nodes row-major: `τ = Y_b · values`.
    pub outputs: Vec<ExprId>,
    /// The base parameters.
    pub base: Base,
    /// The standard parameters they group (names and values; the columns are in the DAG).
    pub standard: Standard,
}

/// Builds the standard regressor of `model` on `tree` in `g`, finds the base parameters and
/// returns the regressor over them.
pub fn regressor(g: &mut Graph, tree: &super::Tree, model: &runtime::model::Model) -> Regressor {
    let standard = super::regressor::standard_regressor(g, tree, model);
    let q_scale: Vec<f64> = model
        .joints
        .iter()
        .map(|j| match j.kind {
            runtime::model::JointKind::Revolute => std::f64::consts::PI,
            runtime::model::JointKind::Prismatic => 0.5,
        })
        .collect();
    let base = base_parameters(g, &standard, &q_scale);
    let n = model.dof();
    let mut outputs = Vec::with_capacity(n * base.kept.len());
    for i in 0..n {
        outputs.extend(base.kept.iter().map(|&k| standard.columns[k][i]));
    }
    Regressor {
        outputs,
        base,
        standard,
    }
}

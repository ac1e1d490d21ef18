//! The CLI's tape evaluated over lanes (`codegen/src/cli/tape_lanes.rs`) against the same tape
//! evaluated one state at a time (`Tape::eval`, `GuardedTape::eval`, the route `identify` and
//! `excite` took before): every lane bit for bit its state's scalar value, on the base
//! regressors of a tree (PUMA 560), a platform (Gough–Stewart) and a closed loop (four-bar), at
//! random states, with lanes that trip a guard, lanes of `NaN` and of `inf`, at 4 and 8 lanes.
//! The reference is the scalar evaluator, an independent loop over the same operations.

#[allow(dead_code)]
#[path = "../src/cli/tape.rs"]
mod tape;
#[allow(dead_code)]
#[path = "../src/cli/tape_lanes.rs"]
mod tape_lanes;

use codegen::spec::{Mechanism, SceneOverrides};
use codegen::sym::{Arg, Graph};
use tape::{GuardedTape, Tape};
use tape_lanes::LaneScratch;

/// A bundled spec's mechanism.
fn load(file: &str) -> Mechanism {
    let path = format!("{}/../mechanisms/specs/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("bundled spec");
    codegen::spec::load(file, &text, &SceneOverrides::default())
        .expect("bundled spec loads")
        .mechanism
}

/// xorshift64*: uniform in `[lo, hi)`.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

/// Bit for bit, `NaN` included (the same operations give the same `NaN`).
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

/// The states `[x, u, u̇]` (or `[q, q̇, q̈]`) of lanes `0..L`, lane last.
fn lanes<const L: usize>(states: &[[Vec<f64>; 3]]) -> [Vec<[f64; L]>; 3] {
    std::array::from_fn(|w| {
        (0..states[0][w].len())
            .map(|i| std::array::from_fn(|k| states[k][w][i]))
            .collect()
    })
}

/// Groups of `L` states: each lane against the scalar evaluation; how many lanes failed.
fn check_guarded<const L: usize>(t: &GuardedTape, states: &[[Vec<f64>; 3]]) -> usize {
    let (mut buf, mut scratch) = (Vec::new(), LaneScratch::<L>::default());
    let mut failed = 0;
    for group in states.chunks_exact(L) {
        let [x, u, ud] = lanes::<L>(group);
        let (out, ok) = t.eval_lanes(&x, &u, &ud, &mut scratch);
        for (k, s) in group.iter().enumerate() {
            let want = t.eval(&s[0], &s[1], &s[2], &mut buf);
            assert_eq!(ok[k], want.is_some(), "lane {k} of {L}: guards");
            let Some(want) = want else {
                failed += 1;
                continue;
            };
            assert_eq!(out.len(), want.len());
            for (i, (o, w)) in out.iter().zip(&want).enumerate() {
                assert!(
                    same(o[k], *w),
                    "lane {k} of {L}, output {i}: {} vs {w}",
                    o[k]
                );
            }
        }
    }
    failed
}

/// `state` with one value replaced by `v` (a `NaN` or `inf` lane).
fn poisoned(state: &[Vec<f64>; 3], which: usize, v: f64) -> [Vec<f64>; 3] {
    let mut s = state.clone();
    s[which][0] = v;
    s
}

#[test]
fn tree_regressor_lanes_are_the_scalar_tape() {
    let Mechanism::Tree(model) = load("puma560.toml") else {
        panic!("a tree")
    };
    let tree = codegen::dynamics::Tree::new(&model);
    let mut g = Graph::new();
    let r = codegen::dynamics::regressor(&mut g, &tree, &model);
    let t = Tape::new(&g, &r.outputs);
    let n = model.dof();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut states: Vec<[Vec<f64>; 3]> = (0..40)
        .map(|_| {
            std::array::from_fn(|w| {
                (0..n)
                    .map(|_| rng.uniform(-3.0, 3.0) * (w + 1) as f64)
                    .collect()
            })
        })
        .collect();
    // Joint 1's angle (about the vertical) is not in the regressor: joint 2's is.
    states[5][0][1] = f64::NAN;
    states[10] = poisoned(&states[10], 1, f64::INFINITY);
    states[19] = poisoned(&states[19], 2, f64::NEG_INFINITY);
    let check = |l: usize, group: &[[Vec<f64>; 3]], got: &dyn Fn(usize, usize) -> f64| {
        let mut buf = Vec::new();
        let mut want = vec![0.0; r.outputs.len()];
        for (k, s) in group.iter().enumerate() {
            let input = |a: Arg, i: usize| match a {
                Arg::Q => s[0][i],
                Arg::Qd => s[1][i],
                Arg::Qdd => s[2][i],
                _ => f64::NAN,
            };
            t.eval(&input, &mut buf, &mut want);
            for (i, w) in want.iter().enumerate() {
                assert!(same(got(k, i), *w), "lane {k} of {l}, output {i}");
            }
        }
    };
    let mut poisoned_lanes = 0;
    let mut out4 = vec![[0.0; 4]; r.outputs.len()];
    let mut out8 = vec![[0.0; 8]; r.outputs.len()];
    let mut buf4 = Vec::new();
    let mut buf8 = Vec::new();
    for group in states.chunks_exact(4) {
        let [q, qd, qdd] = lanes::<4>(group);
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            _ => [f64::NAN; 4],
        };
        t.eval_lanes(&input, &mut buf4, &mut out4);
        check(4, group, &|k, i| out4[i][k]);
        poisoned_lanes += (0..4)
            .filter(|&k| out4.iter().any(|v| !v[k].is_finite()))
            .count();
    }
    for group in states.chunks_exact(8) {
        let [q, qd, qdd] = lanes::<8>(group);
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            _ => [f64::NAN; 8],
        };
        t.eval_lanes(&input, &mut buf8, &mut out8);
        check(8, group, &|k, i| out8[i][k]);
    }
    // The poisoned lanes do poison their own outputs (and only theirs: checked above).
    assert_eq!(poisoned_lanes, 3, "the NaN and inf lanes");
}

/// A platform's regressor kernel at random states around home (`reach` the largest offset,
/// every fifth state `far` instead), three of them poisoned; the lanes that failed.
fn platform(file: &str, reach: f64, far: f64) -> usize {
    let Mechanism::Parallel(model) = load(file) else {
        panic!("a platform")
    };
    let plan = runtime::parallel::noc::Plan::new(&model).expect("plan");
    let k = codegen::parallel::kernels_for(
        &model,
        &plan,
        &codegen::parallel::Layout::default(),
        &[],
        true,
    )
    .expect("kernels");
    let t = GuardedTape::new(&k.graph, &k.regressor.expect("a regressor").kernel);
    let (home, n) = (model.home_x(), model.dof());
    let mut rng = Rng(7);
    let mut states: Vec<[Vec<f64>; 3]> = (0..48)
        .map(|s| {
            let r = if s % 5 == 3 { far } else { reach };
            let du: Vec<f64> = (0..n).map(|_| rng.uniform(-r, r)).collect();
            let x = runtime::parallel::noc::retract(model.motion, &home, &du);
            [
                x,
                (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect(),
                (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect(),
            ]
        })
        .collect();
    states[6] = poisoned(&states[6], 0, f64::NAN);
    states[9] = poisoned(&states[9], 1, f64::INFINITY);
    states[14] = poisoned(&states[14], 2, f64::NAN);
    let failed4 = check_guarded::<4>(&t, &states);
    let failed8 = check_guarded::<8>(&t, &states);
    assert_eq!(failed4, failed8);
    failed4
}

#[test]
fn platform_regressor_lanes_are_the_scalar_tape() {
    // The Gough–Stewart's legs reach any pose: only the `NaN` position fails its guards.
    assert_eq!(platform("gough_stewart.toml", 0.05, 0.1), 1);
    // The Delta's arms do not: the states a metre off home fail theirs, lane by lane.
    let failed = platform("delta_rl5.toml", 0.05, 1.0);
    assert!(
        failed >= 5,
        "lanes out of reach trip their guards ({failed})"
    );
    assert!(failed < 20, "the others do not ({failed})");
}

#[test]
fn closed_loop_regressor_lanes_are_the_scalar_tape() {
    let Mechanism::Closed(model) = load("four_bar.toml") else {
        panic!("a closed loop")
    };
    let plan = runtime::closed::noc::Plan::new(&model).expect("plan");
    let k = codegen::closed::kernels_for(&model, &plan, &[], true).expect("kernels");
    let t = GuardedTape::new(&k.graph, &k.regressor.expect("a regressor").kernel);
    let (home, n) = (plan.home(), plan.dof());
    let independent: Vec<f64> = plan.independent.iter().map(|&j| home[j]).collect();
    let mut rng = Rng(11);
    let mut x = home.clone();
    let mut states: Vec<[Vec<f64>; 3]> = (0..32)
        .map(|s| {
            let q: Vec<f64> = independent
                .iter()
                .map(|h| h + rng.uniform(-0.3, 0.3))
                .collect();
            x = runtime::closed::noc::newton_assembly(&plan, &q, &x).expect("assembles");
            let mut xs = x.clone();
            // Every seventh state a configuration that does not close (any coordinates).
            if s % 7 == 2 {
                xs.iter_mut().for_each(|v| *v = rng.uniform(-10.0, 10.0));
            }
            [
                xs,
                (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect(),
                (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect(),
            ]
        })
        .collect();
    states[3] = poisoned(&states[3], 0, f64::NAN);
    states[12] = poisoned(&states[12], 1, f64::INFINITY);
    states[21] = poisoned(&states[21], 2, f64::NEG_INFINITY);
    let failed4 = check_guarded::<4>(&t, &states);
    let failed8 = check_guarded::<8>(&t, &states);
    assert_eq!(failed4, failed8);
    assert!(failed4 >= 1, "the NaN position trips a guard ({failed4})");
}

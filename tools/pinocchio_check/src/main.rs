mod robots {
    include!(concat!(env!("OUT_DIR"), "/all.rs"));
}

mod rel;
use rel::rel;

macro_rules! check {
    ($m:ident) => {{
        use robots::$m as g;
        const N: usize = g::DOF;
        let text = std::fs::read_to_string(concat!("data/", stringify!($m), ".txt")).unwrap();
        let mut lines = text.lines();
        let pin_names: Vec<&str> = lines.next().unwrap().split(' ').collect();
        assert_eq!(pin_names.len(), N, "{} joint count", stringify!($m));
        // perm[k] = our index of Pinocchio's joint k
        let perm: Vec<usize> = pin_names.iter().map(|n| g::JOINT_NAMES.iter().position(|m| m == n).expect("name")).collect();
        let (mut eid, mut emm, mut efd) = (0.0f64, 0.0f64, 0.0f64);
        let mut t_gen = std::time::Duration::ZERO;
        let mut count = 0;
        for line in lines {
            let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            let take = |k: usize| -> [f64; N] {
                let mut o = [0.0; N];
                for i in 0..N { o[perm[i]] = v[k * N + i]; }
                o
            };
            let (q, qd, qdd, tau) = (take(0), take(1), take(2), take(3));
            let mut mp = [[0.0; N]; N];
            for i in 0..N { for j in 0..N { mp[perm[i]][perm[j]] = v[4 * N + i * N + j]; } }
            let off = 4 * N + N * N;
            let mut t2 = [0.0; N];
            let mut fdp = [0.0; N];
            for i in 0..N { t2[perm[i]] = v[off + i]; fdp[perm[i]] = v[off + N + i]; }
            let t0 = std::time::Instant::now();
            let id = std::hint::black_box(g::inverse_dynamics(&q, &qd, &qdd));
            t_gen += t0.elapsed();
            let mm = g::mass_matrix(&q);
            let fd = g::forward_dynamics(&q, &qd, &t2).unwrap();
            eid = eid.max(rel(&id, &tau));
            emm = emm.max(rel(mm.as_flattened(), mp.as_flattened()));
            efd = efd.max(rel(&fd, &fdp));
            count += 1;
        }
        let _ = t_gen;
        // Timing: median over 31 batches of all states, ns per call (as tools/pinocchio_check/bench.cpp).
        let states: Vec<([f64; N], [f64; N], [f64; N])> = text
            .lines()
            .skip(1)
            .map(|line| {
                let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
                let take = |k: usize| -> [f64; N] {
                    let mut o = [0.0; N];
                    for i in 0..N { o[perm[i]] = v[k * N + i]; }
                    o
                };
                (take(0), take(1), take(2))
            })
            .collect();
        let time = |f: &dyn Fn(&([f64; N], [f64; N], [f64; N])) -> f64| {
            let mut t: Vec<f64> = (0..31)
                .map(|_| {
                    let t0 = std::time::Instant::now();
                    let mut sink = 0.0;
                    for s in &states { sink += f(std::hint::black_box(s)); }
                    std::hint::black_box(sink);
                    t0.elapsed().as_nanos() as f64 / states.len() as f64
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[15]
        };
        let tid = time(&|(q, qd, qdd)| g::inverse_dynamics(q, qd, qdd)[0]);
        let tmm = time(&|(q, _, _)| g::mass_matrix(q)[0][0]);
        let tfd = time(&|(q, qd, qdd)| g::forward_dynamics(q, qd, qdd).map(|a| a[0]).unwrap_or(0.0));
        println!("{:16} dof {:2}  ID {:.1e}  M {:.1e}  FD {:.1e}  ({} states)  ns: ID {:.0} M {:.0} FD {:.0}", stringify!($m), N, eid, emm, efd, count, tid, tmm, tfd);
    }};
}

/// The derivatives (robots with <= 16 DOF; `data/NAME.deriv.txt` from gen.py): worst relative
/// error of each matrix against Pinocchio's computeRNEADerivatives / computeABADerivatives over
/// all states, and ns per call of inverse_dynamics, its derivatives and forward dynamics'
/// derivatives (median of 31 batches over the states, as `check!`; the whole result through
/// `black_box`).
macro_rules! check_deriv {
    ($m:ident) => {{
        use robots::$m as g;
        const N: usize = g::DOF;
        let text = std::fs::read_to_string(concat!("data/", stringify!($m), ".deriv.txt")).unwrap();
        let mut lines = text.lines();
        let pin_names: Vec<&str> = lines.next().unwrap().split(' ').collect();
        assert_eq!(pin_names.len(), N, "{} joint count", stringify!($m));
        let perm: Vec<usize> = pin_names.iter().map(|n| g::JOINT_NAMES.iter().position(|m| m == n).expect("name")).collect();
        // [∂τ/∂q, ∂τ/∂q̇, ∂q̈/∂q, ∂q̈/∂q̇, M⁻¹]
        let mut err = [0.0f64; 5];
        let mut states: Vec<([f64; N], [f64; N], [f64; N], [f64; N])> = Vec::new();
        for line in lines {
            let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            let take = |k: usize| -> [f64; N] {
                let mut o = [0.0; N];
                for i in 0..N { o[perm[i]] = v[k * N + i]; }
                o
            };
            let mat = |k: usize| -> [[f64; N]; N] {
                let off = 4 * N + k * N * N;
                let mut o = [[0.0; N]; N];
                for i in 0..N { for j in 0..N { o[perm[i]][perm[j]] = v[off + i * N + j]; } }
                o
            };
            let (q, qd, qdd, t2) = (take(0), take(1), take(2), take(3));
            let (dq, dv) = g::inverse_dynamics_derivatives(&q, &qd, &qdd);
            let (fq, fv, mi) = g::forward_dynamics_derivatives(&q, &qd, &t2).unwrap();
            for (k, ours) in [dq, dv, fq, fv, mi].iter().enumerate() {
                err[k] = err[k].max(rel(ours.as_flattened(), mat(k).as_flattened()));
            }
            states.push((q, qd, qdd, t2));
        }
        let time = |f: &dyn Fn(&([f64; N], [f64; N], [f64; N], [f64; N])) -> f64| {
            let mut t: Vec<f64> = (0..31)
                .map(|_| {
                    let t0 = std::time::Instant::now();
                    let mut sink = 0.0;
                    for s in &states { sink += f(std::hint::black_box(s)); }
                    std::hint::black_box(sink);
                    t0.elapsed().as_nanos() as f64 / states.len() as f64
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[15]
        };
        // black_box on the whole result: every entry is computed, none left out by inlining.
        let tid = time(&|(q, qd, qdd, _)| std::hint::black_box(g::inverse_dynamics(q, qd, qdd))[0]);
        let tidd = time(&|(q, qd, qdd, _)| std::hint::black_box(g::inverse_dynamics_derivatives(q, qd, qdd)).0[0][0]);
        let tfdd = time(&|(q, qd, _, t2)| {
            std::hint::black_box(g::forward_dynamics_derivatives(q, qd, t2)).map(|(a, _, _)| a[0][0]).unwrap_or(0.0)
        });
        println!(
            "{:16} dof {:2}  dID/dq {:.1e} dID/dv {:.1e}  dFD/dq {:.1e} dFD/dv {:.1e} Minv {:.1e}  ({} states)  ns: ID {:.0} IDD {:.0} FDD {:.0}",
            stringify!($m), N, err[0], err[1], err[2], err[3], err[4], states.len(), tid, tidd, tfdd
        );
    }};
}

/// Generated code without and with fused multiply-adds (`robots::NAME`, `robots::fma::NAME`), and
/// with both fused multiply-adds and the joint angles' `sin_cos` in one call
/// (`robots::batch::NAME`), on the arms, for the table beside Pinocchio's CppADCodeGen code
/// (`bench_cg.cpp`): the FMA and batched variants' worst relative errors against Pinocchio (ID,
/// M, ∂ID), then ns per call of
/// inverse_dynamics, mass_matrix, inverse_dynamics_derivatives and forward_dynamics_derivatives
/// of each (median of 31 batches over the 200 states of `data/NAME.deriv.txt`, the whole result
/// through `black_box`).
macro_rules! compare_fma {
    ($m:ident) => {{
        use robots::$m as g;
        use robots::fma::$m as f;
        use robots::batch::$m as b;
        const N: usize = g::DOF;
        assert_eq!(g::JOINT_NAMES, f::JOINT_NAMES);
        let text = std::fs::read_to_string(concat!("data/", stringify!($m), ".txt")).unwrap();
        let mut lines = text.lines();
        let pin_names: Vec<&str> = lines.next().unwrap().split(' ').collect();
        let perm: Vec<usize> = pin_names.iter().map(|n| g::JOINT_NAMES.iter().position(|m| m == n).expect("name")).collect();
        let (mut eid, mut emm) = (0.0f64, 0.0f64);
        let (mut bid, mut bmm) = (0.0f64, 0.0f64);
        for line in lines {
            let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            let take = |k: usize| -> [f64; N] {
                let mut o = [0.0; N];
                for i in 0..N { o[perm[i]] = v[k * N + i]; }
                o
            };
            let (q, qd, qdd, tau) = (take(0), take(1), take(2), take(3));
            let mut mp = [[0.0; N]; N];
            for i in 0..N { for j in 0..N { mp[perm[i]][perm[j]] = v[4 * N + i * N + j]; } }
            eid = eid.max(rel(&f::inverse_dynamics(&q, &qd, &qdd), &tau));
            emm = emm.max(rel(f::mass_matrix(&q).as_flattened(), mp.as_flattened()));
            bid = bid.max(rel(&b::inverse_dynamics(&q, &qd, &qdd), &tau));
            bmm = bmm.max(rel(b::mass_matrix(&q).as_flattened(), mp.as_flattened()));
        }
        let text = std::fs::read_to_string(concat!("data/", stringify!($m), ".deriv.txt")).unwrap();
        let mut states: Vec<([f64; N], [f64; N], [f64; N], [f64; N])> = Vec::new();
        let (mut edid, mut bdid) = (0.0f64, 0.0f64);
        for line in text.lines().skip(1) {
            let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            let take = |k: usize| -> [f64; N] {
                let mut o = [0.0; N];
                for i in 0..N { o[perm[i]] = v[k * N + i]; }
                o
            };
            let mat = |k: usize| -> [[f64; N]; N] {
                let off = 4 * N + k * N * N;
                let mut o = [[0.0; N]; N];
                for i in 0..N { for j in 0..N { o[perm[i]][perm[j]] = v[off + i * N + j]; } }
                o
            };
            let (q, qd, qdd, t2) = (take(0), take(1), take(2), take(3));
            let (dq, dv) = f::inverse_dynamics_derivatives(&q, &qd, &qdd);
            edid = edid.max(rel(dq.as_flattened(), mat(0).as_flattened())).max(rel(dv.as_flattened(), mat(1).as_flattened()));
            let (dq, dv) = b::inverse_dynamics_derivatives(&q, &qd, &qdd);
            bdid = bdid.max(rel(dq.as_flattened(), mat(0).as_flattened())).max(rel(dv.as_flattened(), mat(1).as_flattened()));
            states.push((q, qd, qdd, t2));
        }
        let time = |h: &dyn Fn(&([f64; N], [f64; N], [f64; N], [f64; N])) -> f64| {
            let mut t: Vec<f64> = (0..31)
                .map(|_| {
                    let t0 = std::time::Instant::now();
                    let mut sink = 0.0;
                    for s in &states { sink += h(std::hint::black_box(s)); }
                    std::hint::black_box(sink);
                    t0.elapsed().as_nanos() as f64 / states.len() as f64
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[15]
        };
        let ns = [
            time(&|(q, qd, qdd, _)| std::hint::black_box(g::inverse_dynamics(q, qd, qdd))[0]),
            time(&|(q, qd, qdd, _)| std::hint::black_box(f::inverse_dynamics(q, qd, qdd))[0]),
            time(&|(q, qd, qdd, _)| std::hint::black_box(b::inverse_dynamics(q, qd, qdd))[0]),
            time(&|(q, _, _, _)| std::hint::black_box(g::mass_matrix(q))[0][0]),
            time(&|(q, _, _, _)| std::hint::black_box(f::mass_matrix(q))[0][0]),
            time(&|(q, _, _, _)| std::hint::black_box(b::mass_matrix(q))[0][0]),
            time(&|(q, qd, qdd, _)| std::hint::black_box(g::inverse_dynamics_derivatives(q, qd, qdd)).0[0][0]),
            time(&|(q, qd, qdd, _)| std::hint::black_box(f::inverse_dynamics_derivatives(q, qd, qdd)).0[0][0]),
            time(&|(q, qd, qdd, _)| std::hint::black_box(b::inverse_dynamics_derivatives(q, qd, qdd)).0[0][0]),
            time(&|(q, qd, _, t2)| std::hint::black_box(g::forward_dynamics_derivatives(q, qd, t2)).map(|(a, _, _)| a[0][0]).unwrap_or(0.0)),
            time(&|(q, qd, _, t2)| std::hint::black_box(f::forward_dynamics_derivatives(q, qd, t2)).map(|(a, _, _)| a[0][0]).unwrap_or(0.0)),
            time(&|(q, qd, _, t2)| std::hint::black_box(b::forward_dynamics_derivatives(q, qd, t2)).map(|(a, _, _)| a[0][0]).unwrap_or(0.0)),
        ];
        println!(
            "fma {:16} dof {:2}  FMA errors: ID {:.1e} M {:.1e} dID {:.1e}  batch errors: ID {:.1e} M {:.1e} dID {:.1e}  ns plain/fma/batch: ID {:.0} {:.0} {:.0}  M {:.0} {:.0} {:.0}  IDD {:.0} {:.0} {:.0}  FDD {:.0} {:.0} {:.0}",
            stringify!($m), N, eid, emm, edid, bid, bmm, bdid, ns[0], ns[1], ns[2], ns[3], ns[4], ns[5], ns[6], ns[7], ns[8], ns[9], ns[10], ns[11]
        );
    }};
}

fn main() {
    check!(ur5);
    check!(ur10);
    check!(panda);
    check!(z1);
    check!(kinova);
    check!(xarm7);
    check!(iiwa14);
    check!(talos_left_arm);
    check!(baxter);
    check!(pr2);
    check!(icub);
    check!(tiago);
    check!(anymal);
    check!(talos_full);
    check!(allegro);
    // Derivatives: the robots with <= 16 DOF (the others' scenes leave them out).
    check_deriv!(ur5);
    check_deriv!(ur10);
    check_deriv!(panda);
    check_deriv!(z1);
    check_deriv!(kinova);
    check_deriv!(xarm7);
    check_deriv!(iiwa14);
    check_deriv!(talos_left_arm);
    check_deriv!(anymal);
    check_deriv!(allegro);
    // Without and with FMA (the arms of build.rs's FMA_ARMS), beside bench_cg.cpp.
    compare_fma!(ur5);
    compare_fma!(ur10);
    compare_fma!(panda);
    compare_fma!(z1);
    compare_fma!(kinova);
    compare_fma!(xarm7);
    compare_fma!(iiwa14);
    compare_fma!(talos_left_arm);
}

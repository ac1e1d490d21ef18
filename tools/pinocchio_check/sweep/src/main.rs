//! Every URDF of example-robot-data against Pinocchio (`run.sh`; ../README.md, "Every URDF of
//! example-robot-data"): per robot the worst relative error (∞-norm over the vector or matrix)
//! of the generated `inverse_dynamics`, `mass_matrix` and `forward_dynamics` against `rnea`,
//! `crba` and `aba` at the states of `data/NAME.txt` (`../gen.py`), joints matched by name, and how
//! many states forward dynamics refused (`Err(Singular)`).
mod robots {
    include!(concat!(env!("OUT_DIR"), "/all.rs"));
}
#[path = "../../src/rel.rs"]
mod rel;
use rel::rel;
macro_rules! check {
    ($m:ident) => {{
        use robots::$m as g;
        const N: usize = g::DOF;
        match std::fs::read_to_string(concat!("data/", stringify!($m), ".txt")) {
            Err(_) => println!("{:40} no data", stringify!($m)),
            Ok(text) => {
                let mut lines = text.lines();
                let pin_names: Vec<&str> = lines.next().unwrap().split(' ').collect();
                if pin_names.len() != N {
                    println!(
                        "{:40} DOF {} vs pinocchio {}",
                        stringify!($m),
                        N,
                        pin_names.len()
                    );
                } else {
                    let perm: Vec<usize> = pin_names
                        .iter()
                        .map(|n| g::JOINT_NAMES.iter().position(|m| m == n).expect("name"))
                        .collect();
                    let (mut eid, mut emm, mut efd, mut nfail) = (0.0f64, 0.0f64, 0.0f64, 0);
                    for line in lines {
                        let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
                        let take = |k: usize| -> [f64; N] {
                            let mut o = [0.0; N];
                            for i in 0..N {
                                o[perm[i]] = v[k * N + i];
                            }
                            o
                        };
                        let (q, qd, qdd, tau) = (take(0), take(1), take(2), take(3));
                        let mut mp = [[0.0; N]; N];
                        for i in 0..N {
                            for j in 0..N {
                                mp[perm[i]][perm[j]] = v[4 * N + i * N + j];
                            }
                        }
                        let off = 4 * N + N * N;
                        let mut t2 = [0.0; N];
                        let mut fdp = [0.0; N];
                        for i in 0..N {
                            t2[perm[i]] = v[off + i];
                            fdp[perm[i]] = v[off + N + i];
                        }
                        let id = g::inverse_dynamics(&q, &qd, &qdd);
                        let mm = g::mass_matrix(&q);
                        eid = eid.max(rel(&id, &tau));
                        emm = emm.max(rel(mm.as_flattened(), mp.as_flattened()));
                        match g::forward_dynamics(&q, &qd, &t2) {
                            Ok(fd) => efd = efd.max(rel(&fd, &fdp)),
                            Err(_) => nfail += 1,
                        }
                    }
                    println!(
                        "{:40} dof {:3}  ID {:.1e}  M {:.1e}  FD {:.1e}  FD errs {}",
                        stringify!($m),
                        N,
                        eid,
                        emm,
                        efd,
                        nfail
                    );
                }
            }
        }
    }};
}
fn main() {
    include!(concat!(env!("OUT_DIR"), "/calls.rs"));
}

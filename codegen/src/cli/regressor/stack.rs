//! The base regressor at many states, as `identify` stacks it over a measurement file and
//! `excite` over a trajectory: [`LANES`] states per evaluation of the flattened kernel
//! ([`super::super::tape_lanes`]), and a block of such groups at a time shared out over rayon's
//! threads (each thread takes whole groups, so the lanes work within a thread's share). Each
//! state's rows are bit for bit what [`Regressor::rows`] gives it alone, whatever the threads.

use std::cell::RefCell;

use rayon::prelude::*;

use super::Regressor;
use crate::cli::platform_regressor::NoRegressor;
use crate::cli::tape_lanes::{LANES, LaneScratch};

/// States evaluated per block (a multiple of [`LANES`]): a few megabytes of rows for the
/// largest regressors, and enough groups to share out over the threads.
const BLOCK: usize = 64 * LANES;

thread_local! {
    /// Each thread's scratch space, kept between blocks and between stacks.
    static SCRATCH: RefCell<LaneScratch<LANES>> = RefCell::new(LaneScratch::default());
}

impl Regressor {
    /// `Y` at `L` states (positions `p[k]`, speeds `v[k]`, rates `a[k]` of state `k`) into
    /// `out` (`L` blocks of `DOF × NBP`, row-major, state after state); each lane's status.
    pub fn rows_lanes<const L: usize>(
        &self,
        p: &[[f64; L]],
        v: &[[f64; L]],
        a: &[[f64; L]],
        scratch: &mut LaneScratch<L>,
        out: &mut [f64],
    ) -> [Result<(), NoRegressor>; L] {
        match self {
            Regressor::Tree(r) => {
                r.rows_lanes(p, v, a, scratch, out);
                std::array::from_fn(|_| Ok(()))
            }
            Regressor::Platform(r) => r.rows_lanes(p, v, a, scratch, out),
            Regressor::Closed(r) => r.rows_lanes(p, v, a, scratch, out),
        }
    }

    /// The regressor at the states `(p[s], v[s], a[s])`, read in order with [`Stack::rows`].
    pub fn stack<'a>(
        &'a self,
        p: &'a [Vec<f64>],
        v: &'a [Vec<f64>],
        a: &'a [Vec<f64>],
    ) -> Stack<'a> {
        Stack {
            reg: self,
            states: [p, v, a],
            size: self.dof() * self.nbp(),
            start: 0,
            rows: Vec::new(),
            status: Vec::new(),
        }
    }
}

/// The regressor at many states, evaluated a block at a time as they are read.
pub struct Stack<'a> {
    reg: &'a Regressor,
    /// Positions, speeds and rates, one `Vec` per state.
    states: [&'a [Vec<f64>]; 3],
    /// `DOF × NBP`.
    size: usize,
    /// The block's first state.
    start: usize,
    /// The block's rows, state after state.
    rows: Vec<f64>,
    /// The block's states' status.
    status: Vec<Result<(), NoRegressor>>,
}

impl Stack<'_> {
    /// State `s`'s `Y` (`DOF × NBP`, row-major), or why it has none.
    pub fn rows(&mut self, s: usize) -> Result<&[f64], NoRegressor> {
        let count = self.states[0].len();
        if s >= count {
            return Err(NoRegressor("no such state"));
        }
        if !(self.start..self.start + self.status.len()).contains(&s) {
            self.start = s;
            self.evaluate(BLOCK.min(count - s));
        }
        let k = s - self.start;
        self.status[k].clone()?;
        Ok(&self.rows[k * self.size..(k + 1) * self.size])
    }

    /// Evaluate the `len` states from `start`: a group of [`LANES`] per call, the groups
    /// shared out over rayon's threads; the states after the last whole group as one more
    /// group (its last state repeated in the lanes left over, whose rows are dropped), or a
    /// lone state alone (cheaper than a group: measured one state alone at about 6 states of a
    /// group).
    fn evaluate(&mut self, len: usize) {
        let (groups, rest) = (len / LANES, len % LANES);
        let (reg, size, states) = (self.reg, self.size, self.states);
        let group = |first: usize, count: usize, out: &mut [f64]| {
            let lanes = |which: usize| -> Vec<[f64; LANES]> {
                let state = |k: usize| &states[which][first + k.min(count - 1)];
                (0..state(0).len())
                    .map(|i| std::array::from_fn(|k| state(k)[i]))
                    .collect()
            };
            let (p, v, a) = (lanes(0), lanes(1), lanes(2));
            SCRATCH.with_borrow_mut(|scratch| reg.rows_lanes(&p, &v, &a, scratch, out))
        };
        self.rows.clear();
        self.rows.resize(len * size, 0.0);
        self.status.clear();
        self.status.resize(len, Ok(()));
        let first = self.start;
        let (whole, tail) = self.rows.split_at_mut(groups * LANES * size);
        let (whole_status, tail_status) = self.status.split_at_mut(groups * LANES);
        whole
            .par_chunks_mut(LANES * size)
            .zip(whole_status.par_chunks_mut(LANES))
            .enumerate()
            .for_each(|(g, (out, status))| {
                status.clone_from_slice(&group(first + g * LANES, LANES, out));
            });
        let s = first + groups * LANES;
        if rest == 1 {
            tail_status[0] = reg.rows(
                &states[0][s],
                &states[1][s],
                &states[2][s],
                &mut Vec::new(),
                tail,
            );
        } else if rest > 1 {
            let mut out = vec![0.0; LANES * size];
            let got = group(s, rest, &mut out);
            tail.copy_from_slice(&out[..rest * size]);
            tail_status.clone_from_slice(&got[..rest]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::Rng;

    /// `count` states of a bundled spec around home (offsets up to `reach`, every ninth up to
    /// `far`), the stack read in order against [`Regressor::rows`] one state at a time: the
    /// same rows bit for bit, the same failures; how many failed.
    fn check(file: &str, count: usize, reach: f64, far: f64) -> usize {
        let path = format!("{}/../mechanisms/specs/{file}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).expect("bundled spec");
        let (reg, _) = Regressor::compile(file, &text, None).expect("compiles");
        let n = reg.dof();
        let mut rng = Rng::new(5);
        let (mut p, mut v, mut a) = (Vec::new(), Vec::new(), Vec::new());
        while p.len() < count {
            let r = if p.len() % 9 == 4 { far } else { reach };
            let d: Vec<f64> = (0..n).map(|_| rng.uniform(-r, r)).collect();
            let dd: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let ddd: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            if let Some((ps, vs, as_)) = reg.state(&d, &dd, &ddd, p.last().map(Vec::as_slice)) {
                p.push(ps);
                v.push(vs);
                a.push(as_);
            }
        }
        let mut stack = reg.stack(&p, &v, &a);
        let (mut buf, mut want) = (Vec::new(), vec![0.0; n * reg.nbp()]);
        let mut failed = 0;
        for s in 0..count {
            let alone = reg.rows(&p[s], &v[s], &a[s], &mut buf, &mut want);
            match (stack.rows(s), alone) {
                (Ok(y), Ok(())) => {
                    assert!(
                        y.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits()),
                        "{file}: state {s}"
                    );
                }
                (Err(e), Err(f)) => {
                    assert_eq!(e, f, "{file}: state {s}");
                    failed += 1;
                }
                (got, alone) => panic!("{file}: state {s}: {:?} alone {alone:?}", got.err()),
            }
        }
        failed
    }

    #[test]
    fn stacked_rows_are_each_state_alone() {
        // Two blocks and a group and a remainder of states (and a lone state after a whole
        // group): every state as it is alone.
        let count = 2 * BLOCK + LANES + 3;
        assert_eq!(check("puma560.toml", count, 3.0, 3.0), 0);
        assert_eq!(check("puma560.toml", LANES + 1, 3.0, 3.0), 0);
        // A Delta's states a metre off home fail (out of reach), each alone.
        let failed = check("delta_rl5.toml", count, 0.05, 1.0);
        assert!(failed > count / 20 && failed < count / 5, "{failed}");
        assert_eq!(check("four_bar.toml", BLOCK + 5, 0.3, 0.3), 0);
        assert_eq!(check("four_bar.toml", 1, 0.3, 0.3), 0);
        let (p, v, a) = (vec![vec![0.0; 6]], vec![vec![0.0; 6]], vec![vec![0.0; 6]]);
        let text = std::fs::read_to_string(format!(
            "{}/../mechanisms/specs/puma560.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .expect("bundled spec");
        let (reg, _) = Regressor::compile("puma560.toml", &text, None).expect("compiles");
        assert!(reg.stack(&p, &v, &a).rows(1).is_err(), "past the states");
    }
}

//! A [`Tape`] evaluated at `L` states at once: each slot holds `[f64; L]`, one value per state
//! (a lane), and each operation is one loop over the lanes, which LLVM turns into vector
//! instructions. The interpreter's per-operation cost (the dispatch on the operation, the reads
//! of its operands' slots) is paid once for `L` states instead of once per state.
//!
//! Lane `k` is bit for bit [`Tape::eval`] at state `k`: the same IEEE operations in the same
//! order, `sqrt`, `sin`, `cos` and `atan2` per lane by the same functions, and the guards and
//! selections decided per lane (a failing guard makes its own lane `NaN` from there on, the
//! other lanes go on), as the generated `_lanes` functions do (docs/performance.md, "Many states
//! in the CLI tools").

use codegen::sym::Arg;

use super::tape::{GuardedTape, Op, Tape};

/// The states of one call in the tools (8 measured 20–40 % faster per state than 4 on the
/// regressors' tapes; docs/performance.md).
pub const LANES: usize = 8;

/// `f` of each lane of `a`.
#[inline(always)]
fn map1<const L: usize>(a: [f64; L], f: impl Fn(f64) -> f64) -> [f64; L] {
    std::array::from_fn(|k| f(a[k]))
}

/// `f` of each lane of `a` and `b`.
#[inline(always)]
fn map2<const L: usize>(a: [f64; L], b: [f64; L], f: impl Fn(f64, f64) -> f64) -> [f64; L] {
    std::array::from_fn(|k| f(a[k], b[k]))
}

impl Tape {
    /// Evaluate at `L` states into `out` (one `[f64; L]` per root); `input(arg, i)` is input
    /// `i` of `arg` at each state, `buf` scratch space kept between calls.
    pub fn eval_lanes<const L: usize>(
        &self,
        input: &dyn Fn(Arg, usize) -> [f64; L],
        buf: &mut Vec<[f64; L]>,
        out: &mut [[f64; L]],
    ) {
        buf.clear();
        buf.reserve(self.ops.len());
        for op in &self.ops {
            let v = |k: usize| buf[k];
            let r = match *op {
                Op::Const(c) => [c; L],
                Op::Input(a, k) => input(a, k),
                Op::Add(a, b) => map2(v(a), v(b), |x, y| x + y),
                Op::Sub(a, b) => map2(v(a), v(b), |x, y| x - y),
                Op::Mul(a, b) => map2(v(a), v(b), |x, y| x * y),
                Op::Div(a, b) => map2(v(a), v(b), |x, y| x / y),
                Op::Neg(a) => map1(v(a), |x| -x),
                Op::Sqrt(a) => map1(v(a), f64::sqrt),
                Op::Sin(a) => map1(v(a), f64::sin),
                Op::Cos(a) => map1(v(a), f64::cos),
                Op::Atan2(a, b) => map2(v(a), v(b), f64::atan2),
                Op::Select(a, b, x, y) => {
                    let (a, b, x, y) = (v(a), v(b), v(x), v(y));
                    std::array::from_fn(|k| if a[k].abs() > b[k].abs() { x[k] } else { y[k] })
                }
                Op::Guard(value, tol, two) => {
                    let (x, t) = (v(value), v(tol));
                    std::array::from_fn(|k| {
                        let ok = if two { x[k].abs() > t[k] } else { x[k] > t[k] };
                        if ok { x[k] } else { f64::NAN }
                    })
                }
            };
            buf.push(r);
        }
        for (o, &r) in out.iter_mut().zip(&self.roots) {
            *o = buf[r];
        }
    }

    /// [`Tape::eval_lanes`] into `scratch`: the roots' values.
    pub fn eval_lanes_in<'s, const L: usize>(
        &self,
        input: &dyn Fn(Arg, usize) -> [f64; L],
        scratch: &'s mut LaneScratch<L>,
    ) -> &'s [[f64; L]] {
        let LaneScratch { buf, all } = scratch;
        all.clear();
        all.resize(self.roots.len(), [0.0; L]);
        self.eval_lanes(input, buf, all);
        all
    }
}

/// Scratch space of [`Tape::eval_lanes_in`] and [`GuardedTape::eval_lanes`], kept between
/// calls.
#[derive(Clone, Debug, Default)]
pub struct LaneScratch<const L: usize> {
    buf: Vec<[f64; L]>,
    all: Vec<[f64; L]>,
}

impl GuardedTape {
    /// The outputs at `L` states `(x, u, u̇)` (lane last: `x[i][k]` is coordinate `i` of state
    /// `k`), and for each lane whether its guards hold ([`GuardedTape::eval`] is `Some` there).
    /// A failed lane's outputs are not to be read.
    pub fn eval_lanes<'s, const L: usize>(
        &self,
        x: &[[f64; L]],
        u: &[[f64; L]],
        ud: &[[f64; L]],
        scratch: &'s mut LaneScratch<L>,
    ) -> (&'s [[f64; L]], [bool; L]) {
        let input = |a: Arg, i: usize| match a {
            Arg::X => x[i],
            Arg::U => u[i],
            Arg::Ud => ud[i],
            _ => [f64::NAN; L],
        };
        let all = self.tape.eval_lanes_in(&input, scratch);
        let (guards, outputs) = all.split_at(self.guards);
        let ok = std::array::from_fn(|k| guards.iter().all(|g| !g[k].is_nan()));
        (outputs, ok)
    }
}

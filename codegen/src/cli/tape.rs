//! A compiled evaluator of some roots of a [`Graph`]: the nodes they reach, in insertion
//! order (a node's operands are always older), as a flat list of operations over one buffer.
//! [`Graph::eval`] does the same per call with a fresh map and a stack; the identification
//! tools evaluate the same roots at thousands of states, so they flatten once.

use codegen::sym::{Arg, ExprId, Graph, Node, TWO_SIDED};

/// One operation: its operands are slots (indices of older operations).
#[derive(Clone, Copy, Debug)]
pub(super) enum Op {
    Const(f64),
    Input(Arg, usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Neg(usize),
    Sqrt(usize),
    Sin(usize),
    Cos(usize),
    Atan2(usize, usize),
    Select(usize, usize, usize, usize),
    Guard(usize, usize, bool),
}

/// The roots of a graph, flattened.
#[derive(Clone, Debug)]
pub struct Tape {
    /// The operations, one slot each, operands first.
    pub(super) ops: Vec<Op>,
    /// The slots of the roots.
    pub(super) roots: Vec<usize>,
}

impl Tape {
    /// Flatten the nodes that `roots` reach.
    pub fn new(g: &Graph, roots: &[ExprId]) -> Tape {
        let mut reach = vec![false; g.len()];
        let mut stack: Vec<ExprId> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if std::mem::replace(&mut reach[id.0 as usize], true) {
                continue;
            }
            stack.extend(g.operands(id).filter(|o| !reach[o.0 as usize]));
        }
        let mut slot = vec![usize::MAX; g.len()];
        let mut ops = Vec::new();
        for (i, _) in reach.iter().enumerate().filter(|(_, r)| **r) {
            let s = |x: ExprId| slot[x.0 as usize];
            let op = match g.node(ExprId(i as u32)) {
                Node::Const(b) => Op::Const(f64::from_bits(b)),
                Node::Input(a, k) => Op::Input(a, k as usize),
                Node::Add(a, b) => Op::Add(s(a), s(b)),
                Node::Sub(a, b) => Op::Sub(s(a), s(b)),
                Node::Mul(a, b) => Op::Mul(s(a), s(b)),
                Node::Div(a, b) => Op::Div(s(a), s(b)),
                Node::Neg(a) => Op::Neg(s(a)),
                Node::Sqrt(a) => Op::Sqrt(s(a)),
                Node::Sin(a) => Op::Sin(s(a)),
                Node::Cos(a) => Op::Cos(s(a)),
                Node::Atan2(a, b) => Op::Atan2(s(a), s(b)),
                Node::Select(a, b, x, y) => Op::Select(s(a), s(b), s(x), s(y)),
                Node::Guard {
                    value, tol, index, ..
                } => Op::Guard(s(value), s(tol), index & TWO_SIDED != 0),
            };
            slot[i] = ops.len();
            ops.push(op);
        }
        let roots = roots.iter().map(|r| slot[r.0 as usize]).collect();
        Tape { ops, roots }
    }

    /// Evaluate into `out` (one value per root); `buf` is scratch space kept between calls.
    pub fn eval(&self, input: &dyn Fn(Arg, usize) -> f64, buf: &mut Vec<f64>, out: &mut [f64]) {
        buf.clear();
        buf.reserve(self.ops.len());
        for op in &self.ops {
            let v = |k: usize| buf[k];
            let r = match *op {
                Op::Const(c) => c,
                Op::Input(a, k) => input(a, k),
                Op::Add(a, b) => v(a) + v(b),
                Op::Sub(a, b) => v(a) - v(b),
                Op::Mul(a, b) => v(a) * v(b),
                Op::Div(a, b) => v(a) / v(b),
                Op::Neg(a) => -v(a),
                Op::Sqrt(a) => v(a).sqrt(),
                Op::Sin(a) => v(a).sin(),
                Op::Cos(a) => v(a).cos(),
                Op::Atan2(a, b) => v(a).atan2(v(b)),
                Op::Select(a, b, x, y) => {
                    if v(a).abs() > v(b).abs() {
                        v(x)
                    } else {
                        v(y)
                    }
                }
                Op::Guard(value, tol, two) => {
                    let ok = if two {
                        v(value).abs() > v(tol)
                    } else {
                        v(value) > v(tol)
                    };
                    if ok { v(value) } else { f64::NAN }
                }
            };
            buf.push(r);
        }
        for (o, &r) in out.iter_mut().zip(&self.roots) {
            *o = buf[r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tape_agrees_with_the_graph_interpreter() {
        let mut g = Graph::new();
        let q = g.input(Arg::Q, 0);
        let qd = g.input(Arg::Qd, 1);
        let s = g.sin(q);
        let c = g.cos(q);
        let m = g.mul(s, qd);
        let r = g.add(m, c);
        let d = g.div(r, qd);
        let roots = [r, d, s];
        let input = |a: Arg, i: usize| match (a, i) {
            (Arg::Q, 0) => 0.3,
            (Arg::Qd, 1) => -1.7,
            _ => f64::NAN,
        };
        let want = g.eval(&roots, &input);
        let t = Tape::new(&g, &roots);
        let mut out = [0.0; 3];
        t.eval(&input, &mut Vec::new(), &mut out);
        assert_eq!(want, out.to_vec());
    }
}

/// A kernel with guards, flattened: its guards, then its outputs, evaluated at `(x, u, u̇)`.
#[derive(Clone, Debug)]
pub struct GuardedTape {
    /// The guards' roots, then the outputs'.
    pub(super) tape: Tape,
    /// Number of guards.
    pub(super) guards: usize,
    /// Number of outputs.
    pub(super) outputs: usize,
}

impl GuardedTape {
    /// Flatten `kernel` of `g`.
    pub fn new(g: &Graph, kernel: &codegen::schedule::Kernel) -> GuardedTape {
        let roots: Vec<ExprId> = kernel
            .guards
            .iter()
            .chain(&kernel.outputs)
            .copied()
            .collect();
        GuardedTape {
            tape: Tape::new(g, &roots),
            guards: kernel.guards.len(),
            outputs: kernel.outputs.len(),
        }
    }

    /// The outputs at `(x, u, u̇)`; `None` when a guard fails. `buf` is scratch space.
    pub fn eval(&self, x: &[f64], u: &[f64], ud: &[f64], buf: &mut Vec<f64>) -> Option<Vec<f64>> {
        let input = |a: Arg, i: usize| match a {
            Arg::X => x[i],
            Arg::U => u[i],
            Arg::Ud => ud[i],
            _ => f64::NAN,
        };
        let mut all = vec![0.0; self.guards + self.outputs];
        self.tape.eval(&input, buf, &mut all);
        if all[..self.guards].iter().any(|v| v.is_nan()) {
            return None;
        }
        Some(all.split_off(self.guards))
    }
}

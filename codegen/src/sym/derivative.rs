//! Symbolic differentiation on the DAG (forward mode, one input direction at a time) and
//! substitution of inputs by nodes.
//!
//! Derivative nodes are built through the [`Graph`]'s own constructors, so they are folded
//! (a derivative that is structurally zero never becomes a node) and shared like everything
//! else: the factors a rule needs that do not depend on the direction (`cos a` of `sin a`,
//! `(a/b)/b` of a quotient, `1/(2√a)` of a root) are one node for every direction. Rules:
//!
//! | node | derivative |
//! |---|---|
//! | `a ± b`, `−a` | `a′ ± b′`, `−a′` |
//! | `a·b` | `a′·b + a·b′` |
//! | `q = a/b` | `(a′ − q·b′)/b` (`a′/b` when `b′ = 0`, `−(q/b)·b′` when `a′ = 0`) |
//! | `√a` | `(½/√a)·a′` |
//! | `sin a`, `cos a` | `cos a · a′`, `−sin a · a′` |
//! | `atan2(y, x)` | `(x/r)·y′ − (y/r)·x′`, `r = x² + y²` |
//! | `select(a, b, x, y)` | `select(a, b, x′, y′)`: the same choice |
//! | `guard(v)` | `v′`: the test stays the original function's (its guards remain roots) |

use std::collections::HashMap;

use super::{Arg, ExprId, Graph, Node};

/// The derivatives of nodes along one direction of the inputs, memoized per node.
pub struct Derivative {
    /// The direction: each seeded input's derivative (`None`: 1); every other input's is 0.
    seeds: Vec<(Arg, u16, Option<ExprId>)>,
    memo: HashMap<ExprId, ExprId>,
}

impl Derivative {
    /// Differentiation with respect to `arg[index]`.
    pub fn new(arg: Arg, index: usize) -> Derivative {
        Derivative {
            seeds: vec![(arg, index as u16, None)],
            memo: HashMap::new(),
        }
    }

    /// The derivative along a direction of the inputs given by nodes: `arg[index]` moves at
    /// the rate `rate` (a tangent of the coordinates' manifold, say), every other input stays.
    pub fn along(direction: &[(Arg, usize, ExprId)]) -> Derivative {
        Derivative {
            seeds: direction
                .iter()
                .map(|&(a, i, r)| (a, i as u16, Some(r)))
                .collect(),
            memo: HashMap::new(),
        }
    }

    /// The operands whose derivatives the rule of `id` reads.
    fn needs(g: &Graph, id: ExprId) -> Vec<ExprId> {
        match g.node(id) {
            Node::Select(_, _, x, y) => vec![x, y],
            Node::Guard { value, .. } => vec![value],
            _ => g.operands(id).collect(),
        }
    }

    /// `∂root/∂arg[index]` as a node of `g`.
    pub fn of(&mut self, g: &mut Graph, root: ExprId) -> ExprId {
        // Post-order without recursion: the DAGs are deeper than a test thread's stack.
        let mut stack = vec![(root, false)];
        while let Some((id, expanded)) = stack.pop() {
            if self.memo.contains_key(&id) {
                continue;
            }
            if !expanded {
                stack.push((id, true));
                for o in Self::needs(g, id) {
                    if !self.memo.contains_key(&o) {
                        stack.push((o, false));
                    }
                }
                continue;
            }
            let d = self.rule(g, id);
            self.memo.insert(id, d);
        }
        self.memo[&root]
    }

    /// The derivative of `id`, its operands' derivatives memoized.
    fn rule(&mut self, g: &mut Graph, id: ExprId) -> ExprId {
        let d = |x: ExprId| self.memo[&x];
        let zero = g.zero();
        match g.node(id) {
            Node::Const(_) => zero,
            Node::Input(a, i) => match self.seeds.iter().find(|s| (s.0, s.1) == (a, i)) {
                Some(&(_, _, Some(rate))) => rate,
                Some(&(_, _, None)) => g.constant(1.0),
                None => zero,
            },
            Node::Add(a, b) => g.add(d(a), d(b)),
            Node::Sub(a, b) => g.sub(d(a), d(b)),
            Node::Neg(a) => g.neg(d(a)),
            Node::Mul(a, b) => {
                let p = g.mul(d(a), b);
                let r = g.mul(a, d(b));
                g.add(p, r)
            }
            Node::Div(a, b) => {
                let (da, db) = (d(a), d(b));
                match (g.is_const(da, 0.0), g.is_const(db, 0.0)) {
                    (_, true) => g.div(da, b),
                    (true, false) => {
                        let r = g.div(id, b);
                        let p = g.mul(r, db);
                        g.neg(p)
                    }
                    (false, false) => {
                        let p = g.mul(id, db);
                        let s = g.sub(da, p);
                        g.div(s, b)
                    }
                }
            }
            Node::Sqrt(a) => {
                let da = d(a);
                if g.is_const(da, 0.0) {
                    return zero;
                }
                let half = g.constant(0.5);
                let h = g.div(half, id);
                g.mul(h, da)
            }
            Node::Sin(a) => {
                let c = g.cos(a);
                g.mul(c, d(a))
            }
            Node::Cos(a) => {
                let s = g.sin(a);
                let p = g.mul(s, d(a));
                g.neg(p)
            }
            Node::Atan2(y, x) => {
                let (dy, dx) = (d(y), d(x));
                if g.is_const(dy, 0.0) && g.is_const(dx, 0.0) {
                    return zero;
                }
                let (xx, yy) = (g.mul(x, x), g.mul(y, y));
                let r = g.add(xx, yy);
                let (u, v) = (g.div(x, r), g.div(y, r));
                let (p, q) = (g.mul(u, dy), g.mul(v, dx));
                g.sub(p, q)
            }
            Node::Select(a, b, x, y) => g.select_abs_gt(a, b, d(x), d(y)),
            Node::Guard { value, .. } => d(value),
        }
    }
}

/// `roots` with every input `arg[i]` for which `with` names a node replaced by that node,
/// rebuilt through the constructors (memoized in `memo`, which may be shared by calls with the
/// same `with`). A guard whose operands change is asked for again ([`Graph::guard`]).
pub fn substitute(
    g: &mut Graph,
    roots: &[ExprId],
    with: &dyn Fn(Arg, usize) -> Option<ExprId>,
    memo: &mut HashMap<ExprId, ExprId>,
) -> Vec<ExprId> {
    let mut stack: Vec<(ExprId, bool)> = roots.iter().map(|&r| (r, false)).collect();
    while let Some((id, expanded)) = stack.pop() {
        if memo.contains_key(&id) {
            continue;
        }
        if !expanded {
            stack.push((id, true));
            for o in g.operands(id) {
                if !memo.contains_key(&o) {
                    stack.push((o, false));
                }
            }
            continue;
        }
        let s = |x: ExprId| memo[&x];
        let new = match g.node(id) {
            Node::Const(_) => id,
            Node::Input(a, i) => with(a, i as usize).unwrap_or(id),
            Node::Add(a, b) => g.add(s(a), s(b)),
            Node::Sub(a, b) => g.sub(s(a), s(b)),
            Node::Mul(a, b) => g.mul(s(a), s(b)),
            Node::Div(a, b) => g.div(s(a), s(b)),
            Node::Neg(a) => g.neg(s(a)),
            Node::Sqrt(a) => g.sqrt(s(a)),
            Node::Sin(a) => g.sin(s(a)),
            Node::Cos(a) => g.cos(s(a)),
            Node::Atan2(a, b) => g.atan2(s(a), s(b)),
            Node::Select(a, b, x, y) => g.select_abs_gt(s(a), s(b), s(x), s(y)),
            Node::Guard {
                value,
                tol,
                scale,
                index,
            } => {
                let (v, t, c) = (s(value), s(tol), s(scale));
                if (v, t, c) == (value, tol, scale) {
                    id
                } else {
                    g.guard(v, t, c, index as usize)
                }
            }
        };
        memo.insert(id, new);
    }
    roots.iter().map(|r| memo[r]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inputs of the tests: `q = [0.3, −1.1, 0.7]`, `qd = [0.4, 2.0, −0.6]`.
    fn input(a: Arg, i: usize) -> f64 {
        match a {
            Arg::Q => [0.3, -1.1, 0.7][i],
            _ => [0.4, 2.0, -0.6][i],
        }
    }

    /// Central differences of `root` in `arg[i]` by the graph's own interpreter, step `h`.
    fn central(g: &Graph, root: ExprId, arg: Arg, i: usize, h: f64) -> f64 {
        let at = |s: f64| {
            g.eval(&[root], &|a, j| {
                input(a, j) + if (a, j) == (arg, i) { s } else { 0.0 }
            })[0]
        };
        (at(h) - at(-h)) / (2.0 * h)
    }

    /// One expression of every node kind.
    fn every_kind(g: &mut Graph) -> Vec<ExprId> {
        let (x, y, z) = (g.input(Arg::Q, 0), g.input(Arg::Q, 1), g.input(Arg::Qd, 0));
        let (s, c) = (g.sin(x), g.cos(y));
        let p = g.mul(s, z);
        let q = g.div(p, c);
        let two = g.constant(2.0);
        let w = g.input(Arg::Qd, 1);
        let r = g.add(two, w);
        let r = g.mul(r, r);
        let root = g.sqrt(r);
        let at = g.atan2(y, z);
        let n = g.neg(at);
        let diff = g.sub(q, n);
        let sel = g.select_abs_gt(x, y, p, root);
        let tol = g.constant(1e-12);
        let one = g.constant(1.0);
        let gd = g.guard(r, tol, one, 0);
        let inv = g.div(one, gd);
        vec![s, c, p, q, root, at, n, diff, sel, gd, inv]
    }

    #[test]
    fn matches_central_differences() {
        let mut g = Graph::new();
        let roots = every_kind(&mut g);
        for (arg, i) in [(Arg::Q, 0), (Arg::Q, 1), (Arg::Qd, 0), (Arg::Qd, 1)] {
            let mut d = Derivative::new(arg, i);
            for &r in &roots {
                let dr = d.of(&mut g, r);
                let exact = g.eval(&[dr], &input)[0];
                let fd = central(&g, r, arg, i, 1e-6);
                assert!(
                    (exact - fd).abs() <= 1e-8 * (1.0 + fd.abs()),
                    "{:?} in {arg:?}[{i}]: {exact} vs {fd}",
                    g.node(r)
                );
            }
        }
    }

    #[test]
    fn closed_forms() {
        let mut g = Graph::new();
        let x = g.input(Arg::Q, 0);
        let y = g.input(Arg::Q, 1);
        let s = g.sin(x);
        let mut d = Derivative::new(Arg::Q, 0);
        // d sin x = cos x, shared with the graph's own cos x.
        assert_eq!(d.of(&mut g, s), g.cos(x));
        // d(x·y)/dx = y; d(x·y)/dq̇ = 0 (no node).
        let p = g.mul(x, y);
        assert_eq!(d.of(&mut g, p), y);
        let zero = g.zero();
        assert_eq!(Derivative::new(Arg::Qd, 0).of(&mut g, p), zero);
        // d(x²)/dx = 2x.
        let xx = g.mul(x, x);
        assert_eq!(d.of(&mut g, xx), g.scale(2.0, x));
        // d cos x = −sin x.
        let c = g.cos(x);
        assert_eq!(d.of(&mut g, c), g.neg(s));
        // Select: the same choice of the derivatives.
        let sel = g.select_abs_gt(x, y, xx, s);
        let want = {
            let (a, b) = (g.scale(2.0, x), g.cos(x));
            g.select_abs_gt(x, y, a, b)
        };
        assert_eq!(d.of(&mut g, sel), want);
    }

    #[test]
    fn substitution_rebuilds() {
        let mut g = Graph::new();
        let roots = every_kind(&mut g);
        let (a, b) = (g.input(Arg::Qd, 1), g.input(Arg::Q, 1));
        let two = g.constant(2.0);
        let t = g.mul(a, two);
        let with = |arg: Arg, i: usize| (arg == Arg::Q && i == 1).then_some(t);
        let mut memo = HashMap::new();
        let new = substitute(&mut g, &roots, &with, &mut memo);
        let got = g.eval(&new, &input);
        let want = g.eval(&roots, &|arg, i| {
            if (arg, i) == (Arg::Q, 1) {
                2.0 * input(Arg::Qd, 1)
            } else {
                input(arg, i)
            }
        });
        for (x, y) in got.iter().zip(&want) {
            assert!((x - y).abs() <= 1e-15 * (1.0 + y.abs()), "{x} vs {y}");
        }
        // Nothing to substitute: the same nodes.
        let none = substitute(&mut g, &[b], &|_, _| None, &mut HashMap::new());
        assert_eq!(none, vec![b]);
    }
}

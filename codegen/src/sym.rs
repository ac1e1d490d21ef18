//! The symbolic layer: a hash-consed expression DAG of scalar `f64` operations.
//!
//! Every node is stored once ([`IndexSet`] with a fixed hasher), so building the same
//! subexpression twice returns the same [`ExprId`]: common-subexpression sharing is free, and an
//! id is its insertion index, so iteration order — and therefore the emitted code — is
//! deterministic. The smart constructors ([`Graph::add`], [`Graph::mul`], …) fold constants and
//! apply the algebraic identities (`x+0`, `x·1`, `x·0`, `x−x`, `−(−x)`, negation pushed into
//! sums and constant factors) as nodes are built, so structural zeros never become nodes at all.
//!
//! Nodes are `f64`-valued; `Guard` is the one node with control flow: it passes its operand on
//! when it is a usable pivot and makes the generated function return `Err(Singular)` otherwise.

#![allow(clippy::redundant_guards, clippy::collapsible_if)] // float guards read clearer than float patterns

pub mod derivative;

use indexmap::IndexSet;
use rustc_hash::FxBuildHasher;

/// Index of a node in a [`Graph`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ExprId(pub u32);

/// A generated function's array argument (`q`, `qd`, `qdd`, `tau`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Arg {
    /// Joint positions.
    Q,
    /// Joint velocities.
    Qd,
    /// Joint accelerations.
    Qdd,
    /// Joint efforts.
    Tau,
    /// Platform coordinates (parallel mechanisms): `[f64; NX]`.
    X,
    /// Platform speeds (parallel mechanisms).
    U,
    /// Platform speed rates (parallel mechanisms).
    Ud,
    /// Run-time parameters (`[scene] parameters = "runtime"`): `p: &Params`, read through
    /// `Params::to_array` (layout in `dynamics::param_index`).
    P,
}

impl Arg {
    /// The argument's name in generated code.
    pub fn name(self) -> &'static str {
        match self {
            Arg::Q => "q",
            Arg::Qd => "qd",
            Arg::Qdd => "qdd",
            Arg::Tau => "tau",
            Arg::X => "x",
            Arg::U => "u",
            Arg::Ud => "ud",
            Arg::P => "p",
        }
    }
}

/// One scalar operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant, stored as canonical `f64` bits (never NaN, never −0).
    Const(u64),
    /// `arg[index]`.
    Input(Arg, u16),
    /// `a + b` (operands in canonical order).
    Add(ExprId, ExprId),
    /// `a − b`.
    Sub(ExprId, ExprId),
    /// `a · b` (operands in canonical order).
    Mul(ExprId, ExprId),
    /// `a / b`.
    Div(ExprId, ExprId),
    /// `−a`.
    Neg(ExprId),
    /// `√a`.
    Sqrt(ExprId),
    /// `sin a` (emitted with its `cos` as one `sin_cos` call).
    Sin(ExprId),
    /// `cos a`.
    Cos(ExprId),
    /// `atan2(a, b)`: the angle of the point `(b, a)`.
    Atan2(ExprId, ExprId),
    /// `if |a| > |b| { x } else { y }` (NaN compares false): the data-dependent choice of
    /// partial pivoting, emitted as a conditional move.
    Select(ExprId, ExprId, ExprId, ExprId),
    /// Pivot `index` of a factorization: the operand when it is `> tol` (a node), else the
    /// function returns `Err(Singular)`; `scale` is the matrix diagonal entry the pivot came from
    /// (for the condition estimate). With [`TWO_SIDED`] set in `index` the test is
    /// `|value| > tol`; the rest of `index` is a site code (`runtime::scalar::Site::code`;
    /// for trees the pivot).
    Guard {
        value: ExprId,
        tol: ExprId,
        scale: ExprId,
        index: u16,
    },
}

/// Flag in a guard's `index`: the test is `|value| > tol`.
pub const TWO_SIDED: u16 = 0x8000;

/// The expression DAG.
#[derive(Default, Clone)]
pub struct Graph {
    nodes: IndexSet<Node, FxBuildHasher>,
    /// Every guard asked for since the last [`Graph::take_guards`], in the order asked (a guard
    /// is a test the evaluator performs: the function that asked for it must schedule it
    /// whether or not any output uses its value).
    guards: Vec<ExprId>,
}

impl Graph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// `true` when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node behind `id`.
    pub fn node(&self, id: ExprId) -> Node {
        self.nodes[id.0 as usize]
    }

    /// The id of `n` if the graph holds it.
    pub fn lookup(&self, n: Node) -> Option<ExprId> {
        self.nodes.get_index_of(&n).map(|i| ExprId(i as u32))
    }

    fn intern(&mut self, n: Node) -> ExprId {
        let (i, _) = self.nodes.insert_full(n);
        ExprId(i as u32)
    }

    /// The constant `v` (−0 is stored as 0). `v` must not be NaN (callers validate the model).
    pub fn constant(&mut self, v: f64) -> ExprId {
        debug_assert!(!v.is_nan(), "NaN constant in the expression graph");
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Node::Const(v.to_bits()))
    }

    /// `0`.
    pub fn zero(&mut self) -> ExprId {
        self.constant(0.0)
    }

    /// `arg[index]`.
    pub fn input(&mut self, arg: Arg, index: usize) -> ExprId {
        self.intern(Node::Input(arg, index as u16))
    }

    /// The value of a constant node.
    pub fn as_const(&self, id: ExprId) -> Option<f64> {
        match self.node(id) {
            Node::Const(b) => Some(f64::from_bits(b)),
            _ => None,
        }
    }

    /// `true` when `id` is the constant `v`.
    pub fn is_const(&self, id: ExprId, v: f64) -> bool {
        self.as_const(id) == Some(v)
    }

    /// `a + b`.
    pub fn add(&mut self, a: ExprId, b: ExprId) -> ExprId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x + y),
            (Some(x), _) if x == 0.0 => return b,
            (_, Some(y)) if y == 0.0 => return a,
            // c + (d + y) = (c + d) + y
            (Some(c), None) | (None, Some(c)) => {
                let other = if self.as_const(a).is_some() { b } else { a };
                if let Node::Add(p, y) = self.node(other) {
                    if let Some(d) = self.as_const(p).or_else(|| self.as_const(y)) {
                        let rest = if self.as_const(p).is_some() { y } else { p };
                        let k = self.constant(c + d);
                        return self.add(k, rest);
                    }
                }
            }
            _ => {}
        }
        if a == b {
            // x + x = 2x (and 2·(c·x) folds into one product).
            return self.scale(2.0, a);
        }
        match (self.node(a), self.node(b)) {
            (Node::Neg(x), Node::Neg(y)) => {
                let s = self.add(x, y);
                self.neg(s)
            }
            (Node::Neg(x), _) => self.sub(b, x),
            (_, Node::Neg(y)) => self.sub(a, y),
            _ => {
                let (a, b) = if a <= b { (a, b) } else { (b, a) };
                self.intern(Node::Add(a, b))
            }
        }
    }

    /// `a − b`.
    pub fn sub(&mut self, a: ExprId, b: ExprId) -> ExprId {
        if a == b {
            return self.zero();
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x - y),
            (Some(x), _) if x == 0.0 => return self.neg(b),
            (_, Some(y)) if y == 0.0 => return a,
            _ => {}
        }
        match (self.node(a), self.node(b)) {
            (_, Node::Neg(y)) => self.add(a, y),
            (Node::Neg(x), _) => {
                let s = self.add(x, b);
                self.neg(s)
            }
            _ => self.intern(Node::Sub(a, b)),
        }
    }

    /// `a · b`.
    pub fn mul(&mut self, a: ExprId, b: ExprId) -> ExprId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x * y),
            (Some(x), _) => return self.scale(x, b),
            (_, Some(y)) => return self.scale(y, a),
            _ => {}
        }
        match (self.node(a), self.node(b)) {
            (Node::Neg(x), Node::Neg(y)) => self.mul(x, y),
            (Node::Neg(x), _) => {
                let p = self.mul(x, b);
                self.neg(p)
            }
            (_, Node::Neg(y)) => {
                let p = self.mul(a, y);
                self.neg(p)
            }
            _ => {
                let (a, b) = if a <= b { (a, b) } else { (b, a) };
                self.intern(Node::Mul(a, b))
            }
        }
    }

    /// `c · x` for a constant `c`. Canonical form: `Mul(c, x)` with `c > 0`, and `−(|c|·x)` for
    /// negative `c`, so that negations can be absorbed by the sums that use them.
    pub fn scale(&mut self, c: f64, x: ExprId) -> ExprId {
        if c == 0.0 {
            return self.zero();
        }
        if c == 1.0 {
            return x;
        }
        if c == -1.0 {
            return self.neg(x);
        }
        match self.node(x) {
            Node::Const(b) => self.constant(c * f64::from_bits(b)),
            Node::Neg(y) => self.scale(-c, y),
            Node::Mul(p, y) if self.as_const(p).is_some() => {
                let k = self.as_const(p).unwrap_or(1.0) * c;
                self.scale(k, y)
            }
            Node::Mul(y, p) if self.as_const(p).is_some() => {
                let k = self.as_const(p).unwrap_or(1.0) * c;
                self.scale(k, y)
            }
            _ => {
                if c < 0.0 {
                    let p = self.scale(-c, x);
                    return self.neg(p);
                }
                let k = self.constant(c);
                let (a, b) = if k <= x { (k, x) } else { (x, k) };
                self.intern(Node::Mul(a, b))
            }
        }
    }

    /// `a / b`.
    pub fn div(&mut self, a: ExprId, b: ExprId) -> ExprId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) if y != 0.0 => return self.constant(x / y),
            (Some(x), _) if x == 0.0 => return a,
            (_, Some(y)) if y == 1.0 => return a,
            (_, Some(y)) if y == -1.0 => return self.neg(a),
            _ => {}
        }
        self.intern(Node::Div(a, b))
    }

    /// `−a`.
    pub fn neg(&mut self, a: ExprId) -> ExprId {
        match self.node(a) {
            Node::Const(b) => self.constant(-f64::from_bits(b)),
            Node::Neg(x) => x,
            Node::Sub(x, y) => self.sub(y, x),
            // Constant factors are kept positive: `−(c·x)` stays a negation (see `scale`).
            _ => self.intern(Node::Neg(a)),
        }
    }

    /// `√a`.
    pub fn sqrt(&mut self, a: ExprId) -> ExprId {
        match self.as_const(a) {
            Some(x) if x >= 0.0 => self.constant(x.sqrt()),
            _ => self.intern(Node::Sqrt(a)),
        }
    }

    /// `sin a`.
    pub fn sin(&mut self, a: ExprId) -> ExprId {
        match self.as_const(a) {
            Some(x) => self.constant(runtime::model::exact_sin_cos(x).0),
            None => self.intern(Node::Sin(a)),
        }
    }

    /// `cos a`.
    pub fn cos(&mut self, a: ExprId) -> ExprId {
        match self.as_const(a) {
            Some(x) => self.constant(runtime::model::exact_sin_cos(x).1),
            None => self.intern(Node::Cos(a)),
        }
    }

    /// `atan2(a, b)`.
    pub fn atan2(&mut self, a: ExprId, b: ExprId) -> ExprId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(y), Some(x)) => self.constant(y.atan2(x)),
            _ => self.intern(Node::Atan2(a, b)),
        }
    }

    /// `if |a| > |b| { x } else { y }`, folded when the choice is known: equal branches,
    /// constant magnitudes, or a constant zero `a` (never larger).
    pub fn select_abs_gt(&mut self, a: ExprId, b: ExprId, x: ExprId, y: ExprId) -> ExprId {
        if x == y {
            return x;
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(p), Some(q)) => {
                if p.abs() > q.abs() {
                    x
                } else {
                    y
                }
            }
            (Some(p), None) if p == 0.0 => y,
            _ if a == b => y,
            _ => self.intern(Node::Select(a, b, x, y)),
        }
    }

    /// A checked pivot (see [`Node::Guard`]), logged for [`Graph::take_guards`].
    pub fn guard(&mut self, value: ExprId, tol: ExprId, scale: ExprId, index: usize) -> ExprId {
        let id = self.intern(Node::Guard {
            value,
            tol,
            scale,
            index: index as u16,
        });
        self.guards.push(id);
        id
    }

    /// The guards asked for since the last call, each once, in the order first asked; the log
    /// is left empty. A function's schedule takes them as roots ([`crate::schedule::schedule`]),
    /// so a test the evaluator performs reaches the output even when nothing reads the value
    /// it passes on (the last pivot of a square LU feeds no row below it).
    pub fn take_guards(&mut self) -> Vec<ExprId> {
        let mut seen = std::collections::HashSet::new();
        std::mem::take(&mut self.guards)
            .into_iter()
            .filter(|&id| seen.insert(id))
            .collect()
    }

    /// Append `guards` to the log (to hand a nested capture's guards on to the enclosing one).
    pub fn log_guards(&mut self, guards: &[ExprId]) {
        self.guards.extend_from_slice(guards);
    }

    /// Operands of a node, in order.
    pub fn operands(&self, id: ExprId) -> impl Iterator<Item = ExprId> {
        let ops: [Option<ExprId>; 4] = match self.node(id) {
            Node::Const(_) | Node::Input(..) => [None, None, None, None],
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Atan2(a, b) => [Some(a), Some(b), None, None],
            Node::Neg(a) | Node::Sqrt(a) | Node::Sin(a) | Node::Cos(a) => {
                [Some(a), None, None, None]
            }
            Node::Select(a, b, x, y) => [Some(a), Some(b), Some(x), Some(y)],
            Node::Guard {
                value, tol, scale, ..
            } => [Some(value), Some(tol), Some(scale), None],
        };
        ops.into_iter().flatten()
    }

    /// Evaluate `roots` for the given inputs (an interpreter: the generator's own oracle).
    /// A failed guard evaluates to NaN.
    pub fn eval(&self, roots: &[ExprId], input: &dyn Fn(Arg, usize) -> f64) -> Vec<f64> {
        let mut val: Vec<Option<f64>> = vec![None; self.len()];
        let mut stack: Vec<(ExprId, bool)> = roots.iter().map(|&r| (r, false)).collect();
        while let Some((id, expanded)) = stack.pop() {
            if val[id.0 as usize].is_some() {
                continue;
            }
            if !expanded {
                stack.push((id, true));
                for o in self.operands(id) {
                    if val[o.0 as usize].is_none() {
                        stack.push((o, false));
                    }
                }
                continue;
            }
            let v = |x: ExprId| val[x.0 as usize].unwrap_or(f64::NAN);
            let r = match self.node(id) {
                Node::Const(b) => f64::from_bits(b),
                Node::Input(a, i) => input(a, i as usize),
                Node::Add(a, b) => v(a) + v(b),
                Node::Sub(a, b) => v(a) - v(b),
                Node::Mul(a, b) => v(a) * v(b),
                Node::Div(a, b) => v(a) / v(b),
                Node::Neg(a) => -v(a),
                Node::Sqrt(a) => v(a).sqrt(),
                Node::Sin(a) => v(a).sin(),
                Node::Cos(a) => v(a).cos(),
                Node::Atan2(a, b) => v(a).atan2(v(b)),
                Node::Select(a, b, x, y) => {
                    if v(a).abs() > v(b).abs() {
                        v(x)
                    } else {
                        v(y)
                    }
                }
                Node::Guard {
                    value, tol, index, ..
                } => {
                    let ok = if index & TWO_SIDED != 0 {
                        v(value).abs() > v(tol)
                    } else {
                        v(value) > v(tol)
                    };
                    if ok { v(value) } else { f64::NAN }
                }
            };
            val[id.0 as usize] = Some(r);
        }
        roots
            .iter()
            .map(|r| val[r.0 as usize].unwrap_or(f64::NAN))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folding_and_sharing() {
        let mut g = Graph::new();
        let x = g.input(Arg::Q, 0);
        let y = g.input(Arg::Q, 1);
        let zero = g.zero();
        let one = g.constant(1.0);
        assert_eq!(g.add(x, zero), x);
        assert_eq!(g.mul(x, one), x);
        assert_eq!(g.mul(x, zero), zero);
        assert_eq!(g.sub(x, x), zero);
        let nx = g.neg(x);
        assert_eq!(g.neg(nx), x);
        // x + (−y) is x − y; y·x is x·y (shared).
        let ny = g.neg(y);
        let s1 = g.add(x, ny);
        let s2 = g.sub(x, y);
        assert_eq!(s1, s2);
        let p1 = g.mul(x, y);
        let p2 = g.mul(y, x);
        assert_eq!(p1, p2);
        // (−x)·(−y) = x·y; 2·(3·x) = 6·x.
        assert_eq!(g.mul(nx, ny), p1);
        let t = g.scale(3.0, x);
        let s = g.scale(2.0, t);
        assert_eq!(s, g.scale(6.0, x));
        // −(a − b) = b − a.
        let d = g.neg(s2);
        assert_eq!(d, g.sub(y, x));
    }

    #[test]
    fn eval_matches_arithmetic() {
        let mut g = Graph::new();
        let x = g.input(Arg::Q, 0);
        let y = g.input(Arg::Qd, 0);
        let s = g.sin(x);
        let c = g.cos(x);
        let a = g.mul(s, y);
        let b = g.sub(a, c);
        let r = g.eval(&[b], &|arg, _| if arg == Arg::Q { 0.3 } else { 2.0 });
        assert!((r[0] - (0.3f64.sin() * 2.0 - 0.3f64.cos())).abs() < 1e-15);
    }
}

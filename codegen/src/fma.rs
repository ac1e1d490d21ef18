//! Fused multiply–add ([`crate::Config::fma`]): `a*b + c`, `a*b - c` and `c - a*b` as one
//! `mul_add` with a single rounding.
//!
//! Rust never contracts `a*b + c` by itself, so a scheduled function is rewritten after
//! [`crate::schedule::schedule`]: an `Add` or `Sub` step one of whose operands is a `Mul` that
//! nothing else reads (not another step, not a guard, not an output) becomes one
//! [`Step::MulAdd`], and the `Mul`'s own step goes. When both operands qualify, the left one is
//! fused. The rule depends only on the schedule, so the output stays deterministic.
//!
//! Each fusion removes one `mul` and one `add` from the function's [`OpCount`](crate::schedule::OpCount) and adds one
//! `fma`; [`OpCount::flops`](crate::schedule::OpCount::flops) counts an `fma` as two, so the flops stay what they were.
//! Off (the default), nothing here runs and the output is byte for byte what it was.
//!
//! The call is the math backend's: `libm::fma` (`fmaf`), `f64::mul_add` (std), or
//! `<runtime>::math::mul_add` (`mul_add_f32`). `f64::mul_add` is one instruction only where the
//! target has FMA (`-C target-cpu=native`, `-C target-feature=+fma`); elsewhere it is a call to
//! the platform's `fma`, which is correct but slow. The runtime's is the instruction there with
//! or without std; `libm::fma` on x86 is a call through a pointer chosen at run time.

use std::cell::Cell;
use std::collections::HashMap;

use proc_macro2::TokenStream;
use quote::quote;

use crate::Config;
use crate::schedule::{Kernel, Operand, Schedule, Step};
use crate::sym::{ExprId, Graph, Node};

thread_local! {
    /// The current generation fuses multiply–adds.
    static ON: Cell<bool> = const { Cell::new(false) };
}

/// Run `f` with fusion on or off (the generation's [`crate::Config::fma`]).
pub(crate) fn with<T>(on: bool, f: impl FnOnce() -> T) -> T {
    let before = ON.with(|c| c.replace(on));
    let out = f();
    ON.with(|c| c.set(before));
    out
}

/// The current generation fuses multiply–adds.
pub(crate) fn enabled() -> bool {
    ON.with(|c| c.get())
}

/// The node a reference to `id` reads: a guard passes its value on.
fn resolve(g: &Graph, mut id: ExprId) -> ExprId {
    while let Node::Guard { value, .. } = g.node(id) {
        id = value;
    }
    id
}

/// Fuse `s` (the schedule of `k`) in place: see the module docs.
pub(crate) fn fuse(g: &Graph, k: &Kernel, s: &mut Schedule) {
    let mut uses: HashMap<ExprId, usize> = HashMap::new();
    for step in &s.steps {
        let read: Vec<ExprId> = match *step {
            Step::Let { node, .. } | Step::Check { node } => g.operands(node).collect(),
            Step::SinCos { arg, .. } => vec![arg],
            Step::SinCosBatch => s.batch.iter().map(|&(_, _, arg)| arg).collect(),
            Step::MulAdd { .. } => Vec::new(),
        };
        for id in read {
            *uses.entry(resolve(g, id)).or_default() += 1;
        }
    }
    // An output is read by the caller: never fused away.
    for &o in k.outputs.iter().chain(&k.guards) {
        *uses.entry(resolve(g, o)).or_default() += 2;
    }
    let single_mul = |id: ExprId| {
        let id = resolve(g, id);
        matches!(g.node(id), Node::Mul(..)) && uses.get(&id) == Some(&1)
    };
    let mut fused: HashMap<ExprId, ()> = HashMap::new();
    for step in s.steps.iter_mut() {
        let Step::Let { name, node } = *step else {
            continue;
        };
        let (Node::Add(a, b) | Node::Sub(a, b)) = g.node(node) else {
            continue;
        };
        let mul = if single_mul(a) {
            resolve(g, a)
        } else if single_mul(b) {
            resolve(g, b)
        } else {
            continue;
        };
        fused.insert(mul, ());
        *step = Step::MulAdd { name, node, mul };
    }
    s.steps
        .retain(|st| !matches!(*st, Step::Let { node, .. } if fused.contains_key(&node)));
    for mul in fused.keys() {
        s.names.remove(mul);
    }
    s.ops.mul -= fused.len();
    s.ops.add -= fused.len();
    s.ops.fma += fused.len();
}

/// The parts of a fused step: `(a, b, c, negate a, negate c)` for
/// `mul_add(±a, b, ±c)`.
pub(crate) fn parts(g: &Graph, node: ExprId, mul: ExprId) -> (ExprId, ExprId, ExprId, bool, bool) {
    let Node::Mul(a, b) = g.node(mul) else {
        panic!("internal error: a fused multiply–add of a node that is no product");
    };
    match g.node(node) {
        Node::Add(x, y) => (a, b, if resolve(g, x) == mul { y } else { x }, false, false),
        // `m - c` = mul_add(a, b, -c); `c - m` = mul_add(-a, b, c).
        Node::Sub(x, y) if resolve(g, x) == mul => (a, b, y, false, true),
        Node::Sub(x, _) => (a, b, x, true, false),
        _ => panic!("internal error: a fused multiply–add of a node that is no sum"),
    }
}

/// The variables a fused step reads (for the block split of long bodies).
pub(crate) fn reads(g: &Graph, s: &Schedule, node: ExprId, mul: ExprId) -> Vec<usize> {
    let (a, b, c, _, _) = parts(g, node, mul);
    [a, b, c]
        .into_iter()
        .filter_map(|id| match s.operand(g, id) {
            Operand::Var(n) => Some(n),
            _ => None,
        })
        .collect()
}

/// The three arguments of `mul_add(±a, b, ±c)` of a fused step; `operand` writes an operand
/// (scalar or lanes) and `lit` a constant (negated ones are written as constants).
pub(crate) fn args(
    g: &Graph,
    node: ExprId,
    mul: ExprId,
    operand: &dyn Fn(ExprId) -> TokenStream,
    lit: &dyn Fn(f64) -> TokenStream,
) -> [TokenStream; 3] {
    let (a, b, c, neg_a, neg_c) = parts(g, node, mul);
    let neg = |id: ExprId, on: bool| {
        if !on {
            return operand(id);
        }
        match g.as_const(id) {
            Some(v) => lit(-v),
            None => {
                let x = operand(id);
                quote!(-#x)
            }
        }
    };
    [neg(a, neg_a), operand(b), neg(c, neg_c)]
}

/// The scalar expression of a fused step: the math backend's `mul_add`.
pub(crate) fn call(
    g: &Graph,
    cfg: &Config,
    node: ExprId,
    mul: ExprId,
    operand: &dyn Fn(ExprId) -> TokenStream,
) -> TokenStream {
    let [a, b, c] = args(g, node, mul, operand, &crate::emit::float_lit);
    crate::emit::math_call(cfg, "mul_add", quote!(#a, #b, #c))
}

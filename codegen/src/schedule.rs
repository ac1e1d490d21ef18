//! The optimized DAG of one function: dead-code removal, deterministic ordering and the
//! operation count.
//!
//! Only nodes reachable from the function's outputs are kept (dead-code removal); they are put
//! in depth-first post-order, operands in order and outputs in order, which depends on nothing
//! but the graph — so the same spec always yields the same statements. `sin` and `cos` of one
//! argument become a single `sin_cos` step.

use std::collections::HashMap;
use std::fmt;

use crate::sym::{ExprId, Graph, Node};

/// Operation counts of one function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Negations.
    pub neg: usize,
    /// Divisions.
    pub div: usize,
    /// Square roots.
    pub sqrt: usize,
    /// `sin_cos` calls (one per joint angle used).
    pub sin_cos: usize,
    /// Pivot checks (comparisons).
    pub cmp: usize,
    /// `atan2` calls (parallel mechanisms: revolute actuator angles).
    pub atan2: usize,
    /// Fused multiply–adds (`mul_add`, one rounding), with [`crate::Config::fma`] only: each
    /// replaces one `mul` and one `add` ([`crate::fma`]).
    pub fma: usize,
}

impl OpCount {
    /// Arithmetic operations: add + mul + neg + div + sqrt + 2 × fma (trigonometry and
    /// comparisons apart). A fused multiply–add is two of them, a multiply and an add, so that
    /// the count is the same with and without fusion.
    pub fn flops(&self) -> usize {
        self.add + self.mul + self.neg + self.div + self.sqrt + 2 * self.fma
    }
}

impl fmt::Display for OpCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} flops ({} add, {} mul, {} neg, {} div, {} sqrt), {} sin_cos, {} cmp",
            self.flops(),
            self.add,
            self.mul,
            self.neg,
            self.div,
            self.sqrt,
            self.sin_cos,
            self.cmp
        )?;
        if self.atan2 > 0 {
            write!(f, ", {} atan2", self.atan2)?;
        }
        if self.fma > 0 {
            write!(f, ", {} fma (counted as 2 flops each)", self.fma)?;
        }
        Ok(())
    }
}

/// One statement of a scheduled function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// `let x{name} = <node>;`
    Let { name: usize, node: ExprId },
    /// `let (x{sin}, x{cos}) = sin_cos(<arg>);`
    SinCos { sin: usize, cos: usize, arg: ExprId },
    /// The `sin_cos` of every pair in [`Schedule::batch`] in one call
    /// ([`crate::Config::batch_sin_cos`]).
    SinCosBatch,
    /// Pivot check of a `Guard` node: return `Err` unless the value exceeds the tolerance.
    Check { node: ExprId },
    /// `let x{name} = mul_add(…);`: the `Add` or `Sub` `node` with its operand `mul` (a `Mul`
    /// read nowhere else) fused into it ([`crate::fma`]).
    MulAdd {
        name: usize,
        node: ExprId,
        mul: ExprId,
    },
}

/// How an operand is referred to in generated code.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operand {
    /// A `let` binding `x{n}`.
    Var(usize),
    /// A literal.
    Const(f64),
    /// `arg[index]`.
    Input(crate::sym::Arg, u16),
}

/// A function's statements in order, with the name of every node it uses.
#[derive(Clone, Debug, Default)]
pub struct Schedule {
    /// Statements.
    pub steps: Vec<Step>,
    pub(crate) names: HashMap<ExprId, usize>,
    /// Operation count.
    pub ops: OpCount,
    /// The `(sin, cos, arg)` of the [`Step::SinCosBatch`] (empty without one).
    pub batch: Vec<(usize, usize, ExprId)>,
}

impl Schedule {
    /// How `id` is written in the function body (after its statement).
    pub fn operand(&self, g: &Graph, id: ExprId) -> Operand {
        match g.node(id) {
            Node::Const(b) => Operand::Const(f64::from_bits(b)),
            Node::Input(a, i) => Operand::Input(a, i),
            Node::Guard { value, .. } => self.operand(g, value),
            _ => Operand::Var(self.names[&id]),
        }
    }
}

/// One function's DAG: its outputs and every guard its evaluation asked for
/// ([`Graph::take_guards`]; the symbolic scalar captures them per function).
#[derive(Clone, Debug, Default)]
pub struct Kernel {
    /// The values the function returns, in order.
    pub outputs: Vec<ExprId>,
    /// The tests the function performs, in the order the evaluator asked for them.
    pub guards: Vec<ExprId>,
}

impl Kernel {
    /// `outputs` with the `guards` they were computed under.
    pub fn new(outputs: Vec<ExprId>, guards: Vec<ExprId>) -> Kernel {
        Kernel { outputs, guards }
    }
}

/// Schedule the nodes that a function's guards and outputs need: the guards first, in the
/// order the evaluator asked for them (so the first failing test is the one the `f64`
/// evaluator reports), then the outputs. Every guard is a root: a test never vanishes as dead
/// code because no output reads the value it passes on.
pub fn schedule(g: &Graph, k: &Kernel) -> Schedule {
    debug_assert!(
        k.guards
            .iter()
            .all(|&id| matches!(g.node(id), Node::Guard { .. })),
        "a guard root that is not a guard"
    );
    let roots: Vec<ExprId> = k.guards.iter().chain(&k.outputs).copied().collect();
    let mut s = Schedule::default();
    let mut done: HashMap<ExprId, ()> = HashMap::new();
    let mut next = 0usize;
    let mut stack: Vec<(ExprId, bool)> = roots.iter().rev().map(|&r| (r, false)).collect();
    while let Some((id, expanded)) = stack.pop() {
        if done.contains_key(&id) {
            continue;
        }
        if !expanded {
            stack.push((id, true));
            let ops: Vec<ExprId> = g.operands(id).collect();
            for &o in ops.iter().rev() {
                if !done.contains_key(&o) {
                    stack.push((o, false));
                }
            }
            continue;
        }
        done.insert(id, ());
        match g.node(id) {
            Node::Const(_) | Node::Input(..) => {}
            Node::Sin(a) | Node::Cos(a) => {
                // Name both halves of the pair at once.
                let (sin, cos) = (next, next + 1);
                next += 2;
                s.steps.push(Step::SinCos { sin, cos, arg: a });
                s.ops.sin_cos += 1;
                for (node, name) in [(Node::Sin(a), sin), (Node::Cos(a), cos)] {
                    if let Some(other) = g.lookup(node) {
                        s.names.insert(other, name);
                        done.insert(other, ());
                    }
                }
            }
            Node::Guard { .. } => {
                s.steps.push(Step::Check { node: id });
                s.ops.cmp += 1;
            }
            n => {
                match n {
                    Node::Add(..) | Node::Sub(..) => s.ops.add += 1,
                    Node::Mul(..) => s.ops.mul += 1,
                    Node::Div(..) => s.ops.div += 1,
                    Node::Neg(..) => s.ops.neg += 1,
                    Node::Sqrt(..) => s.ops.sqrt += 1,
                    Node::Atan2(..) => s.ops.atan2 += 1,
                    Node::Select(..) => s.ops.cmp += 1,
                    _ => {}
                }
                s.names.insert(id, next);
                s.steps.push(Step::Let {
                    name: next,
                    node: id,
                });
                next += 1;
            }
        }
    }
    if crate::fma::enabled() {
        crate::fma::fuse(g, k, &mut s);
    }
    s
}

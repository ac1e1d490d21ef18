//! Operation counts of graph cones: the nodes already paid for and the marginal cost of a
//! choice (for the frame search and the per-body moment forms).

use crate::sym::{ExprId, Graph, Node};

/// Nodes already needed (their cost is sunk), indexed by node id.
#[derive(Clone, Default)]
pub(super) struct Paid(pub(super) Vec<bool>);

impl Paid {
    pub(super) fn contains(&self, id: ExprId) -> bool {
        self.0.get(id.0 as usize).copied().unwrap_or(false)
    }
    /// Add the cone of `roots`.
    pub(super) fn pay(&mut self, g: &Graph, roots: &[ExprId]) {
        if self.0.len() < g.len() {
            self.0.resize(g.len(), false);
        }
        let mut stack: Vec<ExprId> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if !self.0[id.0 as usize] {
                self.0[id.0 as usize] = true;
                stack.extend(g.operands(id));
            }
        }
    }
}

/// `true` for the nodes that [`crate::schedule::OpCount::flops`] counts.
pub(super) fn is_flop(n: Node) -> bool {
    matches!(
        n,
        Node::Add(..)
            | Node::Sub(..)
            | Node::Mul(..)
            | Node::Div(..)
            | Node::Neg(..)
            | Node::Sqrt(..)
    )
}

/// Arithmetic operations (as counted by [`crate::schedule::OpCount::flops`]) that `roots` need
/// beyond the nodes in `paid`: the marginal cost of a choice.
pub(super) fn marginal_flops(g: &Graph, roots: &[ExprId], paid: &Paid) -> usize {
    let mut seen: rustc_hash::FxHashSet<ExprId> = Default::default();
    let mut stack: Vec<ExprId> = roots.to_vec();
    let mut flops = 0;
    while let Some(id) = stack.pop() {
        if paid.contains(id) || !seen.insert(id) {
            continue;
        }
        if is_flop(g.node(id)) {
            flops += 1;
        }
        stack.extend(g.operands(id));
    }
    flops
}

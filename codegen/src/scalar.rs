//! The symbolic scalar: [`runtime::scalar::Real`] implemented by recording one node of the
//! hash-consed DAG ([`crate::sym`]) per operation, so that the runtime's generic evaluators
//! (parallel mechanisms, closed loops) become the generator's expression builders.

use std::cell::RefCell;
use std::ops::{Add, Div, Mul, Neg, Sub};

use runtime::scalar::{Real, Singular, Site};

use crate::sym::{Arg, ExprId, Graph, TWO_SIDED};

thread_local! {
    /// The graph the symbolic scalars of the current generation write to.
    static GRAPH: RefCell<Graph> = RefCell::new(Graph::new());
    /// The current generation targets `f32`: thresholds are rescaled ([`tolerance`]).
    static SINGLE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Run `f` on a fresh graph and return its result with the graph it built.
pub(crate) fn in_fresh_graph<T>(f: impl FnOnce() -> T) -> (T, Graph) {
    with(|g| *g = Graph::new());
    let r = f();
    (r, with(std::mem::take))
}

/// Run `f` with the thresholds of the target precision (`f32` when `single`).
pub(crate) fn with_precision<T>(single: bool, f: impl FnOnce() -> T) -> T {
    let before = SINGLE.with(|c| c.replace(single));
    let out = f();
    SINGLE.with(|c| c.set(before));
    out
}

/// The current generation targets `f32`.
pub(crate) fn single() -> bool {
    SINGLE.with(|c| c.get())
}

/// The threshold for the current target of a test whose `f64` threshold is `t`.
pub(crate) fn tolerance(t: f64) -> f64 {
    if single() {
        runtime::scalar::f32_tolerance(t)
    } else {
        t
    }
}

/// Run `f` and return its result with every guard it asked for (each once, in the order first
/// asked): the guard roots of the function `f` evaluates. A capture inside another hands its
/// guards on to the outer one.
pub(crate) fn guarded<T>(f: impl FnOnce() -> T) -> (T, Vec<ExprId>) {
    let outer = with(|g| g.take_guards());
    let r = f();
    let inner = with(|g| {
        let inner = g.take_guards();
        g.log_guards(&outer);
        g.log_guards(&inner);
        inner
    });
    (r, inner)
}

pub(crate) fn with<T>(f: impl FnOnce(&mut Graph) -> T) -> T {
    GRAPH.with(|c| f(&mut c.borrow_mut()))
}

/// A symbolic scalar: a node of the thread's current graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Sx(pub(crate) ExprId);

macro_rules! binop {
    ($tr:ident, $m:ident, $g:ident) => {
        impl $tr for Sx {
            type Output = Sx;
            fn $m(self, o: Sx) -> Sx {
                Sx(with(|g| g.$g(self.0, o.0)))
            }
        }
    };
}
binop!(Add, add, add);
binop!(Sub, sub, sub);
binop!(Mul, mul, mul);
binop!(Div, div, div);

impl Neg for Sx {
    type Output = Sx;
    fn neg(self) -> Sx {
        Sx(with(|g| g.neg(self.0)))
    }
}

impl Real for Sx {
    fn c(v: f64) -> Sx {
        Sx(with(|g| g.constant(v)))
    }
    fn sqrt(self) -> Sx {
        Sx(with(|g| g.sqrt(self.0)))
    }
    fn atan2(self, x: Sx) -> Sx {
        Sx(with(|g| g.atan2(self.0, x.0)))
    }
    fn sin_cos(self) -> (Sx, Sx) {
        with(|g| (Sx(g.sin(self.0)), Sx(g.cos(self.0))))
    }
    fn tolerance(t: f64) -> f64 {
        tolerance(t)
    }
    fn select_abs_gt(a: Sx, b: Sx, x: Sx, y: Sx) -> Sx {
        Sx(with(|g| g.select_abs_gt(a.0, b.0, x.0, y.0)))
    }
    fn check(
        value: Sx,
        threshold: Sx,
        scale: Sx,
        site: Site,
        two_sided: bool,
    ) -> Result<Sx, Singular> {
        let consts = with(|g| (g.as_const(value.0), g.as_const(threshold.0)));
        if let (Some(v), Some(t)) = consts {
            // Decided at generation time.
            return f64::check(
                v,
                t,
                with(|g| g.as_const(scale.0)).unwrap_or(1.0),
                site,
                two_sided,
            )
            .map(|_| value);
        }
        let code = site.code() | if two_sided { TWO_SIDED } else { 0 };
        Ok(Sx(with(|g| {
            g.guard(value.0, threshold.0, scale.0, code as usize)
        })))
    }
}

pub(crate) fn inputs(arg: Arg, n: usize) -> Vec<Sx> {
    (0..n).map(|i| Sx(with(|g| g.input(arg, i)))).collect()
}

pub(crate) fn ids(v: &[Sx]) -> Vec<ExprId> {
    v.iter().map(|s| s.0).collect()
}

pub(crate) fn flat(m: &[Vec<Sx>]) -> Vec<ExprId> {
    m.iter().flatten().map(|s| s.0).collect()
}

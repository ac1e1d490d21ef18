//! The module plan: what a generated module contains, in the order it is written. Every
//! mechanism kind returns one ([`crate::tree`], [`crate::parallel`], [`crate::closed`]), and
//! [`render`] is the one place that writes a module: the header comment, the items before the
//! functions (constants, error types, `Params`, the fixed templates), the scheduled functions,
//! the items that wrap them, and the inertia-index template every module has.

use proc_macro2::TokenStream;
use quote::quote;

use crate::Config;
use crate::emit::{self, Function, Shape};
use crate::schedule::{Kernel, schedule};
use crate::sym::{Arg, Graph};

/// A generated module before it is written.
pub(crate) struct ModulePlan<'g> {
    /// The mechanism's name (the spec's).
    pub name: &'g str,
    /// The header comment, one line an entry (without `// `).
    pub header: Vec<String>,
    /// The items before the functions.
    pub items: TokenStream,
    /// The DAG the functions read.
    pub graph: &'g Graph,
    /// The scheduled functions, in emission order.
    pub functions: Vec<Function<'g>>,
    /// Items after the functions (wrappers of them).
    pub after: TokenStream,
}

/// The module's text: `plan` rendered in `cfg`'s math backend.
pub(crate) fn render(plan: &ModulePlan<'_>, cfg: &Config) -> String {
    let items = &plan.items;
    let fns = plan
        .functions
        .iter()
        .map(|f| emit::function(plan.graph, cfg, f));
    let after = &plan.after;
    let indices = crate::indices::template(cfg);
    let mut module = quote! {
        #items
        #(#fns)*
        #after
        #indices
    };
    if let Some(runtime) = &cfg.implement {
        module.extend(crate::implement::items(&module, runtime, plan.name));
    }
    if let Some(l) = cfg.lanes {
        module.extend(crate::lanes::items(plan.graph, cfg, &plan.functions, l));
    }
    let batches = crate::sin_cos::batches(cfg, plan.graph, &plan.functions);
    if batches {
        module.extend(crate::sin_cos::batch_items(cfg));
    }
    let mut header = plan.header.clone();
    // The options are named right after the math backend (the table follows), each inserted
    // there, so the last one inserted comes first.
    let mut after_math_backend = |line: String| {
        let at = header
            .iter()
            .position(|h| h.starts_with("Math backend"))
            .map_or(header.len(), |i| i + 1);
        header.insert(at, line);
    };
    if let Some(l) = cfg.lanes {
        after_math_backend(format!(
            "Lanes: {l} states per call in the `_lanes` functions ({}).",
            crate::lanes::names(&plan.functions).join(", ")
        ));
    }
    if batches {
        after_math_backend(
            "Batched `sin_cos`: on (a function's input angles in one polynomial call, \
             `sin_cos_batch`)."
                .into(),
        );
    }
    if cfg.fma {
        after_math_backend(
            "Fused multiply–add: on (`mul_add`, one rounding; `fma` column: each is 2 flops)."
                .into(),
        );
    }
    emit::render(&header, module)
}

/// The `Singular` and `NoConvergence` types of a platform or closed-loop module (each kind has
/// its own `Site`); `site`, `value` and `residual` document what the kind's fields hold.
pub(crate) fn error_types(site: &str, value: &str, residual: &str) -> TokenStream {
    let real = crate::emit::real();
    let real_doc = crate::emit::real_text(
        " Condition-number estimate of the matrix involved (`f64::INFINITY` if unknown).",
    );
    let (site, value, residual) = (
        format!(" {site}"),
        format!(" {value}"),
        format!(" {residual}"),
    );
    quote! {
        /// A configuration where the method fails, or a non-finite input: never a NaN result.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Singular {
            #[doc = #site]
            pub site: Site,
            #[doc = #value]
            pub value: #real,
            #[doc = #real_doc]
            pub condition_estimate: #real,
        }

        /// Forward kinematics did not converge.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct NoConvergence {
            /// Newton iterations made.
            pub iterations: usize,
            #[doc = #residual]
            pub residual: #real,
            /// Why it stopped: tells a `q` outside the workspace from a guess too far away.
            pub stop: Stop,
        }

        /// Why forward kinematics stopped without converging.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Stop {
            /// A non-finite `q` or guess.
            Input,
            /// The guess itself, with these actuated coordinates, cannot be evaluated (out of
            /// reach, or singular): give a guess inside the workspace.
            Guess,
            /// The Jacobian became singular on the way: `q` is at or near the workspace's
            /// boundary, or a singularity lies between the guess and `q`.
            Singular,
            /// No step reduces the residual any more: most likely `q` is outside the
            /// workspace, or beyond a singularity seen from the guess.
            Stalled,
            /// The residual still fell at the iteration limit: a closer guess converges.
            Iterations,
            /// Closed loops: the kept loop equations hold but not all of them (a spurious
            /// branch): give a guess on the intended assembly.
            Branch,
        }

        impl core::fmt::Display for Singular {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                write!(
                    f,
                    "singular at {:?}: value {:e}, condition estimate {:e}",
                    self.site, self.value, self.condition_estimate
                )
            }
        }

        impl core::error::Error for Singular {}

        impl core::fmt::Display for NoConvergence {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                write!(
                    f,
                    "forward kinematics did not converge ({:?}) after {} iterations, residual {:e}",
                    self.stop, self.iterations, self.residual
                )
            }
        }

        impl core::error::Error for NoConvergence {}
    }
}

/// The scheduled functions of a platform or closed-loop module, built alike: each reports
/// `Site`s, and the functions of the masses take the run-time parameters when the module has
/// them.
pub(crate) struct Functions<'g> {
    /// The DAG the kernels are nodes of.
    pub graph: &'g Graph,
    /// Degrees of freedom.
    pub dof: usize,
    /// The module has run-time parameters.
    pub params: bool,
}

impl Functions<'_> {
    /// `args`, then `p` when the module has run-time parameters.
    pub fn with_p(&self, mut args: Vec<Arg>) -> Vec<Arg> {
        if self.params {
            args.push(Arg::P);
        }
        args
    }

    /// The function `name` of `kernel`, scheduled.
    pub fn make<'n>(
        &self,
        name: &'n str,
        doc: Vec<String>,
        args: Vec<Arg>,
        kernel: &Kernel,
        shape: Shape,
        public: bool,
    ) -> Function<'n> {
        Function {
            name,
            doc,
            args,
            schedule: schedule(self.graph, kernel),
            outputs: kernel.outputs.clone(),
            shape,
            dof: self.dof,
            public,
            sites: true,
        }
    }
}

//! Closed loops in joint coordinates: the runtime's evaluator ([`runtime::closed::noc`],
//! written over [`runtime::scalar::Real`]) run on the symbolic scalar, so the whole of every function — tree
//! kinematics, loop Jacobian, the pivoted LU of `Φ_d` (its row swaps are `Select` nodes),
//! the tree's Newton–Euler sweep and the projection `Sᵀ` — is one flat DAG kernel. Newton's
//! assembly is the one loop, a fixed template around a DAG step. [`generate`] assembles the
//! module from named pieces (the scheduled kernels, the op-count rows, the header, the
//! constants and `Params`); the templates are in the `templates` submodule.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::closed::ClosedModel;
use runtime::closed::noc::{self, Plan};
use runtime::drive::DriveInputs;
use runtime::scalar::{Real, Singular};

use crate::emit::{self, Function, Part, Shape};
use crate::module::{self, ModulePlan};
use crate::params::{Layout, drive_inputs, params_items, payload_inputs, payload_inputs_at};
use crate::scalar::{Sx, flat, guarded, ids, in_fresh_graph, inputs};
use crate::schedule::{Kernel, OpCount};
use crate::spec::{Frame, Kind, RuntimeBody, RuntimeParams, Scene};
use crate::sym::{Arg, ExprId, Graph};
use crate::{Config, Generated, MathBackend, VERSION, tangent};

mod regressor;
mod templates;

use templates::templates;

/// The DAG kernels of a closed-loop mechanism: each function's outputs with the guards its
/// evaluation asked for (the closure tests of `x` among them: nothing reads their values, and
/// they are scheduled all the same).
pub struct Kernels {
    /// The shared DAG.
    pub graph: Graph,
    /// All joint rates `ẋ = S u`.
    pub joint_rates: Kernel,
    /// Generalized forces of the independent coordinates.
    pub inverse_dynamics: Kernel,
    /// `I`, row-major.
    pub mass_matrix: Kernel,
    /// `u̇`.
    pub forward_dynamics: Kernel,
    /// Newton step (`NX`), the signed largest scaled residual of the kept loop equations, then
    /// that of every loop equation and axis alignment (on open configurations by design: no
    /// closure tests).
    pub newton_step: Kernel,
    /// `−γ`: the efforts that hold the mechanism still against gravity and the springs.
    pub gravity: Kernel,
    /// `C u`: the velocity-dependent efforts.
    pub coriolis: Kernel,
    /// The joints' friction and the springs' damping; `None` without either.
    pub friction: Option<Kernel>,
    /// `∂τ/∂x` then `∂τ/∂u` of `inverse_dynamics`, row-major, the derivative in `x` along the
    /// constraint manifold (`ẋ = S u`, `codegen/src/tangent.rs`).
    pub inverse_dynamics_derivatives: Kernel,
    /// `u̇` (checked, not returned), then `∂u̇/∂x`, `∂u̇/∂u` and `∂u̇/∂τ`, row-major.
    pub forward_dynamics_derivatives: Kernel,
    /// Per frame of [`kernels_with_frames`]: its pose at `x` (`R` row-major, then `p`).
    pub frames: Vec<Kernel>,
    /// The generalized forces of the base parameters (`DOF × NBP`, row-major), with the base
    /// parameters: [`kernels_for`] a model with constant parameters only.
    pub regressor: Option<RegressorKernel>,
}

/// A closed-loop module's regressor kernel and what its columns are.
pub struct RegressorKernel {
    /// The generalized forces of the base parameters (`DOF × NBP`, row-major): `τ = F_b π_b`.
    pub kernel: Kernel,
    /// The base parameters (their groups index [`RegressorKernel::standard_names`]).
    pub base: crate::dynamics::Base,
    /// The standard parameters' names (`XX_<body>`, …, `FV_<joint>`, `K_<spring>`,
    /// `D_<spring>`), in the groups' order.
    pub standard_names: Vec<String>,
    /// The model's standard parameters, same order.
    pub standard_values: Vec<f64>,
}

/// Build the kernels (a generation-time `Singular` is a structural singularity).
pub fn kernels(plan: &Plan) -> Result<Kernels, Singular> {
    kernels_with(plan, &Layout::default(), None, &[])
}

/// [`kernels`] with run-time parameters in [`Layout`]'s layout: a payload on tree body
/// `payload_body` (entries 0–9, that body's frame), the drives of every tree joint, and the
/// run-time bodies on tree bodies `bodies` (`[scene] runtime_inertia`, ten entries each from
/// [`Layout::body_base`]), through [`noc::Extras`].
pub fn kernels_with(
    plan: &Plan,
    layout: &Layout,
    payload_body: Option<usize>,
    bodies: &[usize],
) -> Result<Kernels, Singular> {
    kernels_with_frames(plan, layout, payload_body, bodies, &[])
}

/// [`kernels_with`] and the poses of `frames` (`[scene] frames`: each fixed to a tree body).
pub fn kernels_with_frames(
    plan: &Plan,
    layout: &Layout,
    payload_body: Option<usize>,
    bodies: &[usize],
    frames: &[Frame],
) -> Result<Kernels, Singular> {
    let (r, graph) = in_fresh_graph(|| build(plan, layout, payload_body, bodies, frames, None));
    r.map(|k| Kernels { graph, ..k })
}

/// [`kernels_with_frames`] of `model` (whose plan is `plan`) without run-time parameters, with
/// its regressor over the base parameters when `regressor`.
pub fn kernels_for(
    model: &ClosedModel,
    plan: &Plan,
    frames: &[Frame],
    regressor: bool,
) -> Result<Kernels, Singular> {
    let model = regressor.then_some(model);
    let layout = Layout::default();
    let (r, graph) = in_fresh_graph(|| build(plan, &layout, None, &[], frames, model));
    r.map(|k| Kernels { graph, ..k })
}

fn build(
    plan: &Plan,
    layout: &Layout,
    payload_body: Option<usize>,
    bodies: &[usize],
    frames: &[Frame],
    model: Option<&ClosedModel>,
) -> Result<Kernels, Singular> {
    let d = plan.dof();
    let x = inputs(Arg::X, plan.nx());
    let u = inputs(Arg::U, d);
    let ud = inputs(Arg::Ud, d);
    let tau = inputs(Arg::Tau, d);
    let mut payloads: Vec<_> = payload_body
        .filter(|_| layout.payload)
        .map(|b| (b, payload_inputs()))
        .into_iter()
        .collect();
    payloads.extend(
        bodies
            .iter()
            .enumerate()
            .map(|(k, &b)| (b, payload_inputs_at(layout.body_base(plan.nx(), k)))),
    );
    let extras = noc::Extras {
        payloads,
        drives: layout.drives().then(|| drive_inputs(plan.nx(), layout)),
    };
    let zero = vec![Sx::c(0.0); d];
    let still = noc::Extras {
        payloads: extras.payloads.clone(),
        drives: extras.drives.as_ref().map(DriveInputs::without_friction),
    };
    let run_time_friction = extras
        .drives
        .as_ref()
        .is_some_and(|d| d.viscous.is_some() || d.coulomb.is_some());
    let dissipation = (plan.has_friction() || run_time_friction).then(|| noc::Extras {
        payloads: Vec::new(),
        drives: extras.drives.as_ref().map(DriveInputs::friction_only),
    });
    // Each function as the `f64` API evaluates it, from `x` (the shared configuration is built
    // once; the DAG shares it, and each kernel keeps the guards it asked for).
    let kernel = |f: &dyn Fn() -> Result<Vec<ExprId>, Singular>| {
        let (outputs, guards) = guarded(f);
        outputs.map(|o| Kernel::new(o, guards))
    };
    let configured = |f: &dyn Fn(&noc::Config<Sx>) -> Vec<ExprId>| {
        kernel(&|| noc::configuration(plan, &x, true).map(|c| f(&c)))
    };
    Ok(Kernels {
        graph: Graph::new(),
        joint_rates: configured(&|c| ids(&noc::joint_rates_generic(plan, c, &u)))?,
        inverse_dynamics: configured(&|c| {
            ids(&noc::generalized_force_with(
                plan, c, &u, &ud, true, &extras,
            ))
        })?,
        mass_matrix: configured(&|c| flat(&noc::generalized_inertia_with(plan, c, &extras)))?,
        forward_dynamics: kernel(&|| {
            noc::forward_dynamics_with(plan, &x, &u, &tau, &extras).map(|fd| ids(&fd))
        })?,
        newton_step: kernel(&|| {
            let (step, kept, full) = noc::newton_step(plan, &x)?;
            let mut newton = ids(&step);
            newton.push(kept.0);
            newton.push(full.0);
            Ok(newton)
        })?,
        // The split of the efforts, built last so that the nodes of the functions above stay
        // as they were without it: `−γ` at rest; `C u` from a plan and drives without
        // dissipation at `u̇ = 0` without gravity; the dissipation from a plan of it alone
        // (`Plan::without_friction`, `Plan::friction_only`; springs count with gravity).
        gravity: configured(&|c| {
            ids(&noc::generalized_force_with(
                plan, c, &zero, &zero, true, &extras,
            ))
        })?,
        coriolis: configured(&|c| {
            ids(&noc::generalized_force_with(
                &plan.without_friction(),
                c,
                &u,
                &zero,
                false,
                &still,
            ))
        })?,
        friction: match dissipation {
            Some(d) => Some(configured(&|c| {
                ids(&noc::generalized_force_with(
                    &plan.friction_only(),
                    c,
                    &u,
                    &zero,
                    true,
                    &d,
                ))
            })?),
            None => None,
        },
        // The derivatives, last again: along `S`'s columns, the speeds and the efforts.
        inverse_dynamics_derivatives: configured(&|c| {
            let f = ids(&noc::generalized_force_with(
                plan, c, &u, &ud, true, &extras,
            ));
            [
                tangent::jacobian(&f, &along_manifold(plan, c)),
                tangent::jacobian(&f, &tangent::along_inputs(Arg::U, d)),
            ]
            .concat()
        })?,
        // Forward dynamics solves `f(x, u, u̇) = τ`: `B = 1`.
        forward_dynamics_derivatives: kernel(&|| {
            let fd = noc::forward_dynamics_with(plan, &x, &u, &tau, &extras)?;
            let c = noc::configuration(plan, &x, true)?;
            let f = noc::generalized_force_with(plan, &c, &u, &ud, true, &extras);
            let b: Vec<Vec<Sx>> = (0..d)
                .map(|r| (0..d).map(|k| Sx::c(f64::from(u8::from(r == k)))).collect())
                .collect();
            tangent::ImplicitForward {
                fd: &fd,
                f: &f,
                inertia: &noc::generalized_inertia_with(plan, &c, &extras),
                b_rate: &[],
                b: &b,
            }
            .derivatives(&along_manifold(plan, &c), &tangent::along_inputs(Arg::U, d))
        })?,
        // Last of all.
        frames: frames
            .iter()
            .map(|f| {
                let (r, p) = noc::frame_pose(plan, &x, f.body, &f.placement);
                let out: Vec<Sx> = r.into_iter().flatten().chain(p).collect();
                Kernel::new(ids(&out), Vec::new())
            })
            .collect(),
        // The regressor, after everything else.
        regressor: match model {
            Some(m) => regressor::regressor(m, plan, &x, &u, &ud)?.map(|r| RegressorKernel {
                kernel: Kernel::new(r.outputs, r.guards),
                base: r.base,
                standard_names: r.standard_names,
                standard_values: r.standard_values,
            }),
            None => None,
        },
    })
}

/// The tangent directions of the constraint manifold at the configuration `c`: `ẋ = S e_j`,
/// the joint rates per unit independent speed.
fn along_manifold(plan: &Plan, c: &noc::Config<Sx>) -> Vec<tangent::Direction> {
    let d = plan.dof();
    let columns: Vec<Vec<Sx>> = (0..d)
        .map(|j| {
            let e: Vec<Sx> = (0..d).map(|k| Sx::c(f64::from(u8::from(k == j)))).collect();
            noc::joint_rates_generic(plan, c, &e)
        })
        .collect();
    // `nx × d`, column `j` the rates of direction `j`.
    let s: Vec<Vec<Sx>> = (0..plan.nx())
        .map(|k| columns.iter().map(|col| col[k]).collect())
        .collect();
    tangent::along_coordinates(&s)
}

/// Generate the module of a closed-loop mechanism for `scene`: only the functions it selects
/// (`inverse_kinematics`, `actuator_rates` and `forward_kinematics` are always emitted,
/// `actuator_mass_matrix` with `mass_matrix`), with its run-time parameters (a payload on a
/// tree body, the run-time bodies and the tree joints' drives; `None`: constants).
/// `inverse_dynamics`, `mass_matrix` and `forward_dynamics` then take `p: &Params` last.
pub fn generate(model: &ClosedModel, scene: &Scene, cfg: &Config) -> Result<Generated, String> {
    let params = scene.params.as_ref();
    let plan = Plan::new(model)?;
    let layout = Layout::of(params);
    let payload = params.and_then(|p| p.payload);
    let bodies = params.map_or(&[][..], |p| &p.bodies[..]);
    let body_links: Vec<usize> = bodies.iter().map(|b| b.body).collect();
    let wanted = |name: &str| scene.functions.wants(Kind::Closed, name);
    let frames: &[Frame] = if wanted("frames") { &scene.frames } else { &[] };
    let k = if layout.any() {
        kernels_with_frames(&plan, &layout, payload.map(|p| p.0), &body_links, frames)
    } else {
        kernels_for(model, &plan, frames, wanted("regressor"))
    }
    .map_err(|e| {
        format!("the mechanism is singular for every input ({e}); check the loop geometry")
    })?;
    let n = plan.dof();
    let functions = functions(&k, &plan, &layout);
    let mut stats = stats(&functions, &wanted);
    let mut functions: Vec<Function<'_>> =
        functions.into_iter().filter(|f| wanted(f.name)).collect();
    let names: Vec<String> = frames
        .iter()
        .map(|f| format!("{}_pose_at", f.ident))
        .collect();
    for ((f, name), kernel) in frames.iter().zip(&names).zip(&k.frames) {
        functions.push(Function {
            name,
            doc: vec![format!(
                "Pose of frame `{}` at the tree joint positions `x` (`JOINT_NAMES` order; not checked for closure): `(R, p)`, the rotation base ← frame and its origin in the base frame (m). `{}_pose` assembles `x` first.",
                f.name, f.ident
            )],
            args: vec![Arg::X],
            outputs: kernel.outputs.clone(),
            shape: Shape::Tuple(vec![Part::Rotation, Part::Array(3)]),
            dof: n,
            schedule: crate::schedule::schedule(&k.graph, kernel),
            public: true,
            sites: false,
        });
        stats.push((
            name.clone(),
            functions.last().map(|f| f.schedule.ops).unwrap_or_default(),
        ));
    }
    let joint_names: Vec<String> = model.tree.joints.iter().map(|j| j.name.clone()).collect();
    let act_names: Vec<String> = plan
        .independent
        .iter()
        .map(|&j| joint_names[j].clone())
        .collect();
    let header = header(model, &plan, &layout, bodies, cfg, &act_names, &stats);
    let mut items = items(cfg, model, &plan, params, &layout, &joint_names, &act_names);
    if let Some(r) = k.regressor.as_ref().filter(|_| wanted("regressor")) {
        items.extend(crate::tree::base_parameter_items(&r.base, "x, u, ud"));
    }
    // The names every actuator-space module has (parallel mechanisms): here the actuated
    // joints are the independent coordinates, so `A = 1`.
    let actuator_mass_matrix = if wanted("mass_matrix") {
        templates::actuator_mass_matrix(cfg, &layout)
    } else {
        quote!()
    };
    let mut after = actuator_mass_matrix;
    after.extend(frame_wrappers(frames));
    let code = module::render(
        &ModulePlan {
            name: &model.name,
            header,
            items,
            graph: &k.graph,
            functions,
            after,
        },
        cfg,
    );
    Ok(Generated {
        code,
        stats,
        dof: n,
        warnings: crate::diag::Diagnostics::new("", ""),
        per: "DOF",
        c_crate: None,
    })
}

/// `NF`, `FRAME_NAMES` and per frame `F_pose(q)`: the loops assembled from `HOME`
/// (`forward_kinematics`), then `F_pose_at`.
fn frame_wrappers(frames: &[Frame]) -> TokenStream {
    if frames.is_empty() {
        return quote!();
    }
    let real = crate::emit::real();
    let nf = Literal::usize_unsuffixed(frames.len());
    let names = frames.iter().map(|f| f.name.as_str());
    let wrappers = frames.iter().map(|f| {
        let pose = quote::format_ident!("{}_pose", f.ident);
        let at = quote::format_ident!("{}_pose_at", f.ident);
        let doc = format!(
            " Pose of frame `{}` at the independent coordinates `q`: the loops assembled by `forward_kinematics(q, &HOME)`, then `{at}`; `Err` where the assembly fails.",
            f.name
        );
        quote! {
            #[doc = #doc]
            pub fn #pose(q: &[#real; DOF]) -> Result<([[#real; 3]; 3], [#real; 3]), NoConvergence> {
                forward_kinematics(q, &HOME).map(|x| #at(&x))
            }
        }
    });
    quote! {
        /// Number of frames whose poses the module offers (`[scene] frames`).
        pub const NF: usize = #nf;
        /// The frames' names as the spec writes them; frame `F`'s functions are `F_pose` and
        /// `F_pose_at`, with `F` the name in lower snake case (docs/spec.md).
        pub const FRAME_NAMES: [&str; NF] = [#(#names),*];
        #(#wrappers)*
    }
}

/// The DAG kernels as the module's scheduled functions, in emission order (all of them; the
/// caller keeps those the scene selects).
fn functions(k: &Kernels, plan: &Plan, layout: &Layout) -> Vec<Function<'static>> {
    let n = plan.dof();
    let nx = plan.nx();
    let fallible = |parts: &[Part]| Shape::Fallible(parts.to_vec());
    let fns = module::Functions {
        graph: &k.graph,
        dof: n,
        params: layout.any(),
    };
    let coords = "`x`: every tree joint's position (rad or m, `JOINT_NAMES` order), closing the loops (see `forward_kinematics`); `u`: the rates of the independent coordinates (`x[INDEPENDENT[k]]`)";
    let friction = k.friction.as_ref().map(|kernel| {
        fns.make(
            "friction",
            vec!["Efforts of the dissipation at `(x, u)`: every joint's friction (viscous and regularized Coulomb, actuated and passive joints alike) and the springs' damping, mapped to the independent coordinates by `Sᵀ`.".into()],
            fns.with_p(vec![Arg::X, Arg::U]),
            kernel,
            fallible(&[Part::Vector]),
            true,
        )
    });
    let mut functions = vec![
        fns.make(
            "joint_rates",
            vec![format!(
                "All joint rates `ẋ = S u` (`ẋ_d = −Φ_d⁻¹ Φ_i u`). {coords}. `Err` when `x` does not close the loops (`Site::Closure`) or the independent coordinates do not determine the others (`Site::Constraint`)."
            )],
            vec![Arg::X, Arg::U],
            &k.joint_rates,
            fallible(&[Part::Coords(nx)]),
            true,
        ),
        fns.make(
            "inverse_dynamics",
            vec![format!(
                "Generalized forces of the independent coordinates, `f = Sᵀ τ_tree = I u̇ + C u − γ` (N or N·m, gravity included): the efforts of the actuated joints that produce the motion `(x, u, ud)`. {coords}."
            )],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Ud]),
            &k.inverse_dynamics,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "mass_matrix",
            vec!["Generalized inertia `I = Sᵀ M S` of the independent coordinates (symmetric positive definite away from singularities).".into()],
            fns.with_p(vec![Arg::X]),
            &k.mass_matrix,
            fallible(&[Part::Matrix]),
            true,
        ),
        fns.make(
            "forward_dynamics",
            vec!["Rates `u̇` of the independent speeds with `I u̇ = τ − (C u − γ)` for the actuator efforts `tau`; `Err` where the method fails or a pivot of `I`'s `LDLᵀ` is not above `1e-12` times its diagonal entry.".into()],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Tau]),
            &k.forward_dynamics,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "inverse_dynamics_derivatives",
            vec![format!(
                "`(∂τ/∂x, ∂τ/∂u)` of `inverse_dynamics` at `(x, u, ud)`; element `[i][j] = ∂τ_i/∂x_j`. The derivative in `x` is taken along the constraint manifold: column `j` is the rate of `τ` while the mechanism moves with the independent speed `u_j` alone (the joints at `ẋ = S e_j`, `joint_rates(x, e_j)`), so it is the derivative with respect to the independent coordinate `x[INDEPENDENT[j]]` with the others following. `∂τ/∂u̇` is `mass_matrix(x)`. The same guards and errors as `inverse_dynamics`. {coords}."
            )],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Ud]),
            &k.inverse_dynamics_derivatives,
            fallible(&[Part::Matrix, Part::Matrix]),
            true,
        ),
        fns.make(
            "forward_dynamics_derivatives",
            vec!["`(∂u̇/∂x, ∂u̇/∂u, ∂u̇/∂τ)` of `forward_dynamics`; element `[i][j] = ∂u̇_i/∂x_j`, the derivative in `x` along the constraint manifold as in `inverse_dynamics_derivatives`; `∂u̇/∂τ = I⁻¹`. The same guards and errors as `forward_dynamics`.".into()],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Tau]),
            &k.forward_dynamics_derivatives,
            fallible(&[Part::Hidden(n), Part::Matrix, Part::Matrix, Part::Matrix]),
            true,
        ),
        fns.make(
            "gravity",
            vec![format!(
                "Efforts of the independent coordinates that hold the mechanism still against gravity and the springs at `x`, `−γ(x)`: `inverse_dynamics(x, 0, 0)`. {coords}."
            )],
            fns.with_p(vec![Arg::X]),
            &k.gravity,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "coriolis",
            vec!["Velocity-dependent efforts `C u` of the independent coordinates (Coriolis and centrifugal terms, the rotors' among them; no gravity, springs or friction). So `inverse_dynamics(x, u, ud) = I ud + coriolis(x, u) + gravity(x) (+ friction(x, u))` with `I = mass_matrix(x)`.".into()],
            fns.with_p(vec![Arg::X, Arg::U]),
            &k.coriolis,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "newton_step",
            vec!["Kernel of `forward_kinematics`: the Newton step of the dependent coordinates, the signed largest scaled residual of the kept loop equations, and that of every loop equation and revolute-axis alignment.".into()],
            vec![Arg::X],
            &k.newton_step,
            fallible(&[Part::Coords(nx), Part::Scalar, Part::Scalar]),
            false,
        ),
    ];
    functions.extend(friction);
    functions.extend(k.regressor.as_ref().map(|RegressorKernel { kernel, base, .. }| {
        fns.make(
            "regressor",
            vec![format!(
                "The regressor over the base parameters: `inverse_dynamics(x, u, ud) = regressor(x, u, ud) · BASE_PARAMETERS`, element `[i][k]` the effort of independent coordinate `i` per unit of base parameter `k` (`BASE_PARAMETER_NAMES[k]`: the standard parameters it groups; springs' stiffness `K_` and damping `D_` among them). {coords}. `Err` where `inverse_dynamics` fails."
            )],
            vec![Arg::X, Arg::U, Arg::Ud],
            kernel,
            fallible(&[Part::Regressor(base.kept.len())]),
            true,
        )
    }));
    functions
}

/// The operation counts of the header's table: each selectable function `wanted` keeps, then
/// a step of `forward_kinematics` (its `newton_step`).
fn stats(functions: &[Function<'_>], wanted: &dyn Fn(&str) -> bool) -> Vec<(String, OpCount)> {
    let ops = |name: &str| {
        functions
            .iter()
            .find(|f| f.name == name)
            .map(|f| f.schedule.ops)
            .unwrap_or_default()
    };
    let mut stats: Vec<(String, OpCount)> = Kind::Closed
        .selectable()
        .iter()
        .map(|f| f.name())
        .filter(|n| wanted(n) && functions.iter().any(|f| f.name == *n))
        .map(|n| (n.to_string(), ops(n)))
        .collect();
    stats.push((
        "forward_kinematics (per Newton step)".into(),
        ops("newton_step"),
    ));
    stats
}

/// The module's header comment: provenance, the loops and coordinates, the math backend, the
/// run-time parameters (if any) and the operation-count table.
fn header(
    model: &ClosedModel,
    plan: &Plan,
    layout: &Layout,
    bodies: &[RuntimeBody],
    cfg: &Config,
    act_names: &[String],
    stats: &[(String, OpCount)],
) -> Vec<String> {
    let n = plan.dof();
    let nx = plan.nx();
    let mut header = vec![
        format!(
            "@generated by nocdyn codegen {VERSION} from mechanism `{}` — do not edit.",
            model.name
        ),
        format!(
            "Closed loops in joint coordinates: {} cut joint(s), {} kept loop equations; NX = {nx} joint coordinates, DOF = {n} independent ({}). Units: SI (m, kg, s, rad, N, N·m).",
            model.cuts.len(),
            plan.rows.len(),
            act_names.join(", ")
        ),
        match &cfg.math {
            MathBackend::Libm => {
                "Math backend: the `libm` crate (sin/cos, sqrt); otherwise core only.".into()
            }
            MathBackend::Std => "Math backend: std.".into(),
            MathBackend::Runtime(p) => format!("Math backend: `{p}::math` (nocdyn runtime)."),
        },
        "Operation counts per call (the LU of `Φ_d` included; `cmp` counts its pivot selections):"
            .into(),
    ];
    if layout.any() {
        header.insert(
            3,
            if bodies.is_empty() {
                "Run-time parameters: the scene's payload and joint drives (`Params`, `[scene] parameters = \"runtime\"`).".into()
            } else {
                "Run-time parameters: the scene's payload, joint drives and the inertial parameters of the bodies in `RUNTIME_BODY_NAMES` (`Params`, `[scene] parameters = \"runtime\"`).".into()
            },
        );
    }
    header.extend(emit::stats_table_per(stats, n, "DOF"));
    header
}

/// The items before the functions: the constants (names, `INDEPENDENT`, `HOME`, and the
/// assembly's `STEP` and `WRAP`), the run-time parameters' items and the fixed templates.
fn items(
    cfg: &Config,
    model: &ClosedModel,
    plan: &Plan,
    params: Option<&RuntimeParams>,
    layout: &Layout,
    joint_names: &[String],
    act_names: &[String],
) -> TokenStream {
    let real = crate::emit::real();
    let nx_lit = Literal::usize_unsuffixed(plan.nx());
    let n_lit = Literal::usize_unsuffixed(plan.dof());
    let indep: Vec<Literal> = plan
        .independent
        .iter()
        .map(|&j| Literal::usize_unsuffixed(j))
        .collect();
    let wrap: Vec<bool> = (0..plan.nx())
        .map(|j| {
            !plan.independent.contains(&j)
                && model.tree.joints[j].kind == runtime::model::JointKind::Revolute
        })
        .collect();
    let step: Vec<Literal> = plan
        .independent
        .iter()
        .map(|&j| {
            Literal::f64_unsuffixed(match model.tree.joints[j].kind {
                runtime::model::JointKind::Revolute => noc::FK_STEP,
                runtime::model::JointKind::Prismatic => noc::FK_STEP * plan.size,
            })
        })
        .collect();
    let home = plan.home();
    // All zero (the default) as before: `[0.0; NX]`.
    let home_value = if home.iter().all(|&h| h == 0.0) {
        quote! { [0.0; NX] }
    } else {
        let h = home.iter().map(|&h| crate::emit::float_lit(h));
        quote! { [#(#h),*] }
    };
    let items = templates(cfg, !plan.springs.is_empty());
    let spring_names = spring_names(plan);
    let params = runtime_params(model, params, layout);
    quote! {
        /// Number of position coordinates `x`: every joint of the spanning tree.
        pub const NX: usize = #nx_lit;
        /// Degrees of freedom: independent coordinates, speeds `u`, actuators.
        pub const DOF: usize = #n_lit;
        /// The tree joints, in the order of `x`.
        pub const JOINT_NAMES: [&str; NX] = [#(#joint_names),*];
        /// The independent (actuated) joints, in the order of `u` and `tau`.
        pub const ACTUATOR_NAMES: [&str; DOF] = [#(#act_names),*];
        /// Index in `x` of each independent coordinate.
        pub const INDEPENDENT: [usize; DOF] = [#(#indep),*];
        #spring_names
        /// The spec's home configuration (every tree joint at its `home` value, zero unless the
        /// spec gives one, where the spec's geometry closes the loops in its declared branch): a
        /// guess for `forward_kinematics` near home.
        pub const HOME: [#real; NX] = #home_value;
        /// The largest move of each independent coordinate per stage of `forward_kinematics`
        /// (rad, or m: a fraction of the mechanism's size).
        const STEP: [#real; DOF] = [#(#step),*];
        /// The dependent revolute joints: assembly keeps each within ±π of its guess.
        const WRAP: [bool; NX] = [#(#wrap),*];
        #params
        #items
    }
}

/// `SPRING_NAMES`, when the mechanism has spring-dampers.
fn spring_names(plan: &Plan) -> TokenStream {
    if plan.springs.is_empty() {
        return quote!();
    }
    let names: Vec<&str> = plan.springs.iter().map(|s| s.name.as_str()).collect();
    let ns = Literal::usize_unsuffixed(names.len());
    quote! {
        /// The spring-dampers (`[[spring]]`), in the order of `Site::Spring`: applied
        /// forces, in every function's efforts with gravity.
        pub const SPRING_NAMES: [&str; #ns] = [#(#names),*];
    }
}

/// The run-time parameters' items (`Params`: the payload, the tree joints' drives, the run-time
/// bodies), nothing without run-time parameters.
fn runtime_params(
    model: &ClosedModel,
    params: Option<&RuntimeParams>,
    layout: &Layout,
) -> TokenStream {
    if !layout.any() {
        return quote!();
    }
    let payload = params.and_then(|p| p.payload);
    let bodies = params.map_or(&[][..], |p| &p.bodies[..]);
    let drives: Vec<&runtime::model::Drive> = model.tree.joints.iter().map(|j| &j.drive).collect();
    params_items(
        layout,
        payload.map(|(b, m, c, i)| (format!("body `{}`", model.tree.bodies[b].name), m, c, i)),
        &drives,
        ("NX", "tree joint (`JOINT_NAMES` order)"),
        "a payload on a body and the joints' drives the scene models",
        bodies,
        &|b| format!("tree body `{}`", model.tree.bodies[b].name),
    )
}

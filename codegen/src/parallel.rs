//! Parallel mechanisms: the runtime's evaluator ([`runtime::parallel::noc`], written over
//! [`Real`]) run on a symbolic scalar, so that every operation becomes a node of the
//! hash-consed DAG ([`crate::sym`]): constants fold, structural zeros vanish and common
//! subexpressions are shared exactly as for trees. The DAG kernels are then wrapped by a few
//! fixed templates (the partially pivoted LU of the actuation matrix, Newton's forward
//! kinematics) into the module's public functions.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::model::JointKind;
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use runtime::scalar::{Real, Singular};

pub use crate::params::Layout;
use crate::params::{drive_inputs, params_items, payload_inputs, payload_inputs_at};
use crate::scalar::{Sx, flat, guarded, ids, in_fresh_graph, inputs};

use crate::emit::{self, Function, Part, Shape};
use crate::module::{self, ModulePlan};
use crate::schedule::{Kernel, OpCount, schedule};
use crate::spec::{Kind, Scene};
use crate::sym::{Arg, ExprId, Graph};
use crate::{Config, Generated, MathBackend, VERSION, lu};

/// The DAG kernels of a parallel mechanism: each function's outputs with the guards its
/// evaluation asked for.
pub struct Kernels {
    /// The shared DAG.
    pub graph: Graph,
    /// Actuated joint positions `q(x)`.
    pub inverse_kinematics: Kernel,
    /// `A u`.
    pub actuator_rates: Kernel,
    /// `A` (row-major) then `f = I u̇ + C u − γ`.
    pub id_parts: Kernel,
    /// `I`, row-major.
    pub mass_matrix: Kernel,
    /// `A` then `I`.
    pub inertia_parts: Kernel,
    /// `u̇`.
    pub forward_dynamics: Kernel,
    /// `q(x)` then `A`.
    pub fk_parts: Kernel,
}

/// Build the kernels (a generation-time `Singular` means the mechanism is singular for every
/// input: a structural singularity).
pub fn kernels(plan: &Plan) -> Result<Kernels, Singular> {
    kernels_with(plan, &Layout::default())
}

/// [`kernels`] with run-time parameters: the payload's mass properties are added by
/// [`noc::payload_force`] and [`noc::payload_inertia`], the drives enter as
/// [`runtime::drive::DriveInputs`].
pub fn kernels_with(plan: &Plan, layout: &Layout) -> Result<Kernels, Singular> {
    let (r, graph) = in_fresh_graph(|| build(plan, layout));
    r.map(|k| Kernels { graph, ..k })
}

fn build(plan: &Plan, layout: &Layout) -> Result<Kernels, Singular> {
    let n = plan.dof();
    let x = inputs(Arg::X, plan.nx());
    let u = inputs(Arg::U, n);
    let ud = inputs(Arg::Ud, n);
    let tau = inputs(Arg::Tau, n);
    // Inverse kinematics needs the legs' positions; every other function starts from their
    // kinematics, Jacobians included, and its tests.
    let (pos, pos_guards) = guarded(|| noc::positions(plan, &x));
    let q = noc::actuated_positions(plan, &pos?.1);
    let (kin, kin_guards) = guarded(|| noc::kinematics(plan, &x));
    let (pl, legs) = kin?;
    let with_kin = |outputs: Vec<ExprId>| Kernel::new(outputs, kin_guards.clone());
    let a = noc::actuation_matrix(plan, &legs);
    let rates: Vec<Sx> = a
        .iter()
        .map(|row| {
            row.iter()
                .zip(&u)
                .fold(Sx::c(0.0), |s, (&aij, &uj)| s + aij * uj)
        })
        .collect();
    let drives = layout
        .drives()
        .then(|| drive_inputs(3 * plan.legs.len(), layout));
    let mut f = noc::generalized_force_with(plan, &pl, &legs, &u, &ud, true, drives.as_ref());
    let mut i = noc::generalized_inertia_with(plan, &pl, &legs, drives.as_ref());
    // The payload, then the platform's own inertia when it is given at run time (each a
    // payload on the platform).
    let mut payloads: Vec<_> = layout.payload.then(payload_inputs).into_iter().collect();
    let nlj = 3 * plan.legs.len();
    payloads.extend((0..layout.bodies).map(|k| payload_inputs_at(layout.body_base(nlj, k))));
    for p in &payloads {
        let fp = noc::payload_force(plan, &pl, p, &u, &ud, true);
        let ip = noc::payload_inertia(plan, &pl, p);
        for r in 0..n {
            f[r] = f[r] + fp[r];
            for c in 0..n {
                i[r][c] = i[r][c] + ip[r][c];
            }
        }
    }
    // Forward dynamics from `x`, as the `f64` API evaluates it (the kinematics again, shared
    // in the DAG, and the `LDLᵀ` of `I`).
    let (fd, fd_guards) =
        guarded(|| noc::forward_dynamics_with(plan, &x, &u, &tau, &payloads, drives.as_ref()));
    let cat = |a: Vec<ExprId>, b: Vec<ExprId>| a.into_iter().chain(b).collect::<Vec<_>>();
    Ok(Kernels {
        graph: Graph::new(),
        inverse_kinematics: Kernel::new(ids(&q), pos_guards),
        actuator_rates: with_kin(ids(&rates)),
        id_parts: with_kin(cat(flat(&a), ids(&f))),
        mass_matrix: with_kin(flat(&i)),
        inertia_parts: with_kin(cat(flat(&a), flat(&i))),
        forward_dynamics: Kernel::new(ids(&fd?), fd_guards),
        fk_parts: with_kin(cat(ids(&q), flat(&a))),
    })
}

/// Operation count of the emitted `lu_solve_many::<K>` for an `n × n` matrix: squared column
/// norms, partial pivoting, `k` right-hand sides (`lu_solve` is `k = 1`, `lu_inverse` is
/// `k = n`). The error paths (a square root and a division each) are not counted.
pub fn lu_many_ops(n: usize, k: usize) -> OpCount {
    let mut c = OpCount::default();
    // Squared column norms (for the scale-free pivot test).
    c.mul += n * n;
    c.add += n * (n - 1);
    for p in 0..n {
        let rows = n - p - 1;
        // The pivot's conditional swaps (one comparison per lower row); its square and the
        // two cross-multiplied products of the tolerance test, the tolerance's product, the
        // test and the running maximum's comparison.
        c.cmp += rows + 2;
        c.mul += 4;
        // Its reciprocal, and the updates of the columns right of it and of the right-hand
        // sides.
        c.div += 1;
        c.mul += rows * (1 + (n - p - 1) + k);
        c.add += rows * ((n - p - 1) + k);
    }
    // Back substitution for k right-hand sides (by the reciprocal pivots).
    c.mul += k * (n * (n - 1) / 2) + n * k;
    c.add += k * (n * (n - 1) / 2);
    c
}

/// Operation count of `lu_solve` (one right-hand side).
pub fn lu_ops(n: usize) -> OpCount {
    lu_many_ops(n, 1)
}

/// Operation count of `lu_inverse` followed by `A⁻ᵀ I A⁻¹` (`I A⁻¹` in full, then the upper
/// triangle of `A⁻ᵀ (I A⁻¹)`).
pub fn lu_inverse_ops(n: usize) -> OpCount {
    let mut c = lu_many_ops(n, n);
    let tri = n * (n + 1) / 2;
    c.mul += n * n * n + tri * n;
    c.add += (n * n + tri) * (n - 1);
    c
}

fn plus(a: OpCount, b: OpCount, times: usize) -> OpCount {
    OpCount {
        add: a.add + b.add * times,
        mul: a.mul + b.mul * times,
        neg: a.neg + b.neg * times,
        div: a.div + b.div * times,
        sqrt: a.sqrt + b.sqrt * times,
        sin_cos: a.sin_cos + b.sin_cos * times,
        cmp: a.cmp + b.cmp * times,
        atan2: a.atan2 + b.atan2 * times,
    }
}

/// Generate the module of a parallel mechanism for `scene`: only the functions it selects
/// (`inverse_kinematics` and `forward_kinematics` are always emitted), with its run-time
/// parameters (`[scene] parameters = "runtime"`: the platform's payload, the run-time bodies
/// and the leg joints' drives; `None`: constants). The functions whose values depend on the
/// masses (`inverse_dynamics`, `mass_matrix`, `actuator_mass_matrix`, `forward_dynamics`)
/// then take `p: &Params` last.
pub fn generate(model: &ParallelModel, scene: &Scene, cfg: &Config) -> Result<Generated, String> {
    let params = scene.params.as_ref();
    let payload = params.and_then(|p| p.payload);
    let layout = Layout::of(params);
    let want = |name: &str| scene.functions.wants(Kind::Parallel, name);
    let plan = Plan::new(model)?;
    let k = kernels_with(&plan, &layout).map_err(|e| {
        format!("the mechanism is singular for every input ({e}); check the leg geometry")
    })?;
    let g = &k.graph;
    let n = plan.dof();
    let nx = plan.nx();
    let fallible = |parts: &[Part]| Shape::Fallible(parts.to_vec());
    let coords = match plan.motion {
        PlatformMotion::Pose => {
            "`x = [px, py, pz, qw, qx, qy, qz]` (platform frame origin, m, and unit quaternion, base frame); `u = [ω; v]` (rad/s; m/s of the platform frame origin, base-frame components)"
        }
        PlatformMotion::Orientation { .. } => {
            "`x = [qw, qx, qy, qz]` (unit quaternion of the platform about the fixed centre, base frame); `u = ω` (rad/s, base-frame components)"
        }
        PlatformMotion::PlanarPoint { .. } => {
            "`x = [px, py]` (the point where the legs meet, m, base frame); `u = [vx, vy]` (m/s)"
        }
    };
    // The functions of the masses read the run-time payload.
    let with_p = |mut args: Vec<Arg>| {
        if layout.any() {
            args.push(Arg::P);
        }
        args
    };
    let make = |name: &'static str,
                doc: Vec<String>,
                args: Vec<Arg>,
                kernel: &Kernel,
                shape: Shape,
                public: bool| Function {
        name,
        doc,
        args,
        schedule: schedule(g, kernel),
        outputs: kernel.outputs.clone(),
        shape,
        dof: n,
        public,
        sites: true,
    };
    let functions = [
        make(
            "inverse_kinematics",
            vec![format!(
                "Actuated joint positions `q(x)` (rad or m, in `ACTUATOR_NAMES` order) by closed-form leg inverse kinematics. {coords}. `Err` when a leg cannot reach the platform (`Site::Reach`) or is singular (`Site::Leg`)."
            )],
            vec![Arg::X],
            &k.inverse_kinematics,
            fallible(&[Part::Vector]),
            true,
        ),
        make(
            "actuator_rates",
            vec!["Actuator rates `q̇ = A u` (rad/s or m/s); `Err` at a leg singularity.".into()],
            vec![Arg::X, Arg::U],
            &k.actuator_rates,
            fallible(&[Part::Vector]),
            true,
        ),
        make(
            "id_parts",
            vec!["Kernel of `inverse_dynamics`: the actuation matrix `A` and the generalized force `f = I u̇ + C u − γ`.".into()],
            with_p(vec![Arg::X, Arg::U, Arg::Ud]),
            &k.id_parts,
            fallible(&[Part::Matrix, Part::Vector]),
            false,
        ),
        make(
            "mass_matrix",
            vec!["Generalized inertia `I = TᵀMT` of the speeds `u` (symmetric positive definite away from singularities; kg·m², kg·m, kg).".into()],
            with_p(vec![Arg::X]),
            &k.mass_matrix,
            fallible(&[Part::Matrix]),
            true,
        ),
        make(
            "inertia_parts",
            vec!["Kernel of `actuator_mass_matrix`: `A` and `I`.".into()],
            with_p(vec![Arg::X]),
            &k.inertia_parts,
            fallible(&[Part::Matrix, Part::Matrix]),
            false,
        ),
        make(
            "forward_dynamics",
            vec!["Speed rates `u̇` with `I u̇ = Aᵀ τ − (C u − γ)` for the actuator efforts `tau` (N or N·m); `Err` at a leg singularity or when a pivot of `I`'s `LDLᵀ` is not above `1e-12` times its diagonal entry.".into()],
            with_p(vec![Arg::X, Arg::U, Arg::Tau]),
            &k.forward_dynamics,
            fallible(&[Part::Vector]),
            true,
        ),
        make(
            "fk_parts",
            vec!["Kernel of `forward_kinematics`: `q(x)` and `A(x)`.".into()],
            vec![Arg::X],
            &k.fk_parts,
            fallible(&[Part::Vector, Part::Matrix]),
            false,
        ),
    ];
    let functions: Vec<Function<'_>> = functions
        .into_iter()
        .filter(|f| {
            want(match f.name {
                "id_parts" => "inverse_dynamics",
                "inertia_parts" => "actuator_mass_matrix",
                n => n,
            })
        })
        .collect();
    let ops = |name: &str| {
        functions
            .iter()
            .find(|f| f.name == name)
            .map(|f| f.schedule.ops)
            .unwrap_or_default()
    };
    let lu = lu_ops(n);
    let stats: Vec<(String, OpCount)> = vec![
        ("inverse_kinematics".into(), ops("inverse_kinematics")),
        ("actuator_rates".into(), ops("actuator_rates")),
        ("inverse_dynamics".into(), plus(ops("id_parts"), lu, 1)),
        ("mass_matrix".into(), ops("mass_matrix")),
        (
            "actuator_mass_matrix".into(),
            plus(ops("inertia_parts"), lu_inverse_ops(n), 1),
        ),
        ("forward_dynamics".into(), ops("forward_dynamics")),
        (
            "forward_kinematics (per Newton step)".into(),
            plus(ops("fk_parts"), lu, 1),
        ),
    ];
    let stats: Vec<(String, OpCount)> = stats.into_iter().filter(|(n, _)| want(n)).collect();
    let mut header = vec![
        format!(
            "@generated by nocdyn codegen {VERSION} from mechanism `{}` — do not edit.",
            model.name
        ),
        format!(
            "Parallel mechanism: {} legs ({}); NX = {nx} position coordinates, DOF = {n}. Units: SI (m, kg, s, rad, N, N·m).",
            plan.legs.len(),
            plan.legs
                .iter()
                .map(|l| l.kind.word())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        match &cfg.math {
            MathBackend::Libm => {
                "Math backend: the `libm` crate (sin/cos, sqrt, atan2); otherwise core only.".into()
            }
            MathBackend::Std => "Math backend: std.".into(),
            MathBackend::Runtime(p) => format!("Math backend: `{p}::math` (nocdyn runtime)."),
        },
        "Operation counts per call (the LU of `A` counted with its pivot tests; error paths not counted):".into(),
    ];
    if layout.any() {
        let mut parts = Vec::new();
        if layout.payload {
            parts.push("the platform's payload");
        }
        if layout.bodies > 0 {
            parts.push("the platform's own inertia (`RUNTIME_BODY_NAMES`)");
        }
        if layout.drives() {
            parts.push("the leg joints' drives");
        }
        let what = match parts.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => parts.concat(),
        };
        header.insert(
            3,
            format!("Run-time parameters: {what} (`Params`, `[scene] parameters = \"runtime\"`)."),
        );
    }
    header.extend(emit::stats_table_per(&stats, n, "DOF"));
    let names: Vec<&str> = model
        .legs
        .iter()
        .map(|l| l.actuated_name.as_str())
        .collect();
    let revolute: Vec<bool> = plan
        .legs
        .iter()
        .map(|l| l.joints[l.actuated] == JointKind::Revolute)
        .collect();
    let items = templates(cfg, &plan, &revolute, &want, layout.any());
    let params_items = if !layout.any() {
        quote!()
    } else {
        let drives: Vec<&runtime::model::Drive> = model
            .legs
            .iter()
            .flat_map(|l| l.joints.iter().take(3).map(|j| &j.drive))
            .collect();
        let joint_names: Vec<&str> = model
            .legs
            .iter()
            .flat_map(|l| l.joints.iter().take(3).map(|j| j.name.as_str()))
            .collect();
        let nlj_lit = Literal::usize_unsuffixed(drives.len());
        let leg_items = if layout.drives() {
            quote! {
                /// Number of leg joints (three per leg, base outwards), whose drives are run-time
                /// parameters.
                pub const LEG_JOINTS: usize = #nlj_lit;
                /// The leg joints, in the order of the drive arrays of [`Params`].
                pub const LEG_JOINT_NAMES: [&str; LEG_JOINTS] = [#(#joint_names),*];
            }
        } else {
            quote!()
        };
        let items = params_items(
            &layout,
            payload.map(|(_, m, c, i)| ("the platform".to_string(), m, c, i)),
            &drives,
            ("LEG_JOINTS", "leg joint (`LEG_JOINT_NAMES` order)"),
            "the payload on the platform and the leg joints' drives the scene models",
            params.map_or(&[][..], |p| &p.bodies[..]),
            &|_| "the platform".to_string(),
        );
        quote! {
            #leg_items
            #items
        }
    };
    let nx_lit = Literal::usize_unsuffixed(nx);
    let n_lit = Literal::usize_unsuffixed(n);
    let home: Vec<Literal> = model
        .home_x()
        .iter()
        .map(|&v| Literal::f64_unsuffixed(v))
        .collect();
    let items = quote! {
        /// Number of position coordinates `x`.
        pub const NX: usize = #nx_lit;
        /// Degrees of freedom: speeds `u`, actuators.
        pub const DOF: usize = #n_lit;
        /// The actuated joints, in the order of `q` and `tau`.
        pub const ACTUATOR_NAMES: [&str; DOF] = [#(#names),*];
        /// The spec's home configuration `x` (its legs in their declared branches): a guess for
        /// `forward_kinematics` near home.
        #[allow(clippy::excessive_precision)]
        pub const HOME: [f64; NX] = [#(#home),*];
        #params_items
        #items
    };
    let code = module::render(
        &ModulePlan {
            header,
            items,
            graph: g,
            functions,
            after: quote!(),
        },
        cfg,
    );
    Ok(Generated {
        code,
        stats,
        dof: n,
        warnings: crate::diag::Diagnostics::new("", ""),
        per: "DOF",
    })
}

/// The fixed items of every parallel module: error types, the LU of `A`, and the public
/// functions that wrap the DAG kernels.
fn templates(
    cfg: &Config,
    plan: &Plan,
    revolute: &[bool],
    want: &dyn Fn(&str) -> bool,
    params: bool,
) -> TokenStream {
    // With run-time parameters the wrappers take and pass on `p: &Params`.
    let (p_arg, p_pass) = if params {
        (quote!(, p: &Params), quote!(, p))
    } else {
        (quote!(), quote!())
    };
    let sqrt_n = emit::math_call(cfg, "sqrt", quote!(n));
    let sqrt_a = emit::math_call(cfg, "sqrt", quote!(a2));
    let sin_cos = emit::math_call(cfg, "sin_cos", quote!(0.5 * a));
    let tol = crate::scalar::tolerance;
    let leg_tol = tol(noc::LEG_TOLERANCE);
    let act_tol = tol(noc::ACTUATION_TOLERANCE);
    let fk_tol = tol(noc::FK_TOLERANCE);
    let fk_max = noc::FK_MAX_ITERATIONS;
    let (qi, has_p) = match plan.motion {
        PlatformMotion::Pose => (3usize, true),
        PlatformMotion::Orientation { .. } => (0usize, false),
        PlatformMotion::PlanarPoint { .. } => (0usize, false),
    };
    let planar = matches!(plan.motion, PlatformMotion::PlanarPoint { .. });
    let qi = Literal::usize_unsuffixed(qi);
    let translate = if has_p {
        quote! {
            for i in 0..3 {
                out[i] += du[3 + i];
            }
        }
    } else {
        quote!()
    };
    let retract = retract_template(
        planar,
        qi.clone(),
        translate.clone(),
        sqrt_a.clone(),
        sin_cos.clone(),
        sqrt_n.clone(),
    );
    // The squared tolerance, rounded to 13 significant digits so that `1e-8²` reads `1e-16`.
    let act_tol2 = act_tol * act_tol;
    let act_tol2 = format!("{act_tol2:.12e}").parse().unwrap_or(act_tol2);
    let sqrt_call = |t: TokenStream| emit::math_call(cfg, "sqrt", t);
    let lu = |name: &str, doc: &str, transpose: bool, rhs: lu::Rhs| {
        lu::lu_solve_fn(&lu::LuSolve {
            name,
            doc,
            n: plan.dof(),
            transpose,
            rhs,
            tol2: act_tol2,
            sqrt: &sqrt_call,
        })
    };
    let lu_solve = lu(
        "lu_solve",
        " Solve `a x = b`: LU with partial pivoting by conditional row swaps, straight-line code.\n\n A pivot of `a` with its columns scaled to unit 2-norm must exceed the tolerance times the\n largest so far (compared squared and cross-multiplied: no square root or division outside\n the error path); otherwise `Err(Site::Actuation(k))` with the ratio of the largest scaled\n pivot to this one as the condition estimate.",
        false,
        lu::Rhs::Vector,
    );
    let lu_solve_t = lu(
        "lu_solve_t",
        " Solve `aᵀ x = b` (as `lu_solve`, on the transpose).",
        true,
        lu::Rhs::Vector,
    );
    let lu_inverse = lu(
        "lu_inverse",
        " `a⁻¹`: one factorization (as `lu_solve`) for the `DOF` columns of the identity.",
        false,
        lu::Rhs::Identity,
    );
    // Rounded to 13 significant digits, as the squared tolerance below.
    let fk_tol = fk_tol * plan.fk_scale();
    let fk_tol = format!("{fk_tol:.12e}").parse().unwrap_or(fk_tol);
    let fk_tol_lit = Literal::f64_unsuffixed(fk_tol);
    let fk_doc = [
        " Forward kinematics: the platform coordinates whose actuated joint positions are `q`,"
            .to_string(),
        " by Newton's method from `guess` (`x ← x ⊕ A⁻¹ (q − q(x))`, the step halved while it"
            .to_string(),
        format!(" does not reduce the residual), at most {fk_max} iterations, converged when"),
        format!(" `max |q(x) − q| ≤ {fk_tol:e}` (angles modulo 2π; a bound that does not grow"),
        " with `q`). A non-finite `q` or `guess` is `Err` at once. The result's quaternion is"
            .to_string(),
        " unit.".to_string(),
    ];
    let sin_cos_q = emit::math_call(cfg, "sin_cos", quote!(v));
    let atan2_sc = emit::math_call(cfg, "atan2", quote!(s, c));
    let fk_max_lit = Literal::usize_unsuffixed(fk_max);
    let leg_doc = format!(
        " Leg `k`'s Jacobian is singular: `|det J| ≤ {leg_tol:e} · ∏‖columns‖` (a leg, type-I, singularity)."
    );
    let act_doc = format!(
        " Pivot `i` of the actuation matrix `A` (columns scaled to unit norm, partial pivoting) is `≤ {act_tol:e}` times the largest pivot: a parallel (type-II) singularity."
    );
    // Wrappers of the kernels `[scene] functions` may leave out.
    let id_wrapper = if want("inverse_dynamics") {
        quote! {
        /// Actuator efforts `τ = A⁻ᵀ (I u̇ + C u − γ)` (N or N·m, gravity included) that produce
        /// the platform motion `(x, u, ud)`; `Err` at a leg or parallel singularity.
        #[inline]
        pub fn inverse_dynamics(x: &[f64; NX], u: &[f64; DOF], ud: &[f64; DOF] #p_arg) -> Result<[f64; DOF], Singular> {
            let (a, f) = id_parts(x, u, ud #p_pass)?;
            lu_solve_t(&a, &f)
        }

        #lu_solve_t

        }
    } else {
        quote!()
    };
    let amm_wrapper = if want("actuator_mass_matrix") {
        quote! {
        #lu_inverse

        /// Inertia in actuator space `A⁻ᵀ I A⁻¹` (the lecture's eq. 68), symmetric.
        #[allow(clippy::all)]
        pub fn actuator_mass_matrix(x: &[f64; NX] #p_arg) -> Result<[[f64; DOF]; DOF], Singular> {
            let (a, i) = inertia_parts(x #p_pass)?;
            let ai = lu_inverse(&a)?;
            // B = I A⁻¹, then A⁻ᵀ B (upper triangle, mirrored).
            let mut b = [[0.0; DOF]; DOF];
            for r in 0..DOF {
                for c in 0..DOF {
                    let mut s = 0.0;
                    for k in 0..DOF {
                        s += i[r][k] * ai[k][c];
                    }
                    b[r][c] = s;
                }
            }
            let mut out = [[0.0; DOF]; DOF];
            for r in 0..DOF {
                for c in r..DOF {
                    let mut s = 0.0;
                    for k in 0..DOF {
                        s += ai[k][r] * b[k][c];
                    }
                    if !s.is_finite() {
                        return Err(Singular { site: Site::Input, value: s, condition_estimate: f64::INFINITY });
                    }
                    out[r][c] = s;
                    out[c][r] = s;
                }
            }
            Ok(out)
        }

        }
    } else {
        quote!()
    };
    quote! {
        /// Where an evaluation failed.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Site {
            /// Pivot `i` of the generalized inertia's `LDLᵀ` (forward dynamics).
            MassMatrix(usize),
            #[doc = #leg_doc]
            Leg(usize),
            /// Leg `k` cannot reach the platform: the pose is outside the workspace.
            Reach(usize),
            #[doc = #act_doc]
            Actuation(usize),
            /// The platform quaternion is zero (or not finite).
            Platform,
            /// An input (`x`, `u`, `ud`, `tau`) is NaN or infinite, or so large that a result
            /// overflows.
            Input,
        }

        /// A configuration where the method fails, or a non-finite input: never a NaN result.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Singular {
            /// Which matrix, leg or pivot.
            pub site: Site,
            /// The determinant, pivot or discriminant that failed its test.
            pub value: f64,
            /// Condition-number estimate of the matrix involved (`f64::INFINITY` if unknown).
            pub condition_estimate: f64,
        }

        /// Forward kinematics did not converge.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct NoConvergence {
            /// Newton iterations made.
            pub iterations: usize,
            /// The last residual `max |q(x) − q|` (m or rad).
            pub residual: f64,
        }

        /// Which actuators are revolute (angles are compared modulo 2π).
        const REVOLUTE: [bool; DOF] = [#(#revolute),*];

        #lu_solve

        #id_wrapper

        #amm_wrapper

        #retract

        /// The residual `q − q(x)` (angles wrapped to (−π, π]: `q`'s revolute entries are already
        /// in [−π, π], as `q(x)`'s are), its max norm, and `A(x)`.
        #[allow(clippy::all)]
        fn fk_residual(q: &[f64; DOF], x: &[f64; NX]) -> Option<([f64; DOF], f64, [[f64; DOF]; DOF])> {
            let (qx, a) = fk_parts(x).ok()?;
            let mut r = [0.0; DOF];
            let mut m: f64 = 0.0;
            for i in 0..DOF {
                let mut d = q[i] - qx[i];
                if REVOLUTE[i] {
                    let t = 2.0 * core::f64::consts::PI;
                    if d > core::f64::consts::PI {
                        d -= t;
                    } else if d <= -core::f64::consts::PI {
                        d += t;
                    }
                }
                r[i] = d;
                let ad = if d < 0.0 { -d } else { d };
                if !(ad <= m) {
                    m = ad;
                }
            }
            if m < f64::INFINITY { Some((r, m, a)) } else { None }
        }

        #(#[doc = #fk_doc])*
        #[allow(clippy::all)]
        pub fn forward_kinematics(q: &[f64; DOF], guess: &[f64; NX]) -> Result<[f64; NX], NoConvergence> {
            for v in q.iter().chain(guess.iter()) {
                if !v.is_finite() {
                    return Err(NoConvergence { iterations: 0, residual: f64::INFINITY });
                }
            }
            // Revolute targets reduced to [−π, π] once (sin and cos reduce accurately).
            let mut q = *q;
            for i in 0..DOF {
                if REVOLUTE[i] {
                    let v = q[i];
                    let (s, c) = #sin_cos_q;
                    q[i] = #atan2_sc;
                }
            }
            let q = &q;
            let tol = #fk_tol_lit;
            let mut x = retract(guess, &[0.0; DOF]);
            let Some(mut cur) = fk_residual(q, &x) else {
                return Err(NoConvergence { iterations: 0, residual: f64::INFINITY });
            };
            for it in 0..#fk_max_lit {
                if cur.1 <= tol {
                    return Ok(x);
                }
                let Ok(du) = lu_solve(&cur.2, &cur.0) else {
                    return Err(NoConvergence { iterations: it, residual: cur.1 });
                };
                let mut step = 1.0;
                let mut moved = false;
                for _ in 0..20 {
                    let mut d = [0.0; DOF];
                    for i in 0..DOF {
                        d[i] = du[i] * step;
                    }
                    let xn = retract(&x, &d);
                    if let Some(r) = fk_residual(q, &xn) {
                        if r.1 < cur.1 {
                            x = xn;
                            cur = r;
                            moved = true;
                            break;
                        }
                    }
                    step *= 0.5;
                }
                if !moved {
                    return Err(NoConvergence { iterations: it + 1, residual: cur.1 });
                }
            }
            if cur.1 <= tol {
                Ok(x)
            } else {
                Err(NoConvergence { iterations: #fk_max_lit, residual: cur.1 })
            }
        }
    }
}

/// The `retract` template: `x ⊕ du`.
fn retract_template(
    planar: bool,
    qi: Literal,
    translate: TokenStream,
    sqrt_a: TokenStream,
    sin_cos: TokenStream,
    sqrt_n: TokenStream,
) -> TokenStream {
    if planar {
        return quote! {
            /// `x` moved by `du` (the point's displacement, m).
            #[allow(clippy::all)]
            fn retract(x: &[f64; NX], du: &[f64; DOF]) -> [f64; NX] {
                let mut out = *x;
                for i in 0..NX {
                    out[i] += du[i];
                }
                out
            }
        };
    }
    quote! {
        /// `x` moved by the small motion `du` (rotation vector, then translation; base frame).
        #[allow(clippy::all)]
        fn retract(x: &[f64; NX], du: &[f64; DOF]) -> [f64; NX] {
            let a2 = du[0] * du[0] + du[1] * du[1] + du[2] * du[2];
            let a = #sqrt_a;
            let (s, c) = #sin_cos;
            let k = if a > 0.0 { s / a } else { 0.5 };
            let d = [c, k * du[0], k * du[1], k * du[2]];
            let i = #qi;
            let q = [x[i], x[i + 1], x[i + 2], x[i + 3]];
            let r = [
                d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
                d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
                d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
                d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0],
            ];
            let n = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3];
            let n = #sqrt_n;
            let mut out = *x;
            for j in 0..4 {
                out[i + j] = r[j] / n;
            }
            #translate
            out
        }

    }
}

//! Parallel mechanisms: the runtime's evaluator ([`runtime::parallel::noc`], written over
//! [`Real`]) run on a symbolic scalar, so that every operation becomes a node of the
//! hash-consed DAG ([`crate::sym`]): constants fold, structural zeros vanish and common
//! subexpressions are shared exactly as for trees. The DAG kernels are then wrapped by a few
//! fixed templates (the partially pivoted LU of the actuation matrix, Newton's forward
//! kinematics) into the module's public functions. [`generate`] assembles the module from named
//! pieces (the scheduled kernels, the op-count rows, the header, the constants and `Params`);
//! the templates are in the `templates` submodule.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::drive::DriveInputs;
use runtime::model::JointKind;
use runtime::parallel::noc::{self, PARASITIC_ITERATIONS, PARASITIC_TOLERANCE, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use runtime::scalar::{Real, Singular};

pub use crate::params::Layout;
use crate::params::{drive_inputs, params_items, payload_inputs, payload_inputs_at};
use crate::scalar::{Sx, flat, guarded, ids, in_fresh_graph, inputs};

use crate::emit::{self, Function, Part, Shape};
use crate::module::{self, ModulePlan};
use crate::schedule::{Kernel, OpCount};
use crate::spec::{Frame, Kind, RuntimeParams, Scene};
use crate::sym::{Arg, ExprId, Graph};
use crate::{Config, Generated, MathBackend, VERSION, tangent};

mod derivatives;
mod templates;

use templates::templates;

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
    /// `A` then `−γ` (`gravity`).
    pub gravity_parts: Kernel,
    /// `A` then `C u` (`coriolis`).
    pub coriolis_parts: Kernel,
    /// `A` then the leg joints' friction mapped to `u` (`friction`); `None` without friction.
    pub friction_parts: Option<Kernel>,
    /// A 1T2R platform's full pose `[px, py, pz, qw, qx, qy, qz]` (`platform_pose`: the
    /// parasitic components); `None` for the other motions.
    pub platform_pose: Option<Kernel>,
    /// `A`, `f`, then `∂A/∂x_j` (one matrix per speed `j`), `∂f/∂x` and `∂f/∂u` (`[i][j]`),
    /// the derivatives along the tangent of `x` (`codegen/src/tangent.rs`).
    pub idd_parts: Kernel,
    /// `u̇` (checked, not returned), then `∂u̇/∂x`, `∂u̇/∂u` and `∂u̇/∂τ`, row-major.
    pub forward_dynamics_derivatives: Kernel,
    /// Per frame of [`kernels_with_frames`] (`[scene] frames`, fixed to the platform): its
    /// pose (`R` row-major, then `p`), its Jacobian `J` (6 × n row-major) and `J̇ u`.
    pub frames: Vec<[Kernel; 3]>,
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
    kernels_with_frames(plan, layout, &[])
}

/// [`kernels_with`] and the kinematics of `frames`, fixed to the platform (each frame's
/// `placement` is its pose in the platform frame).
pub fn kernels_with_frames(
    plan: &Plan,
    layout: &Layout,
    frames: &[Frame],
) -> Result<Kernels, Singular> {
    let (r, graph) = in_fresh_graph(|| build(plan, layout, frames));
    r.map(|k| Kernels { graph, ..k })
}

/// The kernels of a frame fixed to the platform: pose, `J`, `J̇ u`, each with the guards of
/// the platform's pose.
fn frame_kernels(plan: &Plan, x: &[Sx], u: &[Sx], f: &Frame) -> Result<[Kernel; 3], Singular> {
    let at = &f.placement;
    let kernel = |which: usize| -> Result<Kernel, Singular> {
        let (out, guards) = guarded(|| {
            noc::platform(plan, x).map(|pl| match which {
                0 => {
                    let (r, p) = noc::frame_pose(&pl, at);
                    r.into_iter().flatten().chain(p).collect::<Vec<Sx>>()
                }
                1 => noc::frame_jacobian(plan.motion, &pl, at),
                _ => noc::frame_jacobian_dot_u(plan.motion, &pl, at, u).to_vec(),
            })
        });
        Ok(Kernel::new(ids(&out?), guards))
    };
    Ok([kernel(0)?, kernel(1)?, kernel(2)?])
}

fn build(plan: &Plan, layout: &Layout, frames: &[Frame]) -> Result<Kernels, Singular> {
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
    let a = noc::actuation_matrix(plan, &pl, &legs);
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
    let fd = fd?;
    let cat = |a: Vec<ExprId>, b: Vec<ExprId>| a.into_iter().chain(b).collect::<Vec<_>>();
    // The split of the efforts, built last so that the nodes of the functions above stay as
    // they were without it.
    let (fg, fc, ffr) = split(plan, &pl, &legs, &u, drives.as_ref(), &payloads);
    let split_kernel = |f: Vec<Sx>| with_kin(cat(flat(&a), ids(&f)));
    // Last, so that the nodes above stay as they are without it.
    let platform_pose = if plan.motion.parasitic() {
        let (pose, guards) = guarded(|| noc::parasitic_pose(plan, &x));
        Some(Kernel::new(ids(&pose?), guards))
    } else {
        None
    };
    // The derivatives along the tangent of `x`, the speeds and the efforts: last again.
    let d = derivatives::Derivatives::of(plan, &x, &a, &f, &fd, &i, &tau)?;
    let frames = frames
        .iter()
        .map(|f| frame_kernels(plan, &x, &u, f))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Kernels {
        graph: Graph::new(),
        inverse_kinematics: Kernel::new(ids(&q), pos_guards),
        actuator_rates: with_kin(ids(&rates)),
        id_parts: with_kin(cat(flat(&a), ids(&f))),
        mass_matrix: with_kin(flat(&i)),
        inertia_parts: with_kin(cat(flat(&a), flat(&i))),
        forward_dynamics: Kernel::new(ids(&fd), fd_guards.clone()),
        fk_parts: with_kin(cat(ids(&q), flat(&a))),
        gravity_parts: split_kernel(fg),
        coriolis_parts: split_kernel(fc),
        friction_parts: ffr.map(split_kernel),
        platform_pose,
        idd_parts: with_kin(d.idd_parts),
        forward_dynamics_derivatives: Kernel::new(
            d.forward_dynamics,
            tangent::union(fd_guards, d.forward_guards),
        ),
        frames,
    })
}

/// The generalized force split as the module's `gravity`, `coriolis` and `friction` take it
/// (the friction's part only when a leg joint has friction): `−γ` at rest, `C u` from a plan
/// and drives without friction at `u̇ = 0` and no gravity, and the friction from a plan of the
/// friction alone ([`Plan::without_friction`], [`Plan::friction_only`]). The payloads enter
/// the first two.
fn split(
    plan: &Plan,
    pl: &noc::Platform<Sx>,
    legs: &[noc::LegKin<Sx>],
    u: &[Sx],
    drives: Option<&DriveInputs<Sx>>,
    payloads: &[runtime::payload::Payload<Sx>],
) -> (Vec<Sx>, Vec<Sx>, Option<Vec<Sx>>) {
    let n = plan.dof();
    let zero = vec![Sx::c(0.0); n];
    let with_payloads = |mut f: Vec<Sx>, u: &[Sx], gravity: bool| {
        for p in payloads {
            let fp = noc::payload_force(plan, pl, p, u, &zero, gravity);
            for r in 0..n {
                f[r] = f[r] + fp[r];
            }
        }
        f
    };
    // At rest the drives do nothing: the plan's own (and its closed forms) serve.
    let fg = noc::generalized_force_with(plan, pl, legs, &zero, &zero, true, None);
    let fg = with_payloads(fg, &zero, true);
    let still = drives.map(DriveInputs::without_friction);
    let fc = noc::generalized_force_with(
        &plan.without_friction(),
        pl,
        legs,
        u,
        &zero,
        false,
        still.as_ref(),
    );
    let fc = with_payloads(fc, u, false);
    let run_time_friction = drives.is_some_and(|d| d.viscous.is_some() || d.coulomb.is_some());
    let ffr = (plan.has_friction() || run_time_friction).then(|| {
        let friction = drives.map(DriveInputs::friction_only);
        noc::generalized_force_with(
            &plan.friction_only(),
            pl,
            legs,
            u,
            &zero,
            false,
            friction.as_ref(),
        )
    });
    (fg, fc, ffr)
}

/// Operation count of the emitted `lu_solve_many::<K>` for an `n × n` matrix: squared column
/// norms, partial pivoting, `k` right-hand sides (`lu_solve` is `k = 1`, `lu_inverse` is
/// `k = n`). The error paths (a square root and a division each) are not counted.
pub fn lu_many_ops(n: usize, k: usize, groups: &[usize]) -> OpCount {
    let mut c = OpCount::default();
    // Squared column norms (for the scale-free pivot test), and each unit group's largest.
    c.mul += n * n;
    c.add += n * (n - 1);
    let distinct = (0..n)
        .filter(|&j| (0..j).all(|i| groups.get(i) != groups.get(j)))
        .count();
    c.cmp += n - distinct;
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
pub fn lu_ops(n: usize, groups: &[usize]) -> OpCount {
    lu_many_ops(n, 1, groups)
}

/// Operation count of `lu_inverse` followed by `A⁻ᵀ I A⁻¹` (`I A⁻¹` in full, then the upper
/// triangle of `A⁻ᵀ (I A⁻¹)`).
pub fn lu_inverse_ops(n: usize, groups: &[usize]) -> OpCount {
    let mut c = lu_many_ops(n, n, groups);
    let tri = n * (n + 1) / 2;
    c.mul += n * n * n + tri * n;
    c.add += (n * n + tri) * (n - 1);
    c
}

/// Operation count of `inverse_dynamics_derivatives` beyond its kernel: `lu_inverse`, then
/// `τ = A⁻ᵀ f` and, for each of the `2n` columns, its right-hand side (`∂f/∂x_j − (∂A/∂x_j)ᵀ τ`
/// or `∂f/∂u_j`) and its product with `A⁻ᵀ`.
pub fn idd_solve_ops(n: usize, groups: &[usize]) -> OpCount {
    let mut c = lu_many_ops(n, n, groups);
    // `A⁻ᵀ` times `2n + 1` vectors, and `n` products `(∂A/∂x_j)ᵀ τ` subtracted.
    c.mul += (2 * n + 1) * n * n + n * n * n;
    c.add += (2 * n + 1) * n * (n - 1) + n * n * n;
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
        fma: a.fma + b.fma * times,
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
    let layout = Layout::of(params);
    let want = |name: &str| scene.functions.wants(Kind::Parallel, name);
    let plan = Plan::new(model)?;
    if layout.drives() && plan.legs.iter().any(|l| l.shaft.is_some()) {
        // The run-time drives sit three to a leg; a shaft has six joints.
        return Err(
            "a Schönflies platform's drives cannot be run-time parameters yet (its shaft has six joints, the run-time layout three per leg): use [scene] parameters = \"constants\" or leave friction and rotor inertia off"
                .into(),
        );
    }
    let frames: &[Frame] = if want("frames") { &scene.frames } else { &[] };
    let k = kernels_with_frames(&plan, &layout, frames).map_err(|e| {
        format!("the mechanism is singular for every input ({e}); check the leg geometry")
    })?;
    let n = plan.dof();
    let names = frame_names(frames);
    let mut functions = functions(&k, &plan, &layout, &want);
    functions.extend(frame_functions(&k, frames, &names, n));
    let stats = stats(&functions, n, plan.motion.unit_groups(), &want, &names);
    let header = header(model, &plan, &layout, cfg, &stats);
    // The wrappers of the kernels that are emitted.
    let emitted = |name: &str| {
        functions
            .iter()
            .any(|f| f.name.strip_suffix("_parts") == Some(name))
    };
    let mut items = items(model, &plan, params, &layout, cfg, &emitted);
    items.extend(frame_items(frames));
    let code = module::render(
        &ModulePlan {
            name: &model.name,
            header,
            items,
            graph: &k.graph,
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
        c_crate: None,
    })
}

/// The coordinates of `x` and `u` for the platform's motion, as the docs of
/// `inverse_kinematics` state them.
fn coordinates_doc(motion: &PlatformMotion) -> &'static str {
    match motion {
        PlatformMotion::Pose => {
            "`x = [px, py, pz, qw, qx, qy, qz]` (platform frame origin, m, and unit quaternion, base frame); `u = [ω; v]` (rad/s; m/s of the platform frame origin, base-frame components)"
        }
        PlatformMotion::Orientation { .. } => {
            "`x = [qw, qx, qy, qz]` (unit quaternion of the platform about the fixed centre, base frame); `u = ω` (rad/s, base-frame components)"
        }
        PlatformMotion::PlanarPoint { .. } => {
            "`x = [px, py]` (the point where the legs meet, m, base frame); `u = [vx, vy]` (m/s)"
        }
        PlatformMotion::PlanarPose { .. } => {
            "`x = [px, py, φ]` (platform frame origin, m, base frame, in the plane of its home height; φ its rotation about base z from home, rad); `u = [vx, vy, ω]` (m/s of the platform frame origin, rad/s about z)"
        }
        PlatformMotion::HeaveTilt { .. } => {
            "`x = [pz, α, β]` (heave: the platform frame origin's z, m, base frame; tilts α, β, rad, 0 at home: rotation `Rz(γ)·Ry(β)·Rx(α)·R_home` about base axes, with the parasitic `px`, `py`, `γ` from the legs' constraints, see `platform_pose`); `u = [ż, α̇, β̇]`, the platform twist `[ω; v] = S(x) u`"
        }
        PlatformMotion::Translation { .. } => {
            "`x = [px, py, pz]` (platform frame origin, m, base frame; the orientation stays at home); `u = v` (m/s of the platform frame origin, base-frame components)"
        }
        PlatformMotion::Schoenflies { .. } => {
            "`x = [px, py, pz, θ]` (the carrier frame's origin, m, base frame, its orientation fixed at home; θ the tool's angle about base z, rad, 0 at home); `u = [vx, vy, vz, ω]` (m/s of the carrier, rad/s of the tool about z)"
        }
    }
}

/// The DAG kernels as the module's scheduled functions, in emission order: those `want`
/// selects (`id_parts` with `inverse_dynamics`, `inertia_parts` with `actuator_mass_matrix`).
fn functions(
    k: &Kernels,
    plan: &Plan,
    layout: &Layout,
    want: &dyn Fn(&str) -> bool,
) -> Vec<Function<'static>> {
    let n = plan.dof();
    let fallible = |parts: &[Part]| Shape::Fallible(parts.to_vec());
    let coords = coordinates_doc(&plan.motion);
    let fns = module::Functions {
        graph: &k.graph,
        dof: n,
        params: layout.any(),
    };
    let functions = [
        fns.make(
            "inverse_kinematics",
            vec![format!(
                "Actuated joint positions `q(x)` (rad or m, in `ACTUATOR_NAMES` order) by closed-form leg inverse kinematics. {coords}. `Err` when a leg cannot reach the platform (`Site::Reach`) or is singular (`Site::Leg`)."
            )],
            vec![Arg::X],
            &k.inverse_kinematics,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "actuator_rates",
            vec!["Actuator rates `q̇ = A u` (rad/s or m/s); `Err` at a leg singularity.".into()],
            vec![Arg::X, Arg::U],
            &k.actuator_rates,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "id_parts",
            vec!["Kernel of `inverse_dynamics`: the actuation matrix `A` and the generalized force `f = I u̇ + C u − γ`.".into()],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Ud]),
            &k.id_parts,
            fallible(&[Part::Matrix, Part::Vector]),
            false,
        ),
        fns.make(
            "gravity_parts",
            vec!["Kernel of `gravity`: `A` and `−γ`, the generalized force at rest.".into()],
            fns.with_p(vec![Arg::X]),
            &k.gravity_parts,
            fallible(&[Part::Matrix, Part::Vector]),
            false,
        ),
        fns.make(
            "coriolis_parts",
            vec!["Kernel of `coriolis`: `A` and `C u`, the generalized force of the velocities alone.".into()],
            fns.with_p(vec![Arg::X, Arg::U]),
            &k.coriolis_parts,
            fallible(&[Part::Matrix, Part::Vector]),
            false,
        ),
        fns.make(
            "mass_matrix",
            vec!["Generalized inertia `I = TᵀMT` of the speeds `u` (symmetric positive definite away from singularities; kg·m², kg·m, kg).".into()],
            fns.with_p(vec![Arg::X]),
            &k.mass_matrix,
            fallible(&[Part::Matrix]),
            true,
        ),
        fns.make(
            "inertia_parts",
            vec!["Kernel of `actuator_mass_matrix`: `A` and `I`.".into()],
            fns.with_p(vec![Arg::X]),
            &k.inertia_parts,
            fallible(&[Part::Matrix, Part::Matrix]),
            false,
        ),
        fns.make(
            "forward_dynamics",
            vec!["Speed rates `u̇` with `I u̇ = Aᵀ τ − (C u − γ)` for the actuator efforts `tau` (N or N·m); `Err` at a leg singularity or when a pivot of `I`'s `LDLᵀ` is not above `1e-12` times its diagonal entry.".into()],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Tau]),
            &k.forward_dynamics,
            fallible(&[Part::Vector]),
            true,
        ),
        fns.make(
            "idd_parts",
            vec!["Kernel of `inverse_dynamics_derivatives`: `A`, `f = I u̇ + C u − γ`, then `∂A/∂x_j` (one matrix per speed `j`), `∂f/∂x` and `∂f/∂u`, the derivatives in `x` along the tangent `x ⊕ δu`.".into()],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Ud]),
            &k.idd_parts,
            fallible(&[Part::Matrix, Part::Vector, Part::Matrices, Part::Matrix, Part::Matrix]),
            false,
        ),
        fns.make(
            "forward_dynamics_derivatives",
            vec![
                "`(∂u̇/∂x, ∂u̇/∂u, ∂u̇/∂τ)` of `forward_dynamics`; element `[i][j] = ∂u̇_i/∂x_j`, the derivative in `x` along the tangent `x ⊕ δu` (column `j`: `x` moved as by the speed `u_j`; see `inverse_dynamics_derivatives`). The same guards and errors as `forward_dynamics`.".into(),
            ],
            fns.with_p(vec![Arg::X, Arg::U, Arg::Tau]),
            &k.forward_dynamics_derivatives,
            fallible(&[Part::Hidden(n), Part::Matrix, Part::Matrix, Part::Matrix]),
            true,
        ),
        fns.make(
            "fk_parts",
            vec!["Kernel of `forward_kinematics`: `q(x)` and `A(x)`.".into()],
            vec![Arg::X],
            &k.fk_parts,
            fallible(&[Part::Vector, Part::Matrix]),
            false,
        ),
    ];
    let friction = k.friction_parts.as_ref().map(|kernel| {
        fns.make(
            "friction_parts",
            vec![
                "Kernel of `friction`: `A` and the leg joints' friction as a generalized force."
                    .into(),
            ],
            fns.with_p(vec![Arg::X, Arg::U]),
            kernel,
            fallible(&[Part::Matrix, Part::Vector]),
            false,
        )
    });
    let pose = k.platform_pose.as_ref().map(|kernel| {
        fns.make(
            "platform_pose",
            vec![format!(
                "The platform's full pose `[px, py, pz, qw, qx, qy, qz]` at `x` (m; unit quaternion platform → base): the parasitic components `px`, `py` and the turn `γ` about base z that the legs impose, with `R = Rz(γ)·Ry(β)·Rx(α)·R_home` as the quaternion `qz(γ) ⊗ qy(β) ⊗ qx(α) ⊗ q_home`. {coords}. `Err(Site::Platform)` where the legs' constraints do not fix the parasitic motion, `Err(Site::Reach(i))` where its {PARASITIC_ITERATIONS} Newton steps leave leg `i`'s constraint unmet (beyond {PARASITIC_TOLERANCE:e} of the platform radius)."
            )],
            vec![Arg::X],
            kernel,
            fallible(&[Part::Array(7)]),
            true,
        )
    });
    functions
        .into_iter()
        .chain(friction)
        .chain(pose)
        .filter(|f| {
            want(match f.name {
                "id_parts" => "inverse_dynamics",
                "idd_parts" => "inverse_dynamics_derivatives",
                "inertia_parts" => "actuator_mass_matrix",
                n => n.strip_suffix("_parts").unwrap_or(n),
            })
        })
        .collect()
}

/// The names of each frame's functions: `<ident>_pose`, `<ident>_jacobian`,
/// `<ident>_jacobian_dot_u`.
fn frame_names(frames: &[Frame]) -> Vec<[String; 3]> {
    frames
        .iter()
        .map(|f| ["pose", "jacobian", "jacobian_dot_u"].map(|s| format!("{}_{s}", f.ident)))
        .collect()
}

/// `NF` and `FRAME_NAMES` of a module with frames, nothing without.
fn frame_items(frames: &[Frame]) -> TokenStream {
    if frames.is_empty() {
        return TokenStream::new();
    }
    let nf = Literal::usize_unsuffixed(frames.len());
    let names = frames.iter().map(|f| f.name.as_str());
    quote! {
        /// Number of frames whose kinematics the module offers (`[scene] frames`).
        pub const NF: usize = #nf;
        /// The frames' names as the spec writes them; frame `F`'s functions are
        /// `F_pose`, `F_jacobian` and `F_jacobian_dot_u`, with `F` the name in lower snake
        /// case (docs/spec.md).
        pub const FRAME_NAMES: [&str; NF] = [#(#names),*];
    }
}

/// The functions of the frames fixed to the platform, scheduled.
fn frame_functions<'a>(
    k: &Kernels,
    frames: &[Frame],
    names: &'a [[String; 3]],
    n: usize,
) -> Vec<Function<'a>> {
    let fns = module::Functions {
        graph: &k.graph,
        dof: n,
        params: false,
    };
    let fallible = |parts: &[Part]| Shape::Fallible(parts.to_vec());
    let mut out = Vec::new();
    for ((f, [pose, jac, jdot]), kernels) in frames.iter().zip(names).zip(&k.frames) {
        let name = &f.name;
        out.push(fns.make(
            pose,
            vec![format!(
                "Pose of frame `{name}` (fixed to the platform) at `x`: `(R, p)`, the rotation base ← frame and its origin in the base frame (m). `Err` where the platform's pose is (a zero quaternion, `Site::Platform`; a 1T2R platform's parasitic motion, as `platform_pose`)."
            )],
            vec![Arg::X],
            &kernels[0],
            fallible(&[Part::Rotation, Part::Array(3)]),
            true,
        ));
        out.push(fns.make(
            jac,
            vec![format!(
                "Jacobian of frame `{name}`: `J(x) u = [ω; v]`, the frame's angular velocity then the velocity of its origin, base-frame components (Pinocchio's `LOCAL_WORLD_ALIGNED`, angular first); row `r`, column `j` is `∂t_r/∂u_j`. Errors as `{pose}`."
            )],
            vec![Arg::X],
            &kernels[1],
            fallible(&[Part::Jacobian]),
            true,
        ));
        out.push(fns.make(
            jdot,
            vec![format!(
                "`J̇ u` of frame `{name}` (the convention of `{jac}`): its classical acceleration `[ω̇; p̈]` is `J u̇ + J̇ u`. Errors as `{pose}`."
            )],
            vec![Arg::X, Arg::U],
            &kernels[2],
            fallible(&[Part::Array(6)]),
            true,
        ));
    }
    out
}

/// The operation counts of the header's table: each public function `want` selects, a
/// wrapper's LU (`inverse_dynamics`, `actuator_mass_matrix`, a step of `forward_kinematics`)
/// added to its kernel's count, then the frames' functions (`names`).
fn stats(
    functions: &[Function<'_>],
    n: usize,
    groups: &[usize],
    want: &dyn Fn(&str) -> bool,
    names: &[[String; 3]],
) -> Vec<(String, OpCount)> {
    let ops = |name: &str| {
        functions
            .iter()
            .find(|f| f.name == name)
            .map(|f| f.schedule.ops)
            .unwrap_or_default()
    };
    let lu = lu_ops(n, groups);
    let stats: Vec<(String, OpCount)> = vec![
        ("inverse_kinematics".into(), ops("inverse_kinematics")),
        ("actuator_rates".into(), ops("actuator_rates")),
        ("inverse_dynamics".into(), plus(ops("id_parts"), lu, 1)),
        ("gravity".into(), plus(ops("gravity_parts"), lu, 1)),
        ("coriolis".into(), plus(ops("coriolis_parts"), lu, 1)),
        ("mass_matrix".into(), ops("mass_matrix")),
        (
            "actuator_mass_matrix".into(),
            plus(ops("inertia_parts"), lu_inverse_ops(n, groups), 1),
        ),
        ("forward_dynamics".into(), ops("forward_dynamics")),
        (
            "inverse_dynamics_derivatives".into(),
            plus(ops("idd_parts"), idd_solve_ops(n, groups), 1),
        ),
        (
            "forward_dynamics_derivatives".into(),
            ops("forward_dynamics_derivatives"),
        ),
        (
            "forward_kinematics (per Newton step)".into(),
            plus(ops("fk_parts"), lu, 1),
        ),
    ];
    let friction = functions
        .iter()
        .any(|f| f.name == "friction_parts")
        .then(|| ("friction".to_string(), plus(ops("friction_parts"), lu, 1)));
    let pose = functions
        .iter()
        .any(|f| f.name == "platform_pose")
        .then(|| ("platform_pose".to_string(), ops("platform_pose")));
    let frames = names.iter().flatten().map(|f| (f.clone(), ops(f)));
    stats
        .into_iter()
        .chain(friction)
        .chain(pose)
        .filter(|(n, _)| want(n))
        .chain(frames)
        .collect()
}

/// The module's header comment: provenance, the mechanism, the math backend, the run-time
/// parameters (if any) and the operation-count table.
fn header(
    model: &ParallelModel,
    plan: &Plan,
    layout: &Layout,
    cfg: &Config,
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
            "Parallel mechanism: {} legs ({}); NX = {nx} position coordinates, DOF = {n}. Units: SI (m, kg, s, rad, N, N·m).",
            plan.legs.len(),
            plan.legs
                .iter()
                .map(|l| match (plan.motion.parasitic(), l.kind) {
                    // A 1T2R platform's P-R and R-P legs end in a spherical joint.
                    (true, runtime::parallel::LegKind::PlanarPr) => "PRS",
                    (true, runtime::parallel::LegKind::PlanarRp) => "RPS",
                    (_, kind) => kind.word(),
                })
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
        header.insert(3, params_line(layout));
    }
    header.extend(emit::stats_table_per(stats, n, "DOF"));
    header
}

/// The header line naming the run-time parameters.
fn params_line(layout: &Layout) -> String {
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
    format!("Run-time parameters: {what} (`Params`, `[scene] parameters = \"runtime\"`).")
}

/// The items before the functions: the constants, the run-time parameters' items and the fixed
/// templates.
fn items(
    model: &ParallelModel,
    plan: &Plan,
    params: Option<&RuntimeParams>,
    layout: &Layout,
    cfg: &Config,
    want: &dyn Fn(&str) -> bool,
) -> TokenStream {
    let real = crate::emit::real();
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
    let items = templates(cfg, plan, &revolute, want, layout.any());
    let params_items = runtime_params(model, params, layout);
    let nx_lit = Literal::usize_unsuffixed(plan.nx());
    let n_lit = Literal::usize_unsuffixed(plan.dof());
    let home: Vec<Literal> = model
        .home_x()
        .iter()
        .map(|&v| Literal::f64_unsuffixed(v))
        .collect();
    quote! {
        /// Number of position coordinates `x`.
        pub const NX: usize = #nx_lit;
        /// Degrees of freedom: speeds `u`, actuators.
        pub const DOF: usize = #n_lit;
        /// The actuated joints, in the order of `q` and `tau`.
        pub const ACTUATOR_NAMES: [&str; DOF] = [#(#names),*];
        /// The spec's home configuration `x` (its legs in their declared branches): a guess for
        /// `forward_kinematics` near home.
        #[allow(clippy::excessive_precision)]
        pub const HOME: [#real; NX] = [#(#home),*];
        #params_items
        #items
    }
}

/// The run-time parameters' items (`Params`; with the drives, `LEG_JOINTS` and
/// `LEG_JOINT_NAMES`), nothing without run-time parameters.
fn runtime_params(
    model: &ParallelModel,
    params: Option<&RuntimeParams>,
    layout: &Layout,
) -> TokenStream {
    if !layout.any() {
        return quote!();
    }
    let payload = params.and_then(|p| p.payload);
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
        layout,
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
}

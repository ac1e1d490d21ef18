//! Trees: the symbolic dynamics of a validated model ([`crate::dynamics`]) scheduled and
//! emitted as the module's functions, with the `Params` struct of a module whose payload,
//! bodies or drives are run-time parameters.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::model::Model;

use crate::dynamics::{self, Terms, Tree};
use crate::emit::{self, Function, Part, Shape};
use crate::module::{self, ModulePlan};
use crate::schedule::{Kernel, OpCount, schedule};
use crate::spec::{self, Kind, Scene};
use crate::sym::{self, Arg, Graph};
use crate::{Config, Generated, MathBackend, VERSION, diag};

/// The symbolic dynamics of a model: one expression DAG and the output nodes of each function.
pub struct Symbolic {
    /// The shared DAG.
    pub graph: Graph,
    /// Degrees of freedom.
    pub dof: usize,
    /// `I(q)`, row-major.
    pub mass_matrix: Vec<sym::ExprId>,
    /// `C(q, q̇) q̇`.
    pub coriolis: Vec<sym::ExprId>,
    /// `−γ(q)`.
    pub gravity: Vec<sym::ExprId>,
    /// `I q̈ + C q̇ − γ`.
    pub inverse_dynamics: Vec<sym::ExprId>,
    /// `I⁻¹ (τ − C q̇ + γ)` with checked pivots.
    pub forward_dynamics: Vec<sym::ExprId>,
    /// The pivot guards of `forward_dynamics`, in the order of its factorization (the other
    /// functions test nothing).
    pub forward_dynamics_guards: Vec<sym::ExprId>,
    /// Joint friction `δ(q̇)`, when some joint's drive has friction (`[scene] friction`).
    pub friction: Option<Vec<sym::ExprId>>,
    /// `∂τ/∂q` then `∂τ/∂q̇` of `inverse_dynamics`, each row-major.
    pub inverse_dynamics_derivatives: Vec<sym::ExprId>,
    /// `q̈` (checked, not returned), then `∂q̈/∂q`, `∂q̈/∂q̇` and `I⁻¹ = ∂q̈/∂τ`, each
    /// row-major; under `forward_dynamics_guards`.
    pub forward_dynamics_derivatives: Vec<sym::ExprId>,
    /// The regressor over the base parameters (`None` with run-time parameters).
    pub regressor: Option<dynamics::Regressor>,
    /// Per frame of [`symbolic_with_frames`], in its order: `pose` (`R` row-major, then `p`),
    /// `jacobian` (`6 × n` row-major) and `J̇ q̇` ([`dynamics::frame_kinematics`]).
    pub frames: Vec<[Vec<sym::ExprId>; 3]>,
}

/// Build the symbolic dynamics of a validated model.
pub fn symbolic(model: &Model) -> Symbolic {
    symbolic_with(model, None)
}

/// [`symbolic`] with run-time parameters (`[scene] parameters = "runtime"`): every output also
/// reads `Arg::P` (layout: [`dynamics::param_index`]).
pub fn symbolic_with(model: &Model, params: Option<&spec::RuntimeParams>) -> Symbolic {
    symbolic_with_frames(model, params, &[])
}

/// [`symbolic_with`] and the kinematics of `frames` (`[scene] frames`).
pub fn symbolic_with_frames(
    model: &Model,
    params: Option<&spec::RuntimeParams>,
    frames: &[spec::Frame],
) -> Symbolic {
    let mut tree = Tree::new(model);
    if let Some(rp) = params {
        tree = tree.with_runtime_params(rp.payload.as_ref().map(|p| p.0), rp.coulomb_velocity);
        let bodies: Vec<usize> = rp.bodies.iter().map(|b| b.body).collect();
        tree = tree.with_runtime_bodies(&bodies);
    }
    let mut g = Graph::new();
    let mm = dynamics::mass_matrix(&mut g, &tree);
    let mass_matrix: Vec<_> = mm.iter().flatten().copied().collect();
    let coriolis = dynamics::inverse_dynamics(
        &mut g,
        &tree,
        Terms {
            velocity: true,
            ..Terms::NONE
        },
    );
    let gravity = dynamics::inverse_dynamics(
        &mut g,
        &tree,
        Terms {
            gravity: true,
            ..Terms::NONE
        },
    );
    let inverse_dynamics = dynamics::inverse_dynamics(&mut g, &tree, Terms::ALL);
    debug_assert!(
        g.take_guards().is_empty(),
        "a tree function other than FD tests"
    );
    let forward_dynamics = dynamics::forward_dynamics(&mut g, &tree);
    let forward_dynamics_guards = g.take_guards();
    let friction = model
        .joints
        .iter()
        .any(|j| j.drive.viscous != 0.0 || j.drive.coulomb != 0.0)
        .then(|| {
            dynamics::inverse_dynamics(
                &mut g,
                &tree,
                Terms {
                    friction: true,
                    ..Terms::NONE
                },
            )
        });
    // Built last, so that the nodes (and the emitted text) of the functions above stay as
    // they were without them.
    let mut inverse_dynamics_derivatives =
        dynamics::inverse_dynamics_derivatives(&mut g, &inverse_dynamics);
    let mut forward_dynamics_derivatives = dynamics::forward_dynamics_derivatives(
        &mut g,
        &tree,
        &inverse_dynamics_derivatives,
        &forward_dynamics,
    );
    debug_assert_eq!(
        g.take_guards(),
        forward_dynamics_guards,
        "the derivatives test what forward dynamics tests"
    );
    // With run-time parameters the base parameters' values would be inputs: left out.
    let regressor = params
        .is_none()
        .then(|| dynamics::regressor(&mut g, &tree, model));
    // Last of all, for the same reason.
    let frames = frames
        .iter()
        .map(|f| {
            [
                dynamics::FramePart::Pose,
                dynamics::FramePart::Jacobian,
                dynamics::FramePart::JacobianDotQd,
            ]
            .map(|part| dynamics::frame_kinematics(&mut g, &tree, f.body, &f.placement, part))
        })
        .collect();
    // The recursive derivatives where they are cheaper, after everything else (same reason).
    dynamics::prefer_recursive_derivatives(
        &mut g,
        &tree,
        &mut inverse_dynamics_derivatives,
        &mut forward_dynamics_derivatives,
        &forward_dynamics,
    );
    let guards = g.take_guards();
    debug_assert!(
        guards.is_empty() || guards == forward_dynamics_guards,
        "the derivatives test what forward dynamics tests"
    );
    Symbolic {
        graph: g,
        dof: tree.dof(),
        mass_matrix,
        coriolis,
        gravity,
        inverse_dynamics,
        forward_dynamics,
        forward_dynamics_guards,
        friction,
        inverse_dynamics_derivatives,
        forward_dynamics_derivatives,
        regressor,
        frames,
    }
}

/// The `Params` struct of a module with run-time parameters: fields named for the user, its
/// `DEFAULT` (the values the spec gives), and `to_array` in [`dynamics::param_index`]'s layout.
fn params_template(model: &Model, rp: &spec::RuntimeParams) -> proc_macro2::TokenStream {
    let real = crate::emit::real();
    use proc_macro2::Literal;
    use quote::quote;
    let n = model.dof();
    let np = Literal::usize_unsuffixed(dynamics::param_count_with(n, rp.bodies.len()));
    let arr = |f: &dyn Fn(&runtime::model::Drive) -> f64| {
        let v: Vec<_> = model
            .joints
            .iter()
            .map(|j| emit::float_lit(f(&j.drive)))
            .collect();
        quote!([#(#v),*])
    };
    let damping = arr(&|d| d.viscous);
    let friction = arr(&|d| d.coulomb);
    let armature = arr(&|d| d.armature);
    let at = |k| Literal::usize_unsuffixed(dynamics::param_index(k, 0, n));
    let (d0, f0, a0) = (
        at(dynamics::ParamKind::Damping),
        at(dynamics::ParamKind::Friction),
        at(dynamics::ParamKind::Armature),
    );
    let (payload_fields, payload_default, payload_fill) = match &rp.payload {
        None => (quote!(), quote!(), quote!()),
        Some((b, m, c, i)) => {
            crate::params::payload_params(&format!("body `{}`", model.bodies[*b].name), *m, c, i)
        }
    };
    let (body_items, body_fields, body_default, body_fill) = crate::params::body_params(
        &rp.bodies,
        &|b| format!("model body `{}`", model.bodies[b].name),
        dynamics::body_param_index(0, n),
    );
    quote! {
        #body_items
        /// Number of run-time parameters in [`Params::to_array`].
        pub const NP: usize = #np;
        /// Run-time parameters (`[scene] parameters = "runtime"`): every function takes them, so
        /// one binary serves several payloads or drive calibrations. SI units.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Params {
            #payload_fields
            /// Viscous friction per joint (N·m·s/rad or N·s/m).
            pub damping: [#real; DOF],
            /// Coulomb friction level per joint (N·m or N), regularized as in the spec docs.
            pub friction: [#real; DOF],
            /// Reflected rotor inertia per joint (kg·m² or kg).
            pub armature: [#real; DOF],
            #body_fields
        }
        impl Params {
            /// The values of the spec (what a module with constants would fold in).
            pub const DEFAULT: Params = Params {
                #payload_default
                damping: #damping,
                friction: #friction,
                armature: #armature,
                #body_default
            };
            /// The flat layout the generated functions read.
            pub fn to_array(&self) -> [#real; NP] {
                let mut a = [0.0; NP];
                #payload_fill
                let mut i = 0;
                while i < DOF {
                    a[#d0 + i] = self.damping[i];
                    a[#f0 + i] = self.friction[i];
                    a[#a0 + i] = self.armature[i];
                    i += 1;
                }
                #body_fill
                a
            }
        }
        impl Default for Params {
            fn default() -> Self {
                Self::DEFAULT
            }
        }
    }
}

/// Generate the module of a validated tree for `scene`: only the functions it selects (those
/// not asked for are not emitted, so their operations cost nothing), with its run-time
/// parameters (`None`: constants).
pub fn generate(model: &Model, scene: &Scene, cfg: &Config) -> Generated {
    let params = scene.params.as_ref();
    let frames: &[spec::Frame] = if scene.functions.wants(Kind::Tree, "frames") {
        &scene.frames
    } else {
        &[]
    };
    let parts = symbolic_with_frames(model, params, frames);
    let n = parts.dof;
    let base = parts.regressor.as_ref().map(|r| r.base.clone());
    let (g, specs) = tree_specs(parts, params.is_some(), frames);
    let names: Vec<String> = specs.iter().map(|s| s.0.clone()).collect();
    let functions = tree_functions(&g, specs, &names, scene, n);
    let base = base.filter(|_| functions.iter().any(|f| f.name == "regressor"));
    let stats: Vec<(String, OpCount)> = functions
        .iter()
        .map(|f| (f.name.to_string(), f.schedule.ops))
        .collect();
    let header = tree_header(model, n, cfg, &stats);
    let joint_names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let mut extra = params
        .map(|rp| params_template(model, rp))
        .unwrap_or_default();
    if let Some(base) = &base {
        extra.extend(base_parameter_items(base, "q, q̇, q̈"));
    }
    let frame_names: Vec<&str> = frames.iter().map(|f| f.name.as_str()).collect();
    let items = items(n, &joint_names, &frame_names, &functions, extra);
    let code = module::render(
        &ModulePlan {
            name: &model.name,
            header,
            items,
            graph: &g,
            functions,
            after: quote!(),
        },
        cfg,
    );
    Generated {
        code,
        stats,
        dof: n,
        warnings: diag::Diagnostics::new("", ""),
        per: "joint",
        c_crate: None,
    }
}

/// One candidate function of a tree module: name, doc paragraphs, arguments, kernel, shape.
type Spec = (String, Vec<String>, Vec<Arg>, Kernel, Shape);

/// The graph and every function a tree module can hold, in module order (`friction` when the
/// model has friction, then the functions of `frames`); each dynamics function also reads
/// `Arg::P` with `runtime_params`.
fn tree_specs(parts: Symbolic, runtime_params: bool, frames: &[spec::Frame]) -> (Graph, Vec<Spec>) {
    let Symbolic {
        graph: g,
        dof: _,
        mass_matrix: mm_out,
        coriolis: cor,
        gravity: grav,
        inverse_dynamics: id,
        forward_dynamics: fd,
        forward_dynamics_guards: fd_guards,
        friction,
        inverse_dynamics_derivatives: idd,
        forward_dynamics_derivatives: fdd,
        regressor,
        frames: frame_outputs,
    } = parts;
    let n = fd.len();
    let k = |outputs: Vec<sym::ExprId>| Kernel::new(outputs, Vec::new());
    let mut specs: Vec<Spec> = vec![
        (
            "mass_matrix".into(),
            vec![
                "Generalized inertia matrix `I(q) = TᵀMT` (lecture eq. 21), symmetric positive \
                 definite away from singularities; kg·m² (revolute rows/columns), kg (prismatic)."
                    .into(),
            ],
            vec![Arg::Q],
            k(mm_out),
            Shape::Matrix,
        ),
        (
            "coriolis".into(),
            vec![
                "Velocity-dependent efforts `C(q, q̇) q̇` with `C = Tᵀ(MṪ + WMT)` (lecture eq. 22): \
                 Coriolis and centrifugal terms, no gravity."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd],
            k(cor),
            Shape::Vector,
        ),
        (
            "gravity".into(),
            vec![
                "Efforts that hold the mechanism still against gravity, `−γ(q) = −Tᵀ w^G`; equal \
                 to `inverse_dynamics(q, 0, 0)`."
                    .into(),
            ],
            vec![Arg::Q],
            k(grav),
            Shape::Vector,
        ),
        (
            "inverse_dynamics".into(),
            vec![
                "Joint efforts (N·m for revolute, N for prismatic joints) that produce the motion: \
                 `τ = I q̈ + C q̇ − γ` (lecture eq. 24). Units: q in rad or m, q̇ in rad/s or m/s, \
                 q̈ in rad/s² or m/s²."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Qdd],
            k(id),
            Shape::Vector,
        ),
        (
            "forward_dynamics".into(),
            vec![
                "Joint accelerations `q̈ = I⁻¹ (τ − C q̇ + γ)`; `Err(Singular)` when a pivot of \
                 the mass matrix's factorization is not above `1e-12` times its diagonal entry \
                 (or an input is NaN)."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Tau],
            Kernel::new(fd, fd_guards.clone()),
            Shape::FallibleVector,
        ),
        (
            "inverse_dynamics_derivatives".into(),
            vec![
                "Derivatives of `inverse_dynamics`: `(∂τ/∂q, ∂τ/∂q̇)`, element `[i][j] = \
                 ∂τ_i/∂x_j`, exact (symbolic differentiation of the same expressions, friction \
                 and rotor inertia included). `∂τ/∂q̈` is `mass_matrix`."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Qdd],
            k(idd),
            Shape::Tuple(vec![Part::Matrix, Part::Matrix]),
        ),
        (
            "forward_dynamics_derivatives".into(),
            vec![
                "Derivatives of `forward_dynamics`: `(∂q̈/∂q, ∂q̈/∂q̇, I⁻¹ = ∂q̈/∂τ)`, element \
                 `[i][j] = ∂q̈_i/∂x_j`, with `∂q̈/∂x = −I⁻¹ ∂τ/∂x` at `q̈ = forward_dynamics(q, \
                 q̇, τ)`. The same factorization, pivots and errors as `forward_dynamics` (and \
                 `Err` with `pivot == DOF` when a derivative overflows)."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Tau],
            Kernel::new(fdd, fd_guards),
            Shape::Fallible(vec![
                Part::Hidden(n),
                Part::Matrix,
                Part::Matrix,
                Part::Matrix,
            ]),
        ),
    ];
    if let Some(friction) = friction {
        specs.push((
            "friction".into(),
            vec![
                "Joint friction efforts `δ(q̇) = b q̇ + c q̇ / √(q̇² + v_s²)` (viscous and \
                 regularized Coulomb, `[scene] friction = true`); included in \
                 `inverse_dynamics` and `forward_dynamics`."
                    .into(),
            ],
            vec![Arg::Qd],
            k(friction),
            Shape::Vector,
        ));
    }
    if let Some(r) = regressor {
        specs.push((
            "regressor".into(),
            vec![
                "The regressor over the base parameters: `inverse_dynamics(q, q̇, q̈) = \
                 regressor(q, q̇, q̈) · BASE_PARAMETERS`, element `[i][k]` the effort of joint \
                 `i` per unit of base parameter `k` (`BASE_PARAMETER_NAMES[k]`: the standard \
                 parameters it groups). Linear in the parameters, for identification from \
                 measured efforts."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Qdd],
            k(r.outputs),
            Shape::Regressor,
        ));
    }
    if runtime_params {
        for spec in &mut specs {
            spec.2.push(Arg::P);
        }
    }
    for (f, [pose, jacobian, jdot]) in frames.iter().zip(frame_outputs) {
        specs.extend(frame_specs(f, pose, jacobian, jdot));
    }
    (g, specs)
}

/// The three functions of frame `f`.
fn frame_specs(
    f: &spec::Frame,
    pose: Vec<sym::ExprId>,
    jacobian: Vec<sym::ExprId>,
    jdot: Vec<sym::ExprId>,
) -> [Spec; 3] {
    let k = |outputs: Vec<sym::ExprId>| Kernel::new(outputs, Vec::new());
    let (name, id) = (&f.name, &f.ident);
    [
        (
            format!("{id}_pose"),
            vec![format!(
                "Pose of frame `{name}`: `(R, p)`, the rotation base ← frame (its columns are \
                 the frame's axes in the base frame) and the position of its origin in the base \
                 frame (m)."
            )],
            vec![Arg::Q],
            k(pose),
            Shape::Tuple(vec![Part::Rotation, Part::Array(3)]),
        ),
        (
            format!("{id}_jacobian"),
            vec![format!(
                "Jacobian of frame `{name}`: `J q̇ = [ω; v]`, its angular velocity then the \
                 velocity of its origin, both in base-frame components (Pinocchio's \
                 `LOCAL_WORLD_ALIGNED`, angular first); row `r`, column `j` is `∂t_r/∂q̇_j`."
            )],
            vec![Arg::Q],
            k(jacobian),
            Shape::Tuple(vec![Part::Jacobian]),
        ),
        (
            format!("{id}_jacobian_dot_qd"),
            vec![format!(
                "`J̇ q̇` of frame `{name}` (the convention of `{id}_jacobian`): its classical \
                 acceleration `[ω̇; p̈]` is `J q̈ + J̇ q̇`."
            )],
            vec![Arg::Q, Arg::Qd],
            k(jdot),
            Shape::Tuple(vec![Part::Array(6)]),
        ),
    ]
}

/// The functions `scene` selects among `specs` (named `names`, the specs' names), each
/// scheduled on `g`. The frames' functions are already chosen (`generate`).
fn tree_functions<'a>(
    g: &Graph,
    specs: Vec<Spec>,
    names: &'a [String],
    scene: &Scene,
    n: usize,
) -> Vec<Function<'a>> {
    specs
        .into_iter()
        .zip(names)
        .filter(|(s, _)| scene.functions.wants(Kind::Tree, &s.0))
        .map(|((_, doc, args, kernel, shape), name)| {
            let schedule = schedule(g, &kernel);
            let outputs = kernel.outputs;
            Function {
                name,
                doc,
                args,
                outputs,
                shape,
                schedule,
                dof: n,
                public: true,
                sites: false,
            }
        })
        .collect()
}

/// `NBP`, `BASE_PARAMETERS` and `BASE_PARAMETER_NAMES`, emitted with `regressor` (whose
/// arguments are `args`, as its docs write them).
pub(crate) fn base_parameter_items(base: &dynamics::Base, args: &str) -> TokenStream {
    let real = crate::emit::real();
    let nbp = Literal::usize_unsuffixed(base.values.len());
    // In single precision, the values rounded to `f32` (as many digits as the type holds).
    let values = base.values.iter().map(|&v| {
        if crate::scalar::single() {
            let lit = Literal::f32_unsuffixed((v as f32).abs());
            if v < 0.0 { quote!(-#lit) } else { quote!(#lit) }
        } else {
            emit::float_lit(v)
        }
    });
    let names = base.names.iter();
    let values_doc = format!(" `regressor({args}) · BASE_PARAMETERS = inverse_dynamics({args})`.");
    quote! {
        /// Number of base (identifiable) parameters: the rank of the standard regressor over
        /// generic states (docs/method.md, "Identification: the regressor and base parameters").
        pub const NBP: usize = #nbp;
        /// The spec's values of the base parameters, so that
        #[doc = #values_doc]
        pub const BASE_PARAMETERS: [#real; NBP] = [#(#values),*];
        /// What each base parameter is: the linear combination of standard parameters it
        /// groups. Standard parameters (Khalil's convention) per body, in its body frame about
        /// its origin: `XX, XY, XZ, YY, YZ, ZZ` (inertia tensor entries), `MX, MY, MZ` (mass
        /// times mass centre), `M`, written `XX_<body>`; per joint with drives `FV_<joint>`
        /// (viscous), `FC_<joint>` (Coulomb level), `IA_<joint>` (rotor inertia).
        pub const BASE_PARAMETER_NAMES: [&str; NBP] = [#(#names),*];
    }
}

/// The module's header: provenance, degrees of freedom, math backend, operation counts.
fn tree_header(model: &Model, n: usize, cfg: &Config, stats: &[(String, OpCount)]) -> Vec<String> {
    let mut header = vec![
        format!(
            "@generated by nocdyn codegen {VERSION} from mechanism `{}` — do not edit.",
            model.name
        ),
        format!("Degrees of freedom: {n}. Units: SI (m, kg, s, rad, N, N·m)."),
        match &cfg.math {
            MathBackend::Libm => {
                "Math backend: the `libm` crate (sin/cos, sqrt); otherwise core only.".into()
            }
            MathBackend::Std => "Math backend: std (`f64::sin_cos`).".into(),
            MathBackend::Runtime(p) => format!("Math backend: `{p}::math` (nocdyn runtime)."),
        },
        "Operation counts per call:".into(),
    ];
    header.extend(emit::stats_table(stats, n));
    header
}

/// The tree module's items before its functions: `DOF`, `JOINT_NAMES`, `NF` and `FRAME_NAMES`
/// (when the module has frames), the `Singular` error of `forward_dynamics` (when it is
/// emitted) and `extra` (the `Params` items).
fn items(
    dof: usize,
    joint_names: &[String],
    frame_names: &[&str],
    functions: &[Function<'_>],
    extra: TokenStream,
) -> TokenStream {
    let real = crate::emit::real();
    let real_doc = crate::emit::real_text(
        " of the mass matrix (`f64::INFINITY` when the pivot is not positive).",
    );
    let dof_lit = Literal::usize_unsuffixed(dof);
    let names = joint_names.iter();
    let needs_singular = functions
        .iter()
        .any(|f| matches!(f.shape, Shape::FallibleVector | Shape::Fallible(_)));
    let singular = needs_singular.then(|| {
        quote! {
            /// A failed pivot of the mass-matrix factorization: the configuration is singular
            /// (or an input is NaN). `value` is the pivot that was not above its tolerance
            /// (`1e-12` times the diagonal entry it came from); `condition_estimate` is that
            /// diagonal entry divided by the pivot, a lower bound of the 2-norm condition number
            #[doc = #real_doc]
            /// `pivot == DOF` is no pivot: the pivots passed but an input was not finite or the
            /// result overflowed (`value` is the first non-finite entry of the result).
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Singular {
                /// Index (joint) of the failed pivot; `DOF` for a non-finite input or result.
                pub pivot: usize,
                /// The pivot's value (the non-finite entry when `pivot == DOF`).
                pub value: #real,
                /// Lower bound of the mass matrix's 2-norm condition number.
                pub condition_estimate: #real,
            }

            impl core::fmt::Display for Singular {
                fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                    if self.pivot == DOF {
                        write!(f, "non-finite input or result ({:e})", self.value)
                    } else {
                        write!(
                            f,
                            "singular mass matrix: pivot {} is {:e}, condition number at least {:e}",
                            self.pivot, self.value, self.condition_estimate
                        )
                    }
                }
            }

            impl core::error::Error for Singular {}
        }
    });
    let frames = (!frame_names.is_empty()).then(|| {
        let nf = Literal::usize_unsuffixed(frame_names.len());
        quote! {
            /// Number of frames whose kinematics the module offers (`[scene] frames`).
            pub const NF: usize = #nf;
            /// The frames' names as the spec writes them; frame `F`'s functions are
            /// `F_pose`, `F_jacobian` and `F_jacobian_dot_qd`, with `F` the name in lower snake
            /// case (docs/spec.md).
            pub const FRAME_NAMES: [&str; NF] = [#(#frame_names),*];
        }
    });
    quote! {
        /// Number of degrees of freedom (joint coordinates).
        pub const DOF: usize = #dof_lit;
        /// Joint names, in coordinate order.
        pub const JOINT_NAMES: [&str; DOF] = [#(#names),*];
        #frames
        #singular
        #extra
    }
}

//! The `[scene]` table and the [`SceneOverrides`] on top of it: the passes between reading and
//! lowering (point masses, massless bodies, locked joints, drives, snapping), the functions a
//! scene selects, and the run-time parameters placed on their model bodies.

use super::{Function, MAX_SNAP, SNAP_HINT, is_snap_tolerance, suggest_hint};
use super::{
    FunctionSet, Kind, Mechanism, closed, geom, ir, is_urdf, lower, parallel, read_toml, snap,
};
use crate::diag::{Diagnostic, Diagnostics};

/// What the application needs of the mechanism (the spec's `[scene]` table, with the
/// [`SceneOverrides`] applied), as the generators read it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The public functions to emit (`[scene] functions`).
    pub functions: FunctionSet,
    /// The run-time parameters (`[scene] parameters = "runtime"`; `None`: constants).
    pub params: Option<RuntimeParams>,
    /// The frames whose kinematics the module offers (`[scene] frames`; a tree's default is
    /// its leaf bodies, the other kinds have none by default).
    pub frames: Vec<super::Frame>,
}

/// Scene switches from outside the spec (CLI flags, [`crate::Config`]): each turns its effect
/// on in addition to what the spec's `[scene]` says (a URDF has no `[scene]`; its
/// `<dynamics damping friction>` apply only with `friction`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneOverrides {
    /// A `[scene]` sidecar: a TOML file holding only `[scene]` (and `[parameters]`) for a spec
    /// that has none, a URDF's in particular (docs/scene.md, "A scene for a URDF").
    pub sidecar: Option<SceneFile>,
    /// Apply the joints' viscous (`damping`) and Coulomb (`friction`) friction.
    pub friction: bool,
    /// Apply the joints' reflected rotor inertia (`armature`).
    pub rotor_inertia: bool,
    /// Take near-exact angles and offsets as exact within this tolerance (as `[scene] snap`;
    /// replaces the spec's value). Out of (0, [`MAX_SNAP`]] it is an error.
    pub snap: Option<f64>,
    /// Leave these functions out, on top of what `[scene] functions` selects (a name the
    /// mechanism's kind does not offer, or always emits, is ignored): e.g. a single-precision
    /// build without derivatives.
    pub omit: Vec<super::Function>,
}

/// A `[scene]` sidecar file: its name (for messages) and text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneFile {
    /// The file's name as diagnostics show it.
    pub name: String,
    /// Its text.
    pub text: String,
}

/// An error when joint `j`, which `role` (e.g. "closes a loop"), has a drive: friction and rotor
/// inertia are modelled only where the joint's rate is known.
pub(super) fn no_drive(j: &ir::JointSpec, role: &str, hint: &str, diags: &mut Diagnostics) {
    if j.drive != Default::default() {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" {role}: friction and rotor inertia are not modelled there",
                j.name
            ))
            .with_key(j.key.clone())
            .with_span(j.span.clone())
            .with_hint(hint),
        );
    }
}

/// The error of a scene key naming joint `n`, which `joints` does not have (with the closest
/// name as hint).
fn unknown_joint(n: &ir::Named, joints: &[ir::JointSpec]) -> Diagnostic {
    let names: Vec<&str> = joints.iter().map(|j| j.name.as_str()).collect();
    let d = Diagnostic::error(format!("unknown joint {:?}", n.name))
        .with_key(n.key.clone())
        .with_span(n.span.clone());
    match suggest_hint(&n.name, &names) {
        Some(h) => d.with_hint(h),
        None => d,
    }
}

/// The passes between reading and lowering: the overrides on top of the spec's `[scene]`,
/// snapping, then the scene's changes to the bodies and joints.
pub(super) fn prepare(spec: &mut ir::Spec, overrides: &SceneOverrides, diags: &mut Diagnostics) {
    spec.scene.friction |= overrides.friction;
    spec.scene.rotor_inertia |= overrides.rotor_inertia;
    if let Some(tol) = overrides.snap {
        if is_snap_tolerance(tol) {
            spec.scene.snap = Some(tol);
        } else {
            // Set outside the file (`--snap`, `Builder::snap`): no place in it to point at.
            diags.push(
                Diagnostic::error(format!(
                    "the snap tolerance {tol} is not in (0, {MAX_SNAP}]"
                ))
                .with_hint(SNAP_HINT),
            );
        }
    }
    // A URDF's own link "base" (read under another name): what the scene's "base" means.
    if let Some(alias) = spec.base_link.clone() {
        spec.scene.rename_body(ir::BASE, &alias);
    }
    snap::snap(spec, diags);
    apply_scene(spec, diags);
}

/// `[scene]`: point masses and massless bodies replace the bodies' inertial data before
/// lowering (so everything downstream, fixed-joint merging included, sees the scene's model).
pub(super) fn apply_scene(spec: &mut ir::Spec, diags: &mut Diagnostics) {
    codourey(spec, diags);
    let scene = spec.scene.clone();
    let names: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
    let find = |n: &ir::Named, diags: &mut Diagnostics| -> Option<usize> {
        let i = names.iter().position(|b| *b == n.name);
        if i.is_none() {
            let mut d = Diagnostic::error(format!("unknown body {:?}", n.name))
                .with_key(n.key.clone())
                .with_span(n.span.clone());
            if let Some(h) = suggest_hint(&n.name, &names) {
                d = d.with_hint(h);
            }
            diags.push(d);
        }
        i
    };
    let mut point = Vec::new();
    let mut massless = Vec::new();
    for n in &scene.point_mass {
        point.extend(find(n, diags));
    }
    for n in &scene.massless {
        massless.extend(find(n, diags));
    }
    let runtime = resolve_runtime_inertia(spec, &scene, &point, &massless, &find, diags);
    if let Some(p) = &scene.payload
        && let Some(i) = find(&p.body, diags)
    {
        let runtime = scene.runtime_params;
        if !(p.mass.is_finite() && p.mass >= 0.0) {
            diags.push(
                Diagnostic::error(format!(
                    "payload mass {} is not a finite, non-negative number",
                    p.mass
                ))
                .with_key("scene.payload.mass")
                .with_span(p.mass_span.clone()),
            );
        } else {
            // The payload's tensor is judged on its own, at its place (it was only seen summed
            // into the body's, and the warning blamed the body's own, physical, tensor).
            if let Err((msg, hint)) = geom::check_inertia(&p.inertia) {
                diags.push(
                    Diagnostic::warning(format!("payload {msg}"))
                        .with_key("scene.payload.inertia")
                        .with_span(p.inertia_span.clone())
                        .with_hint(format!(
                            "{hint}; the tensor is used as given, but no rigid body has it, and forward dynamics fails where the mass matrix is not positive definite"
                        )),
                );
            }
        }
        if p.mass.is_finite() && p.mass >= 0.0 && !runtime {
            // Run-time parameters keep the payload apart (`scene_params`).
            let b = &mut spec.bodies[i];
            let c = geom::MassProps::combine(&[
                geom::MassProps {
                    mass: b.mass,
                    com: b.com,
                    inertia: b.inertia,
                },
                geom::MassProps {
                    mass: p.mass,
                    com: p.com,
                    inertia: p.inertia,
                },
            ]);
            b.own_inertia.get_or_insert(b.inertia);
            b.mass = c.mass;
            b.com = c.com;
            b.inertia = c.inertia;
        }
    }
    // The scene's armature replaces the joints' own (before any joint is locked).
    for (n, value) in &scene.armature {
        match spec.joints.iter_mut().find(|j| j.name == n.name) {
            Some(j) if matches!(j.kind, ir::Kind::Revolute | ir::Kind::Prismatic) => {
                j.drive.armature = *value;
            }
            Some(j) => diags.push(
                Diagnostic::error(format!("a {} joint has no armature", j.kind.word()))
                    .with_key(n.key.clone())
                    .with_span(n.span.clone())
                    .with_hint("rotor inertia applies to revolute and prismatic joints"),
            ),
            None => diags.push(unknown_joint(n, &spec.joints)),
        }
    }
    // Locked joints become fixed joints placed at their value.
    for (n, value) in &scene.locked {
        let Some(j) = spec.joints.iter_mut().find(|j| j.name == n.name) else {
            diags.push(unknown_joint(n, &spec.joints));
            continue;
        };
        if !matches!(j.kind, ir::Kind::Revolute | ir::Kind::Prismatic) {
            diags.push(
                Diagnostic::error(format!("cannot lock a {} joint", j.kind.word()))
                    .with_key(n.key.clone())
                    .with_span(n.span.clone())
                    .with_hint("only revolute and prismatic joints can be locked"),
            );
            continue;
        }
        let axis = j
            .axes
            .first()
            .map(|a| a.v)
            .filter(|v| geom::norm(v) > 1e-12)
            .map(|v| {
                let l = geom::norm(&v);
                [v[0] / l, v[1] / l, v[2] / l]
            })
            .unwrap_or([0.0, 0.0, 1.0]);
        let motion = if j.kind == ir::Kind::Revolute {
            runtime::model::Transform {
                rotation: runtime::model::axis_angle(&axis, *value),
                translation: [0.0; 3],
            }
        } else {
            geom::trans([axis[0] * value, axis[1] * value, axis[2] * value])
        };
        let (origin, offset) = lower::placement_frames(&j.placement);
        j.placement =
            ir::Placement::Origin(geom::compose(&geom::compose(&origin, &motion), &offset));
        j.kind = ir::Kind::Fixed;
        j.axes.clear();
        j.actuated = false;
    }
    // Run-time inertia: the spec's values are kept apart as the defaults, the constants go.
    for r in &runtime {
        let b = &mut spec.bodies[r.body];
        b.mass = 0.0;
        b.com = [0.0; 3];
        b.inertia = [[0.0; 3]; 3];
    }
    spec.scene.runtime_bodies = runtime;
    for i in point {
        spec.bodies[i].inertia = [[0.0; 3]; 3];
    }
    for i in massless {
        spec.bodies[i].mass = 0.0;
        spec.bodies[i].inertia = [[0.0; 3]; 3];
    }
}

/// Codourey's share of a forearm pair's mass lumped at its elbow (the rest on the platform).
pub(crate) const CODOUREY_SPLIT: f64 = 2.0 / 3.0;

/// `[scene] delta_model = "codourey"` (Codourey 1998, IJRR 17(12)): the simplified Delta, as
/// a change of the bodies before everything else in the scene. For each `[[parallelogram]]`:
/// - its equivalent rod (`<name>_rods`, twice `rod_mass`) becomes massless;
/// - `forearm_split` (default 2/3) of that mass is a point mass at the elbow `E` on the parent
///   (the upper arm), the rest a point mass at the platform frame's origin (the platform only
///   translates, so where on it does not change the dynamics: its rotational inertia and the
///   place of its mass centre never enter);
/// - the parent's own mass becomes a thin uniform rod from the motor axis to `E`: mass centre at
///   `l/2` (the spec's mass centre is *replaced*, so that `m l²/3` about the motor axis is a
///   real rigid body: with the RL5's published 0.2463 m > l/2 = 0.21 m, keeping it would need a
///   negative inertia about the mass centre), inertia `m l²/12` across the rod about it, none
///   along it (`l` the distance of `E` from the motor axis).
///
/// Other bodies (elbow pins, the platform's own mass) stay as written. Errors, at the key: the
/// level without a `[[parallelogram]]` on a translational platform, `forearm_split` without it.
fn codourey(spec: &mut ir::Spec, diags: &mut Diagnostics) {
    let Some(span) = spec.scene.codourey.clone() else {
        if let Some((_, s)) = &spec.scene.forearm_split {
            diags.push(
                Diagnostic::error("`forearm_split` without `delta_model = \"codourey\"`")
                    .with_key("scene.forearm_split")
                    .with_span(s.clone())
                    .with_hint("the split belongs to Codourey's simplified Delta: add delta_model = \"codourey\" to [scene], or remove forearm_split"),
            );
        }
        return;
    };
    let platform = spec
        .platform
        .as_ref()
        .filter(|p| p.coordinates == Some(ir::Coordinates::Translation))
        .and_then(|p| p.body.clone());
    let Some(platform) = platform.filter(|_| !spec.parallelograms.is_empty()) else {
        diags.push(
            Diagnostic::error("`delta_model = \"codourey\"` needs a Delta: [[parallelogram]] legs on a translational platform")
                .with_key("scene.delta_model")
                .with_span(span)
                .with_hint("Codourey's simplified model lumps each parallelogram's rods at its elbow and the platform; this mechanism has none (write [platform] coordinates = \"translation\" and the legs as [[parallelogram]] entries, or remove delta_model)"),
        );
        return;
    };
    let split = spec
        .scene
        .forearm_split
        .as_ref()
        .map_or(CODOUREY_SPLIT, |s| s.0);
    let body = |spec: &ir::Spec, n: &str| spec.bodies.iter().position(|b| b.name == n);
    let mut rods_done: Vec<String> = Vec::new();
    for pg in spec.parallelograms.clone() {
        let elbow = spec.joints.iter().find(|j| j.name == format!("{pg}_elbow"));
        let (Some(rods), Some(elbow), Some(plat)) = (
            body(spec, &format!("{pg}_rods")),
            elbow,
            body(spec, &platform),
        ) else {
            continue; // the expansion failed: already reported
        };
        let arm_name = elbow.parent.clone();
        let (Some(arm), ir::Placement::Origin(at), Some(a)) =
            (body(spec, &arm_name), &elbow.placement, elbow.axes.first())
        else {
            continue;
        };
        let e = at.translation;
        let a = a.v;
        let Some(motor) = spec.joints.iter().find(|j| j.child == arm_name) else {
            continue;
        };
        // A point of the motor axis in the arm's frame: the joint frame's origin, seen from the
        // child frame (`offset⁻¹ · 0`).
        let (_, offset) = lower::placement_frames(&motor.placement);
        let (r, t) = (offset.rotation, offset.translation);
        let o: runtime::model::Vec3 =
            std::array::from_fn(|i| -(0..3).map(|k| r[k][i] * t[k]).sum::<f64>());
        let eo = [e[0] - o[0], e[1] - o[1], e[2] - o[2]];
        let along = eo[0] * a[0] + eo[1] * a[1] + eo[2] * a[2];
        let foot = [
            o[0] + along * a[0],
            o[1] + along * a[1],
            o[2] + along * a[2],
        ];
        let rod = [e[0] - foot[0], e[1] - foot[1], e[2] - foot[2]];
        let l = geom::norm(&rod);
        let m_rods = spec.bodies[rods].mass;
        let point = |mass: f64, com: runtime::model::Vec3| geom::MassProps {
            mass,
            com,
            inertia: [[0.0; 3]; 3],
        };
        // The upper arm: a thin rod (once per arm) plus the elbow's share.
        let b = &spec.bodies[arm];
        let mut arm_props = geom::MassProps {
            mass: b.mass,
            com: b.com,
            inertia: b.inertia,
        };
        if !rods_done.contains(&arm_name) && l > 0.0 {
            let d = rod.map(|x| x / l);
            let k = b.mass * l * l / 12.0;
            arm_props = geom::MassProps {
                mass: b.mass,
                com: std::array::from_fn(|i| 0.5 * (foot[i] + e[i])),
                inertia: std::array::from_fn(|r| {
                    std::array::from_fn(|c| k * (f64::from(u8::from(r == c)) - d[r] * d[c]))
                }),
            };
            rods_done.push(arm_name.clone());
        }
        let arm_props = geom::MassProps::combine(&[arm_props, point(split * m_rods, e)]);
        let b = &mut spec.bodies[arm];
        (b.mass, b.com, b.inertia) = (arm_props.mass, arm_props.com, arm_props.inertia);
        let p = &spec.bodies[plat];
        let p_props = geom::MassProps::combine(&[
            geom::MassProps {
                mass: p.mass,
                com: p.com,
                inertia: p.inertia,
            },
            point((1.0 - split) * m_rods, [0.0; 3]),
        ]);
        let p = &mut spec.bodies[plat];
        (p.mass, p.com, p.inertia) = (p_props.mass, p_props.com, p_props.inertia);
        let r = &mut spec.bodies[rods];
        (r.mass, r.com, r.inertia) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
    }
}

/// `[scene] runtime_inertia`: the bodies whose inertial parameters become run-time
/// parameters, with the spec's values (see [`ir::RuntimeBodySpec`]). `"all"` takes every body
/// with mass or inertia that is neither a point mass nor massless (in a parallel mechanism:
/// the platform and the bodies fixed to it). Errors: the key without `parameters = "runtime"`,
/// unknown names (with a suggestion), a body named twice or also in `point_mass` / `massless`,
/// and a leg body of a parallel mechanism.
pub(super) fn resolve_runtime_inertia(
    spec: &ir::Spec,
    scene: &ir::SceneSpec,
    point: &[usize],
    massless: &[usize],
    find: &dyn Fn(&ir::Named, &mut Diagnostics) -> Option<usize>,
    diags: &mut Diagnostics,
) -> Vec<ir::RuntimeBodySpec> {
    let Some((which, span)) = &scene.runtime_inertia else {
        return Vec::new();
    };
    if !scene.runtime_params {
        diags.push(
            Diagnostic::error("`runtime_inertia` makes bodies' inertial parameters run-time parameters, but the scene's parameters are constants")
                .with_key("scene.runtime_inertia")
                .with_span(span.clone())
                .with_hint("add `parameters = \"runtime\"` to [scene] (the module then takes a `Params` struct), or remove `runtime_inertia`"),
        );
        return Vec::new();
    }
    let on_platform =
        |name: &str| spec.platform.is_none() || parallel::pose_on_platform(spec, name).is_some();
    let mut chosen: Vec<(usize, Option<ir::Named>)> = Vec::new();
    match which {
        ir::RuntimeInertia::All => {
            for (i, b) in spec.bodies.iter().enumerate() {
                let has_mass = b.mass != 0.0 || b.inertia.iter().flatten().any(|x| *x != 0.0);
                if has_mass && !point.contains(&i) && !massless.contains(&i) && on_platform(&b.name)
                {
                    chosen.push((i, None));
                }
            }
        }
        ir::RuntimeInertia::Bodies(names) => {
            for n in names {
                let Some(i) = find(n, diags) else { continue };
                let error = |msg: String, hint: &str| {
                    Diagnostic::error(msg)
                        .with_key(n.key.clone())
                        .with_span(n.span.clone())
                        .with_hint(hint)
                };
                if chosen.iter().any(|(k, _)| *k == i) {
                    diags.push(error(
                        format!("body {:?} is named twice in `runtime_inertia`", n.name),
                        "name each body once",
                    ));
                } else if point.contains(&i) || massless.contains(&i) {
                    let what = if point.contains(&i) {
                        "point_mass"
                    } else {
                        "massless"
                    };
                    diags.push(error(
                        format!("body {:?} is in both `runtime_inertia` and `{what}`", n.name),
                        "a body's inertia is either given at run time or simplified as a constant: remove it from one of the two lists",
                    ));
                } else if !on_platform(&n.name) {
                    diags.push(error(
                        format!("body {:?} is not the platform or fixed to it: leg bodies' inertia is constant; only the platform's can be a run-time parameter", n.name),
                        "name the platform body (or a body fixed to it), or drop this body from `runtime_inertia`; its inertia stays folded into the leg dynamics",
                    ));
                } else {
                    chosen.push((i, Some(n.clone())));
                }
            }
        }
    }
    chosen
        .into_iter()
        .map(|(i, named)| {
            let b = &spec.bodies[i];
            ir::RuntimeBodySpec {
                body: i,
                named,
                mass: b.mass,
                com: b.com,
                inertia: b.inertia,
            }
        })
        .collect()
}

pub(super) fn check_scene_functions(m: &Mechanism, fs: &[ir::Named], diags: &mut Diagnostics) {
    let kind = m.kind();
    let offered = || kind.selectable().iter().chain(kind.always());
    for f in fs {
        let ok = f
            .name
            .parse::<Function>()
            .is_ok_and(|f| offered().any(|&g| g == f));
        if !ok {
            let names: Vec<&str> = offered().map(|f| f.name()).collect();
            let always: Vec<&str> = kind.always().iter().map(|f| f.name()).collect();
            let what = match kind {
                Kind::Tree => "a tree module",
                Kind::Parallel => "a parallel module",
                Kind::Closed => "a closed-loop module",
            };
            let hint = if always.is_empty() {
                format!("{what} offers {}", names.join(", "))
            } else {
                format!(
                    "{what} offers {} ({} are always emitted)",
                    names.join(", "),
                    always.join(" and ")
                )
            };
            diags.push(
                Diagnostic::error(format!("cannot select function {:?}", f.name))
                    .with_key(f.key.clone())
                    .with_span(f.span.clone())
                    .with_hint(hint),
            );
        }
    }
}

/// The spec's body names in file order (TOML only; `None` when it cannot be read). For tools
/// that write `[scene]` tables (`codegen reduce`).
pub fn body_names(file_name: &str, source: &str) -> Option<Vec<String>> {
    if is_urdf(file_name) {
        return None;
    }
    let mut d = Diagnostics::new(file_name, source);
    let spec = read_toml::read(source, &mut d)?;
    Some(spec.bodies.into_iter().map(|b| b.name).collect())
}

/// The run-time parameters of a spec with `[scene] parameters = "runtime"` ([`Scene::params`];
/// `None` without).
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeParams {
    /// The payload: the model body it rides on, its mass (kg), mass centre (m) and inertia about
    /// the mass centre (kg·m²), both in that body's frame. For a parallel mechanism the body is
    /// the platform (index 0) and the values are in the platform frame; for closed loops it is
    /// the body of the spanning tree.
    pub payload: Option<(usize, f64, runtime::model::Vec3, runtime::model::Mat3)>,
    /// The speed scale `v_s` of the regularized Coulomb law (`[scene] coulomb_velocity`).
    pub coulomb_velocity: f64,
    /// Parallel mechanisms (leg joints) and closed loops (tree joints): the joints' viscous and
    /// Coulomb friction are run-time parameters (the scene's `friction` is on). Trees take every
    /// drive at run time.
    pub leg_friction: bool,
    /// Parallel mechanisms and closed loops: the joints' rotor inertias are run-time parameters
    /// (the scene's `rotor_inertia` is on).
    pub leg_rotor_inertia: bool,
    /// `[scene] runtime_inertia`: the bodies whose inertial parameters are run-time parameters,
    /// in the order of the list (`"all"`: the spec's body order), bodies fixed to the base left
    /// out. Their constants are zero in the model.
    pub bodies: Vec<RuntimeBody>,
}

/// A body whose inertial parameters are run-time parameters (`[scene] runtime_inertia`): it
/// enters the dynamics exactly as a run-time payload on the model body it is part of.
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeBody {
    /// The spec body's name (the generated `RUNTIME_BODY_NAMES`).
    pub name: String,
    /// The model body it is rigidly part of (after fixed-joint merging; for a parallel
    /// mechanism 0, the platform; for closed loops a body of the spanning tree).
    pub body: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Mass centre in the model body's frame (m).
    pub com: runtime::model::Vec3,
    /// Inertia about the mass centre, model body's axes (kg·m²).
    pub inertia: runtime::model::Mat3,
}

impl RuntimeBody {
    /// The spec's values of `r` placed on model body `body` at `pose` (the spec body's frame in
    /// the model body's frame).
    fn placed(
        spec: &ir::Spec,
        r: &ir::RuntimeBodySpec,
        body: usize,
        pose: &runtime::model::Transform,
    ) -> RuntimeBody {
        let m = geom::MassProps {
            mass: r.mass,
            com: r.com,
            inertia: r.inertia,
        }
        .transformed(pose);
        RuntimeBody {
            name: spec.bodies[r.body].name.clone(),
            body,
            mass: m.mass,
            com: m.com,
            inertia: m.inertia,
        }
    }
}

/// The run-time parameters of a prepared spec (see [`RuntimeParams`]), placed by `attach`
/// (where each spec body went in the tree of a tree or closed-loop mechanism; `None` for a
/// parallel one, whose payload rides on the platform).
pub(super) fn runtime_params(
    spec: &ir::Spec,
    attach: Option<&[Option<lower::Attach>]>,
) -> Option<RuntimeParams> {
    if !spec.scene.runtime_params {
        return None;
    }
    // Parallel mechanisms and closed loops: the payload (if any) placed on its model body, and
    // the drives the scene models.
    let placed = |spec: &ir::Spec, body: usize, pose: &runtime::model::Transform| {
        let p = spec.scene.payload.as_ref()?;
        let m = geom::MassProps {
            mass: p.mass,
            com: p.com,
            inertia: p.inertia,
        }
        .transformed(pose);
        Some((body, m.mass, m.com, m.inertia))
    };
    let with_drives =
        |spec: &ir::Spec,
         payload: Option<(usize, f64, runtime::model::Vec3, runtime::model::Mat3)>,
         bodies: Vec<RuntimeBody>| {
            let (friction, rotor) = (spec.scene.friction, spec.scene.rotor_inertia);
            (payload.is_some() || friction || rotor || !bodies.is_empty()).then_some(
                RuntimeParams {
                    payload,
                    coulomb_velocity: spec.scene.coulomb_velocity,
                    leg_friction: friction,
                    leg_rotor_inertia: rotor,
                    bodies,
                },
            )
        };
    // The run-time bodies placed by `attach` (closed loops, trees): on the model body each
    // spec body is part of; those fixed to the base move with nothing and are left out.
    let attached = |spec: &ir::Spec, attach: &[Option<lower::Attach>]| -> Vec<RuntimeBody> {
        spec.scene
            .runtime_bodies
            .iter()
            .filter_map(|r| {
                let at = attach[r.body]?;
                Some(RuntimeBody::placed(spec, r, at.target?, &at.pose))
            })
            .collect()
    };
    let Some(attach) = attach else {
        let payload = match spec.scene.payload.as_ref() {
            None => None,
            Some(p) => placed(spec, 0, &parallel::pose_on_platform(spec, &p.body.name)?),
        };
        let bodies = spec
            .scene
            .runtime_bodies
            .iter()
            .filter_map(|r| {
                let pose = parallel::pose_on_platform(spec, &spec.bodies[r.body].name)?;
                Some(RuntimeBody::placed(spec, r, 0, &pose))
            })
            .collect();
        return with_drives(spec, payload, bodies);
    };
    if closed::is_closed(spec) {
        // A payload on a body fixed to the base moves with nothing: it is left out.
        let payload = spec.scene.payload.as_ref().and_then(|p| {
            let b = spec.bodies.iter().position(|b| b.name == p.body.name)?;
            let at = attach[b]?;
            placed(spec, at.target?, &at.pose)
        });
        let bodies = attached(spec, attach);
        return with_drives(spec, payload, bodies);
    }
    let payload = spec.scene.payload.as_ref().and_then(|p| {
        let b = spec.bodies.iter().position(|b| b.name == p.body.name)?;
        let at = attach[b]?;
        let target = at.target?;
        let m = geom::MassProps {
            mass: p.mass,
            com: p.com,
            inertia: p.inertia,
        }
        .transformed(&at.pose);
        Some((target, m.mass, m.com, m.inertia))
    });
    Some(RuntimeParams {
        payload,
        coulomb_velocity: spec.scene.coulomb_velocity,
        leg_friction: false,
        leg_rotor_inertia: false,
        bodies: attached(spec, attach),
    })
}

//! The format-neutral spec: what the TOML and URDF readers produce and [`super::lower`] turns
//! into a [`runtime::model::Model`]. Values are already numbers (angles parsed, units SI);
//! every entry keeps its key path and source span for diagnostics.

use std::ops::Range;

use runtime::model::{Mat3, Transform, Vec3};

/// Byte range in the source.
pub(crate) type Span = Option<Range<usize>>;

/// A parsed, not yet validated mechanism.
#[derive(Clone, Debug)]
pub(crate) struct Spec {
    pub name: String,
    pub gravity: Vec3,
    pub bodies: Vec<BodySpec>,
    /// In the order in which they are to be numbered when already topological.
    pub joints: Vec<JointSpec>,
    /// Where to point whole-file diagnostics (e.g. "no movable joints").
    pub anchor: Span,
    /// Some joint could not be read far enough to know its parent or child (already reported):
    /// don't report bodies as unattached, that would only echo the first error.
    pub joints_incomplete: bool,
    /// The `[platform]` table: present for a parallel mechanism (TOML only).
    pub platform: Option<PlatformSpec>,
    /// The `[scene]` table: what the application needs (TOML only).
    pub scene: SceneSpec,
    /// `[[spring]]` force elements (TOML only; closed loops in joint coordinates).
    pub springs: Vec<SpringSpec>,
    /// `[[parallelogram]]` elements (TOML only; translational platforms), already expanded
    /// into `bodies` and `joints` (their equivalent rod, a U at the elbow and an S at the
    /// platform); their names, for the mobility count.
    pub parallelograms: Vec<String>,
    /// Each `[[parallelogram]]`'s short-side width (m), in the order of `parallelograms`: the
    /// declared-motion check places its two rods.
    pub parallelogram_widths: Vec<f64>,
    /// A URDF link named `"base"` that is not the root, under the name the spec reads it by
    /// (`"base"` names the fixed world): the body a scene's `"base"` means (URDF only).
    pub base_link: Option<String>,
    /// A URDF's root link: the fixed world, which a scene's frame may name (URDF only).
    pub root_link: Option<String>,
}

/// A `[[spring]]` entry: a linear spring-damper between a point of `body_a` and one of
/// `body_b` (body frames; `"base"` allowed).
#[derive(Clone, Debug)]
pub(crate) struct SpringSpec {
    pub name: String,
    pub key: String,
    pub span: Span,
    pub body_a: Named,
    pub point_a: Vec3,
    pub body_b: Named,
    pub point_b: Vec3,
    pub stiffness: f64,
    pub rest_length: f64,
    pub damping: f64,
}

/// A name written in the `[scene]` table, with where.
#[derive(Clone, Debug)]
pub(crate) struct Named {
    pub name: String,
    pub key: String,
    pub span: Span,
}

/// The `[scene]` table: model no more than the application needs.
#[derive(Clone, Debug)]
pub(crate) struct SceneSpec {
    /// Emit only these public functions (trees).
    pub functions: Option<Vec<Named>>,
    /// `frames = ["tool", …]`: the bodies whose kinematics the module offers (see
    /// `spec::frames`), with the span of the value; `None`: the default (the leaves).
    pub frames: Option<(Vec<Named>, Span)>,
    /// Bodies modelled as point masses at their mass centres (no rotational inertia).
    pub point_mass: Vec<Named>,
    /// Bodies modelled as massless (no mass, no inertia).
    pub massless: Vec<Named>,
    /// A payload rigidly added to a body.
    pub payload: Option<Payload>,
    /// Joints locked at a value (rad or m): they become fixed joints, their bodies merge.
    pub locked: Vec<(Named, f64)>,
    /// `friction = true`: apply the joints' `damping` (viscous) and `friction` (Coulomb).
    pub friction: bool,
    /// `rotor_inertia = true`: apply the joints' `armature` (reflected rotor inertia).
    pub rotor_inertia: bool,
    /// `armature = { joint = value, … }`: the joints' reflected rotor inertia (kg·m² or kg),
    /// replacing what the joint writes (a URDF has no place for it).
    pub armature: Vec<(Named, f64)>,
    /// `coulomb_velocity`: the speed scale `v_s` of the regularized Coulomb law (rad/s or m/s).
    pub coulomb_velocity: f64,
    /// `snap = TOL`: take near-exact angles and offsets as exact (see `spec::snap`).
    pub snap: Option<f64>,
    /// `parameters = "runtime"`: payload and drive coefficients in a generated `Params` struct
    /// passed at run time (trees), instead of constants folded into the code.
    pub runtime_params: bool,
    /// Span of the `parameters` value.
    pub runtime_params_span: Span,
    /// `runtime_inertia = ["body", …]` or `"all"`: these bodies' inertial parameters become
    /// run-time parameters (with `parameters = "runtime"` only); with the span of the value.
    pub runtime_inertia: Option<(RuntimeInertia, Span)>,
    /// The bodies `runtime_inertia` resolved to, with their inertial data as the spec gives it
    /// (filled by `apply_scene`, which then zeroes those bodies' constants).
    pub runtime_bodies: Vec<RuntimeBodySpec>,
    /// `delta_model = "codourey"`: Codourey's simplified Delta (see `scene::codourey`); the
    /// span of the value.
    pub codourey: Option<Span>,
    /// `forearm_split`: the fraction of each forearm pair's mass lumped at the elbow (the rest
    /// on the platform), in [0, 1]; with the span of the value. Default 2/3.
    pub forearm_split: Option<(f64, Span)>,
    /// The span of the `[scene]` header, when the spec writes one.
    pub written: Span,
}

impl SceneSpec {
    /// Moves every span by `by` bytes (a sidecar's spans past the spec's text, so that the
    /// diagnostics about them can be told apart and moved to the sidecar's file).
    pub fn shift(&mut self, by: usize) {
        let s = |span: &mut Span| {
            if let Some(r) = span {
                *r = r.start + by..r.end + by;
            }
        };
        let n = |named: &mut Named| {
            if let Some(r) = &mut named.span {
                *r = r.start + by..r.end + by;
            }
        };
        self.functions.iter_mut().flatten().for_each(n);
        if let Some((f, span)) = &mut self.frames {
            f.iter_mut().for_each(n);
            s(span);
        }
        self.point_mass.iter_mut().for_each(n);
        self.massless.iter_mut().for_each(n);
        if let Some(p) = &mut self.payload {
            n(&mut p.body);
            s(&mut p.mass_span);
            s(&mut p.inertia_span);
        }
        self.locked.iter_mut().for_each(|(named, _)| n(named));
        self.armature.iter_mut().for_each(|(named, _)| n(named));
        s(&mut self.runtime_params_span);
        if let Some((r, span)) = &mut self.runtime_inertia {
            s(span);
            if let RuntimeInertia::Bodies(b) = r {
                b.iter_mut().for_each(n);
            }
        }
        if let Some(span) = &mut self.codourey {
            s(span);
        }
        if let Some((_, span)) = &mut self.forearm_split {
            s(span);
        }
        s(&mut self.written);
    }

    /// Every body this scene names `from` (point masses, massless bodies, the payload's body,
    /// run-time inertia, frames) renamed `to`.
    pub fn rename_body(&mut self, from: &str, to: &str) {
        let n = |named: &mut Named| {
            if named.name == from {
                named.name = to.to_owned();
            }
        };
        if let Some((f, _)) = &mut self.frames {
            f.iter_mut().for_each(n);
        }
        self.point_mass.iter_mut().for_each(n);
        self.massless.iter_mut().for_each(n);
        if let Some(p) = &mut self.payload {
            n(&mut p.body);
        }
        if let Some((RuntimeInertia::Bodies(b), _)) = &mut self.runtime_inertia {
            b.iter_mut().for_each(n);
        }
    }
}

/// The value of `[scene] runtime_inertia`.
#[derive(Clone, Debug)]
pub(crate) enum RuntimeInertia {
    /// `"all"`: every body with mass or inertia that can take part (see `apply_scene`).
    All,
    /// The bodies named.
    Bodies(Vec<Named>),
}

/// A body whose inertial parameters are run-time parameters: its index in `Spec::bodies`, the
/// name as written (`None` when `"all"` picked it), and its mass (kg), mass centre (m) and
/// inertia about the mass centre (kg·m²) in its own frame, as the spec gives them.
#[derive(Clone, Debug)]
pub(crate) struct RuntimeBodySpec {
    pub body: usize,
    pub named: Option<Named>,
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
}

/// The default `v_s` of the regularized Coulomb law (rad/s or m/s): 99.5 % of the Coulomb
/// level at 1e-3, the resolution of a typical joint speed estimate.
pub(crate) const COULOMB_VELOCITY: f64 = 1e-4;

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            functions: None,
            frames: None,
            point_mass: Vec::new(),
            massless: Vec::new(),
            payload: None,
            locked: Vec::new(),
            friction: false,
            rotor_inertia: false,
            armature: Vec::new(),
            coulomb_velocity: COULOMB_VELOCITY,
            snap: None,
            runtime_params: false,
            runtime_params_span: None,
            runtime_inertia: None,
            runtime_bodies: Vec::new(),
            codourey: None,
            forearm_split: None,
            written: None,
        }
    }
}

impl SceneSpec {
    /// The drive a joint gets in this scene: its written values, each effect only when the
    /// scene turns it on (off by default).
    pub fn drive(&self, d: &DriveSpec) -> runtime::model::Drive {
        runtime::model::Drive {
            viscous: if self.friction { d.damping } else { 0.0 },
            coulomb: if self.friction { d.friction } else { 0.0 },
            coulomb_velocity: if self.friction && d.friction != 0.0 {
                self.coulomb_velocity
            } else {
                0.0
            },
            armature: if self.rotor_inertia { d.armature } else { 0.0 },
        }
    }
}

/// A joint's drive as written (`damping`, `friction`, `armature`; URDF `<dynamics>`), SI.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct DriveSpec {
    /// Viscous coefficient (N·m·s/rad or N·s/m).
    pub damping: f64,
    /// Coulomb level (N·m or N).
    pub friction: f64,
    /// Reflected rotor inertia (kg·m² or kg).
    pub armature: f64,
}

/// `[scene] payload = { body, mass, com, inertia }`: inertial data in the body's frame.
#[derive(Clone, Debug)]
pub(crate) struct Payload {
    pub body: Named,
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
    /// Where `mass` and `inertia` are written (the body's name when absent).
    pub mass_span: Span,
    pub inertia_span: Span,
}

/// How a parallel mechanism's platform moves (`platform.coordinates`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Coordinates {
    /// Six DOF: position and orientation.
    Pose,
    /// Three DOF: orientation about a fixed centre (a spherical mechanism).
    Orientation,
    /// Two DOF: a point moving in a plane `z = const` (a planar five-bar).
    Planar,
    /// Three DOF: the platform's position, its orientation fixed (a Delta robot).
    Translation,
    /// Three DOF: the platform moves in a plane `z = const` and turns about its normal
    /// (`x = [px, py, φ]`; a planar 3-RRR, 3-PRR, 3-RPR).
    PlanarPose,
    /// Three DOF with parasitic motion (1T2R): heave and two tilts, `x = [pz, α, β]`; the
    /// parasitic `(px, py, γ)` follow from the legs (a 3-PRS or 3-RPS head).
    HeaveTilt,
    /// Four DOF, the Schönflies motions: a translating carrier `[px, py, pz]` and a tool that
    /// turns on it about `z` by `θ` (a 4-axis Delta with a telescopic R-U-P-U shaft).
    Schoenflies,
}

/// The `[platform]` table of a parallel mechanism. Entries that could not be read are `None`
/// (the error is already reported).
#[derive(Clone, Debug)]
pub(crate) struct PlatformSpec {
    /// Span of the `platform` key of the `[platform]` header (whole-platform diagnostics).
    pub span: Span,
    /// The moving platform: a body name.
    pub body: Option<String>,
    pub body_span: Span,
    pub coordinates: Option<Coordinates>,
    pub coordinates_span: Span,
    /// The platform frame's pose in the base frame at home (identity by default).
    pub home: Transform,
    pub home_span: Span,
    /// Orientation platforms: the fixed centre (base frame, m), if written.
    pub centre: Option<Vec3>,
    pub centre_span: Span,
}

/// A rigid body, inertial data in its user frame `F`.
#[derive(Clone, Debug)]
pub(crate) struct BodySpec {
    pub name: String,
    /// Key path, e.g. `body "link2"`.
    pub key: String,
    /// Span of the body's name (or its element).
    pub span: Span,
    pub mass: f64,
    pub mass_span: Span,
    /// Mass centre in `F` (m).
    pub com: Vec3,
    /// Inertia about the mass centre in `F`'s axes (kg·m²), symmetric.
    pub inertia: Mat3,
    pub inertia_span: Span,
    /// The body's own inertia about its own mass centre, in `F`'s axes, when a `[scene]`
    /// payload has been added to `inertia` (which then holds the sum); the physical checks
    /// judge the body by this and the payload by its own tensor, each at its own place.
    pub own_inertia: Option<Mat3>,
    /// The pose of the body's own frame (the one the spec writes it in, the frame
    /// `[scene] frames` names) in `F`: the identity, except after a child-side joint frame
    /// (`child_origin` on a tree joint) has re-expressed the body in its joint frame
    /// (`child_frame.rs`).
    pub own_frame: Transform,
}

/// Joint kinds of the spec.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Revolute,
    Prismatic,
    Universal,
    Spherical,
    Fixed,
}

impl Kind {
    /// The joint coordinates a joint of this kind adds: 1 for revolute and prismatic, 2 for
    /// universal, 3 for spherical, 0 for fixed.
    pub fn coordinates(self) -> usize {
        match self {
            Kind::Revolute | Kind::Prismatic => 1,
            Kind::Universal => 2,
            Kind::Spherical => 3,
            Kind::Fixed => 0,
        }
    }

    pub fn word(self) -> &'static str {
        match self {
            Kind::Revolute => "revolute",
            Kind::Prismatic => "prismatic",
            Kind::Universal => "universal",
            Kind::Spherical => "spherical",
            Kind::Fixed => "fixed",
        }
    }
}

/// Denavit–Hartenberg parameters (m, rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Dh {
    pub a: f64,
    pub alpha: f64,
    pub d: f64,
    pub theta: f64,
}

/// Where the joint frame is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Placement {
    /// Pose of the joint frame in the parent body's user frame.
    Origin(Transform),
    /// Standard (distal) DH; the child's user frame is the distal DH frame.
    Dh(Dh),
    /// Modified (proximal, Craig) DH.
    Mdh(Dh),
}

/// An axis as written, with where it was written.
#[derive(Clone, Debug)]
pub(crate) struct AxisSpec {
    pub v: Vec3,
    pub key: String,
    pub span: Span,
}

/// A joint between two named bodies (`"base"` is the fixed world).
#[derive(Clone, Debug)]
pub(crate) struct JointSpec {
    pub name: String,
    /// Key path, e.g. `joint "j2"`.
    pub key: String,
    /// Span of the joint's name (or its element).
    pub span: Span,
    pub kind: Kind,
    /// Span of the `kind` value (or of the joint's element).
    pub kind_span: Span,
    pub parent: String,
    pub parent_span: Span,
    pub child: String,
    pub child_span: Span,
    pub placement: Placement,
    /// R/P: one axis; U: two; S and fixed: none (S uses x, y, z). Empty means the default.
    pub axes: Vec<AxisSpec>,
    /// Parallel mechanisms: `actuated = true`, with the span of the `actuated` key.
    pub actuated: bool,
    pub actuated_span: Span,
    /// Parallel mechanisms, joints into the platform: the joint frame in the platform frame.
    pub child_origin: Option<Transform>,
    /// Span of the `child_origin` key, when written.
    pub child_origin_span: Span,
    /// `home`: the joint's coordinate at home (rad or m), so that generated functions take and
    /// return absolute coordinates; 0 by default (docs/spec.md, "Coordinates at home").
    pub home: f64,
    /// Span of the `home` value, when written.
    pub home_span: Span,
    /// Friction and rotor inertia as written (applied only when `[scene]` says so).
    pub drive: DriveSpec,
    /// A universal joint's `cross`: the inertial data of its body `<name>_cross`, in that body's
    /// frame (the joint frame carried by the first rotation); `None`: massless
    /// (docs/spec.md, "Joint kinds").
    pub cross: Option<BodySpec>,
    /// `limit` (TOML) or `<limit>` (URDF): the joint's range and speed bound, carried beside
    /// the model for the CLI tools (`excite`), never part of the dynamics.
    pub limit: Option<LimitSpec>,
}

/// A joint's limits as written (rad or m, rad/s or m/s), with where.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LimitSpec {
    /// Lower bound of the coordinate, `< upper`.
    pub lower: f64,
    /// Upper bound of the coordinate.
    pub upper: f64,
    /// Bound on the speed `|q̇|`, `> 0`, when given.
    pub velocity: Option<f64>,
    /// Span of the limit (the TOML value or the URDF `<limit>` element).
    pub span: Span,
}

/// The name of the fixed world in `parent`.
pub(crate) const BASE: &str = "base";

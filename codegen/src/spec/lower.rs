//! Validation and lowering of a [`Spec`] to a [`Model`]: value checks, name resolution,
//! topology (every body the child of exactly one joint, no cycles), stable topological order,
//! fixed-joint merging, U/S expansion and the DH frame bookkeeping.

use std::collections::HashMap;

use runtime::model::{Body, Joint, JointKind, Model, Transform, Vec3};

use super::geom::{self, MassProps, compose};
use super::ir::{BASE, BodySpec, JointSpec, Kind, Placement, Span, Spec};
use super::suggest_hint;
use crate::diag::{Diagnostic, Diagnostics};

/// Validates `spec` (a tree: no `[platform]`) and builds the model, with the bookkeeping:
/// where every spec body ended up. Errors and warnings go to `diags`; `None` when there was
/// any error.
pub(super) fn lower_built(spec: &Spec, diags: &mut Diagnostics) -> Option<Built> {
    let axes = check_values(spec, diags);
    check_no_parallel_keys(spec, diags);
    let topo = check_topology(spec, diags, &Skip::none(spec));
    if diags.has_errors() {
        return None;
    }
    let topo = topo?;
    let built = build(spec, &topo, &axes, diags);
    check_runtime_bodies(spec, &built.attach, diags);
    let massive = check_massless_subtrees(spec, &built, diags);
    check_inertia_about_axes(spec, &built, &massive, diags);
    if diags.has_errors() {
        None
    } else {
        Some(built)
    }
}

/// A movable joint that moves only massless bodies (no mass and no inertia anywhere beyond it)
/// has a zero row and column in the mass matrix at every configuration: `forward_dynamics`
/// always returns `Err(Singular)`. A warning, not an error: inverse dynamics and gravity are
/// still right, and URDFs often have such links (no `<inertial>`). Once per spec joint. Returns
/// per model joint whether it moves a mass or an inertia.
fn check_massless_subtrees(spec: &Spec, built: &Built, diags: &mut Diagnostics) -> Vec<bool> {
    let m = &built.model;
    let mut massive: Vec<bool> = m
        .bodies
        .iter()
        .map(|b| b.mass != 0.0 || b.inertia.iter().flatten().any(|x| *x != 0.0))
        .collect();
    // Bodies with run-time inertia have zero constants but a mass at run time.
    for r in &spec.scene.runtime_bodies {
        if let Some(t) = built.attach[r.body].and_then(|a| a.target) {
            massive[t] = true;
        }
    }
    // Parents come before children: accumulate from the tips.
    for i in (0..m.joints.len()).rev() {
        if massive[i]
            && let Some(p) = m.joints[i].parent
        {
            massive[p] = true;
        }
    }
    let flagged: Vec<bool> = massive.iter().map(|m| !m).collect();
    warn_joints(
        spec,
        built,
        &flagged,
        "moves only massless bodies",
        "its row of the mass matrix is zero at every configuration, so forward_dynamics will always return Err(Singular); give a body beyond it a mass or an inertia, or make the joint fixed",
        diags,
    );
    massive
}

/// A warning `joint "<name>" <what>` with `hint` at each spec joint one of whose model joints
/// is `flagged` (once per spec joint: a U or S expands into several).
fn warn_joints(
    spec: &Spec,
    built: &Built,
    flagged: &[bool],
    what: &str,
    hint: &str,
    diags: &mut Diagnostics,
) {
    let mut reported = Vec::new();
    for (i, _) in flagged.iter().enumerate().filter(|(_, f)| **f) {
        let sj = built.spec_joint[i];
        if reported.contains(&sj) {
            continue;
        }
        reported.push(sj);
        let j = &spec.joints[sj];
        diags.push(
            Diagnostic::warning(format!("joint \"{}\" {what}", j.name))
                .with_key(j.key.clone())
                .with_span(j.span.clone())
                .with_hint(hint),
        );
    }
}

/// A revolute joint that moves mass, but none of it off its axis and no inertia about it (a
/// point mass on the axis, a rod along it without its axial moment) has a zero diagonal entry
/// in the mass matrix, `sᵀ I_c s = 0` with `I_c` the composite inertia beyond it: at every
/// configuration when nothing beyond it moves the mass off the axis. Tested on the inertia
/// matrix (the runtime's CRBA, rotor inertia on the diagonal) at the home pose and four fixed
/// configurations spread over the joint ranges; a warning when the entry is zero at all five
/// (to 1e-13 of the largest diagonal entry), as for a massless joint. Once per spec joint, not
/// with run-time parameters (their constants stand in for values given at run time).
fn check_inertia_about_axes(spec: &Spec, built: &Built, massive: &[bool], diags: &mut Diagnostics) {
    let m = &built.model;
    let n = m.dof();
    if spec.scene.runtime_params || n == 0 {
        return;
    }
    let mut zero = vec![true; n];
    for k in 0..5 {
        // Home (k = 0), then fixed, incommensurate angles (rad) and offsets (m).
        let q: Vec<f64> = (0..n)
            .map(|j| {
                let x = (1.7 * j as f64 + 2.3 * k as f64).sin();
                let scale = match m.joints[j].kind {
                    JointKind::Revolute => 2.5,
                    JointKind::Prismatic => 0.3,
                };
                if k == 0 { 0.0 } else { scale * x }
            })
            .collect();
        let h = runtime::rnea::mass_matrix(m, &q);
        let diag: Vec<f64> = (0..n)
            .map(|i| h[(i, i)] + m.joints[i].drive.armature)
            .collect();
        let largest = diag.iter().fold(0.0f64, |a, d| a.max(d.abs()));
        for i in 0..n {
            if diag[i].abs() > 1e-13 * largest {
                zero[i] = false;
            }
        }
    }
    let flagged: Vec<bool> = (0..n).map(|i| zero[i] && massive[i]).collect();
    warn_joints(
        spec,
        built,
        &flagged,
        "moves no inertia about its axis",
        "the mass beyond it lies on its axis and has no moment about it (a point mass on the axis, or a body without its axial moment), so its row of the mass matrix is zero and forward_dynamics will always return Err(Singular); give a body beyond it an inertia about the axis or move its mass centre off the axis, or make the joint fixed",
        diags,
    );
}

/// A body named in `[scene] runtime_inertia` must move: one fixed to the base (directly or
/// through fixed joints) never enters the dynamics, so its parameters would do nothing.
pub(super) fn check_runtime_bodies(
    spec: &Spec,
    attach: &[Option<Attach>],
    diags: &mut Diagnostics,
) {
    for r in &spec.scene.runtime_bodies {
        if let (Some(n), Some(Attach { target: None, .. })) = (&r.named, attach[r.body]) {
            diags.push(
                Diagnostic::error(format!(
                    "body {:?} is fixed to the base: its inertia never enters the dynamics",
                    n.name
                ))
                .with_key(n.key.clone())
                .with_span(n.span.clone())
                .with_hint("name only bodies that a joint moves; `\"all\"` leaves out the bodies fixed to the base"),
            );
        }
    }
}

/// `actuated` belongs to parallel mechanisms and closed loops (never to a tree), and so does a
/// `child_origin` that closes a loop.
fn check_no_parallel_keys(spec: &Spec, diags: &mut Diagnostics) {
    for j in &spec.joints {
        if j.actuated {
            diags.push(
                Diagnostic::error("`actuated` is only for parallel mechanisms and closed loops")
                    .with_key(format!("{}.actuated", j.key))
                    .with_span(j.actuated_span.clone().or(j.span.clone()))
                    .with_hint("this spec has no [platform] table and no loop-closing joint (one with `child_origin` whose child another joint also reaches), so it is a tree, in which every joint is actuated; remove `actuated`, or close the loop (docs/spec.md, \"Closed loops in joint coordinates\") or add a [platform] table"),
            );
        }
        if j.child_origin.is_some() {
            diags.push(
                Diagnostic::error("`child_origin` is only for joints into the platform of a parallel mechanism")
                    .with_key(format!("{}.child_origin", j.key))
                    .with_span(j.child_origin_span.clone().or(j.span.clone()))
                    .with_hint("this spec has no [platform] table, so it is a tree; remove `child_origin` (the child's frame is the joint frame)"),
            );
        }
    }
}

/// Joint axes after validation: per joint, the unit axes of its revolutes/prismatic.
pub(super) type Axes = Vec<Vec<Vec3>>;

/// Joints and bodies that the tree checks and the tree lowering leave out (a parallel
/// mechanism's joints into the platform, and the platform with what is fixed to it).
pub(super) struct Skip {
    pub joint: Vec<bool>,
    pub body: Vec<bool>,
}

impl Skip {
    /// Nothing skipped (a tree).
    pub(super) fn none(spec: &Spec) -> Skip {
        Skip {
            joint: vec![false; spec.joints.len()],
            body: vec![false; spec.bodies.len()],
        }
    }
}

/// Finite values, masses, inertias, axes. Returns the normalized axes per joint.
pub(super) fn check_values(spec: &Spec, diags: &mut Diagnostics) -> Axes {
    for (k, g) in spec.gravity.iter().enumerate() {
        if !g.is_finite() {
            diags.push(
                Diagnostic::error("gravity is not finite")
                    .with_key(format!("mechanism.gravity[{k}]"))
                    .with_span(spec.anchor.clone()),
            );
        }
    }
    // A universal joint's cross is checked as a body is (docs/spec.md, "Joint kinds").
    for b in spec
        .bodies
        .iter()
        .chain(spec.joints.iter().filter_map(|j| j.cross.as_ref()))
    {
        check_body(b, diags);
    }
    spec.joints.iter().map(|j| joint_axes(j, diags)).collect()
}

fn check_body(b: &BodySpec, diags: &mut Diagnostics) {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    if !b.mass.is_finite() {
        diags.push(
            Diagnostic::error("mass is not finite")
                .with_key(format!("{}.mass", b.key))
                .with_span(b.mass_span.clone()),
        );
    } else if b.mass < 0.0 {
        diags.push(
            Diagnostic::error(format!("negative mass {}", b.mass))
                .with_key(format!("{}.mass", b.key))
                .with_span(b.mass_span.clone())
                .with_hint("a mass is in kg and must be >= 0 (0 for a massless body)"),
        );
    }
    if !finite(&b.com) {
        diags.push(
            Diagnostic::error("mass centre is not finite")
                .with_key(format!("{}.com", b.key))
                .with_span(b.span.clone()),
        );
    }
    if !b.inertia.iter().all(|r| finite(r)) {
        diags.push(
            Diagnostic::error("inertia is not finite")
                .with_key(format!("{}.inertia", b.key))
                .with_span(b.inertia_span.clone()),
        );
    } else if let Err((msg, hint)) =
        geom::check_inertia(b.own_inertia.as_ref().unwrap_or(&b.inertia))
    {
        // A warning: published URDFs carry such tensors (Allegro hand, ANYmal, HyQ, PR2,
        // TIAGo), and Pinocchio and RBDL take them as given; so does nocdyn.
        diags.push(
            Diagnostic::warning(msg)
                .with_key(format!("{}.inertia", b.key))
                .with_span(b.inertia_span.clone())
                .with_hint(format!(
                    "{hint}; the tensor is used as given (as Pinocchio does), but no rigid body has it, and forward dynamics fails where the mass matrix is not positive definite"
                )),
        );
    }
}

/// Validates and normalizes the axes of `j` (zero → error, non-unit → warning).
fn joint_axes(j: &JointSpec, diags: &mut Diagnostics) -> Vec<Vec3> {
    let mut out = Vec::new();
    for a in &j.axes {
        let n = geom::norm(&a.v);
        if !a.v.iter().all(|x| x.is_finite()) {
            diags.push(
                Diagnostic::error("axis is not finite")
                    .with_key(a.key.clone())
                    .with_span(a.span.clone()),
            );
            out.push([0.0, 0.0, 1.0]);
        } else if n < 1e-12 {
            diags.push(
                Diagnostic::error("zero-length axis")
                    .with_key(a.key.clone())
                    .with_span(a.span.clone())
                    .with_hint("an axis is a direction in the joint frame, e.g. [0, 0, 1]"),
            );
            out.push([0.0, 0.0, 1.0]);
        } else if n != 1.0 {
            if (n - 1.0).abs() > 1e-9 {
                diags.push(
                    Diagnostic::warning(format!(
                        "axis is not a unit vector (length {n}); normalized"
                    ))
                    .with_key(a.key.clone())
                    .with_span(a.span.clone()),
                );
            }
            out.push(a.v.map(|x| x / n));
        } else {
            out.push(a.v);
        }
    }
    match j.kind {
        Kind::Revolute | Kind::Prismatic if out.is_empty() => out.push([0.0, 0.0, 1.0]),
        Kind::Universal => {
            if out.is_empty() {
                out = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
            }
            if out.len() == 2 && geom::norm(&geom::cross(&out[0], &out[1])) < 1e-9 {
                let (key, span) = j.axes.first().map_or((j.key.clone(), j.span.clone()), |a| {
                    (a.key.clone(), a.span.clone())
                });
                diags.push(
                    Diagnostic::error("the two axes of a universal joint are parallel")
                        .with_key(key)
                        .with_span(span)
                        .with_hint("a universal joint needs two non-parallel axes, e.g. axes = [[1, 0, 0], [0, 1, 0]]"),
                );
            }
        }
        Kind::Spherical => out = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        _ => {}
    }
    out
}

/// Resolved topology.
pub(super) struct Topo {
    /// Per joint: parent body index (`None` = base) and child body index.
    pub parent: Vec<Option<usize>>,
    pub child: Vec<usize>,
    /// Joints in processing order (parents first, declared order where possible); skipped
    /// joints are left out.
    pub order: Vec<usize>,
}

/// Names, references and the tree structure. Joints and bodies in `skip` are resolved (their
/// names and bodies must exist) but take no part in the tree rules.
pub(super) fn check_topology(spec: &Spec, diags: &mut Diagnostics, skip: &Skip) -> Option<Topo> {
    // Unique names.
    let body_index = unique_body_names(spec, diags);
    check_unique_joint_names(spec, diags);
    super::cross::check_skipped(spec, skip, diags);

    // Resolve parent and child.
    let mut links = Links::new(spec, skip, body_index);
    for (ji, j) in spec.joints.iter().enumerate() {
        links.resolve_joint(ji, j, diags);
    }
    links.check_attached(diags);
    if !links.ok {
        return None;
    }
    let Links {
        parent,
        child,
        child_of,
        ..
    } = links;

    // Cycles.
    if !check_cycles(spec, diags, skip, &parent, &child_of) {
        return None;
    }

    let order = topological_order(spec, skip, &parent, &child)?;
    Some(Topo {
        parent,
        child,
        order,
    })
}

/// Body names: not "base", not twice. Returns the index of each body by name (the first of
/// duplicates).
fn unique_body_names<'a>(spec: &'a Spec, diags: &mut Diagnostics) -> HashMap<&'a str, usize> {
    let mut body_index: HashMap<&str, usize> = HashMap::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        if b.name == BASE {
            diags.push(
                Diagnostic::error("a body cannot be named \"base\"")
                    .with_key(format!("{}.name", b.key))
                    .with_span(b.span.clone())
                    .with_hint("\"base\" is the fixed world that the first joints attach to; it has no [[body]] entry"),
            );
        } else if let Some(&first) = body_index.get(b.name.as_str()) {
            diags.push(
                Diagnostic::error(format!("duplicate body name \"{}\"", b.name))
                    .with_key(format!("{}.name", b.key))
                    .with_span(b.span.clone())
                    .with_hint(format!(
                        "body names must be unique; the first \"{}\" is {}",
                        b.name,
                        position(diags.source(), &spec.bodies[first].span)
                    )),
            );
        } else {
            body_index.insert(&b.name, i);
        }
    }
    body_index
}

/// Joint names: not twice.
fn check_unique_joint_names(spec: &Spec, diags: &mut Diagnostics) {
    let mut joint_index: HashMap<&str, usize> = HashMap::new();
    for (i, j) in spec.joints.iter().enumerate() {
        if let Some(&first) = joint_index.get(j.name.as_str()) {
            diags.push(
                Diagnostic::error(format!("duplicate joint name \"{}\"", j.name))
                    .with_key(format!("{}.name", j.key))
                    .with_span(j.span.clone())
                    .with_hint(format!(
                        "joint names must be unique; the first \"{}\" is {}",
                        j.name,
                        position(diags.source(), &spec.joints[first].span)
                    )),
            );
        } else {
            joint_index.insert(&j.name, i);
        }
    }
}

/// The parent and child bodies of the joints, being resolved.
struct Links<'a> {
    spec: &'a Spec,
    skip: &'a Skip,
    body_index: HashMap<&'a str, usize>,
    body_names: Vec<&'a str>,
    /// Per joint: parent body index (`None` = base).
    parent: Vec<Option<usize>>,
    /// Per joint: child body index (`usize::MAX` while unresolved).
    child: Vec<usize>,
    /// Per body: the (unskipped) joint it is the child of.
    child_of: Vec<Option<usize>>,
    /// No error so far.
    ok: bool,
}

impl<'a> Links<'a> {
    fn new(spec: &'a Spec, skip: &'a Skip, body_index: HashMap<&'a str, usize>) -> Self {
        Links {
            spec,
            skip,
            body_index,
            body_names: spec.bodies.iter().map(|b| b.name.as_str()).collect(),
            parent: vec![None; spec.joints.len()],
            child: vec![usize::MAX; spec.joints.len()],
            child_of: vec![None; spec.bodies.len()],
            ok: true,
        }
    }

    /// Resolves joint `ji`'s parent and child and, unless it is skipped, claims its child.
    fn resolve_joint(&mut self, ji: usize, j: &JointSpec, diags: &mut Diagnostics) {
        self.resolve_parent(ji, j, diags);
        let Some(c) = self.resolve_child(j, diags) else {
            return;
        };
        self.child[ji] = c;
        if self.skip.joint[ji] {
            return;
        }
        self.claim_child(ji, j, c, diags);
    }

    fn resolve_parent(&mut self, ji: usize, j: &JointSpec, diags: &mut Diagnostics) {
        if j.parent != BASE {
            match self.body_index.get(j.parent.as_str()) {
                Some(&b) => self.parent[ji] = Some(b),
                None => {
                    self.ok = false;
                    let mut cands = self.body_names.clone();
                    cands.push(BASE);
                    diags.push(
                        Diagnostic::error(format!("unknown parent body \"{}\"", j.parent))
                            .with_key(format!("{}.parent", j.key))
                            .with_span(j.parent_span.clone())
                            .with_hint(suggest_hint(&j.parent, &cands).unwrap_or_else(|| {
                                "the parent must be \"base\" or the name of a body".into()
                            })),
                    );
                }
            }
        }
    }

    /// The child body of `j`, or `None` (reported) when it is the base or unknown.
    fn resolve_child(&mut self, j: &JointSpec, diags: &mut Diagnostics) -> Option<usize> {
        if j.child == BASE {
            self.ok = false;
            diags.push(
                Diagnostic::error("the base cannot be a joint's child")
                    .with_key(format!("{}.child", j.key))
                    .with_span(j.child_span.clone())
                    .with_hint("\"base\" is the fixed world; swap `parent` and `child`?"),
            );
            return None;
        }
        let Some(&c) = self.body_index.get(j.child.as_str()) else {
            self.ok = false;
            diags.push(
                Diagnostic::error(format!("unknown child body \"{}\"", j.child))
                    .with_key(format!("{}.child", j.key))
                    .with_span(j.child_span.clone())
                    .with_hint(
                        suggest_hint(&j.child, &self.body_names)
                            .unwrap_or_else(|| "the child must be the name of a body".into()),
                    ),
            );
            return None;
        };
        Some(c)
    }

    /// Makes body `c` the child of joint `ji`: not a platform body, not the child of another
    /// joint.
    fn claim_child(&mut self, ji: usize, j: &JointSpec, c: usize, diags: &mut Diagnostics) {
        if self.skip.body[c] {
            self.ok = false;
            diags.push(
                Diagnostic::error(format!(
                    "body \"{}\" is part of the platform and cannot be the child of joint \"{}\"",
                    j.child, j.name
                ))
                .with_key(format!("{}.child", j.key))
                .with_span(j.child_span.clone())
                .with_hint("the platform and the bodies fixed to it are reached only through the joints into the platform (with `child_origin`) and the fixed joints hanging from it"),
            );
            return;
        }
        if let Some(first) = self.child_of[c] {
            self.ok = false;
            let d = if self.skip.body.iter().any(|s| *s) {
                // A parallel mechanism: only the platform closes loops.
                Diagnostic::error("only the platform may be the child of several joints: other closed loops are not supported")
                    .with_hint(format!(
                        "body \"{}\" is already the child of joint \"{}\"; the loops of a simple-platform mechanism close at the platform, every other body is the child of exactly one joint",
                        j.child, self.spec.joints[first].name
                    ))
            } else {
                Diagnostic::error(format!("body \"{}\" is the child of two joints: this closes a loop", j.child))
                    .with_hint(format!(
                        "body \"{}\" is already the child of joint \"{}\"; to close a loop, give this joint `child_origin` (its frame in the child's body frame) and mark the independent joints `actuated` (docs/spec.md, \"Closed loops in joint coordinates\"), or add a [platform] table for a parallel mechanism",
                        j.child, self.spec.joints[first].name
                    ))
            };
            diags.push(
                d.with_key(format!("{}.child", j.key))
                    .with_span(j.child_span.clone()),
            );
        } else {
            self.child_of[c] = Some(ji);
        }
    }

    /// Every body (but skipped ones) is the child of a joint.
    fn check_attached(&mut self, diags: &mut Diagnostics) {
        let spec = self.spec;
        for (bi, b) in spec.bodies.iter().enumerate() {
            if self.child_of[bi].is_none()
                && !self.skip.body[bi]
                && !spec.joints_incomplete
                && b.name != BASE
                && self.body_index.get(b.name.as_str()) == Some(&bi)
            {
                self.ok = false;
                diags.push(
                    Diagnostic::error(format!("body \"{}\" is not attached to anything", b.name))
                        .with_key(b.key.clone())
                        .with_span(b.span.clone())
                        .with_hint(format!(
                            "add a joint with child = \"{}\" (use kind = \"fixed\" for a rigid attachment)",
                            b.name
                        )),
                );
            }
        }
    }
}

/// Cycles: follow parents from every joint; `false` when there is one (reported).
fn check_cycles(
    spec: &Spec,
    diags: &mut Diagnostics,
    skip: &Skip,
    parent: &[Option<usize>],
    child_of: &[Option<usize>],
) -> bool {
    let mut ok = true;
    // 0 = unseen, 1 = on the current walk, 2 = reaches base.
    let mut state = vec![0u8; spec.joints.len()];
    for start in (0..spec.joints.len()).filter(|&j| !skip.joint[j]) {
        let mut walk = Vec::new();
        let mut j = start;
        loop {
            match state[j] {
                2 => break,
                1 => {
                    report_cycle(spec, diags, &walk, j);
                    ok = false;
                    break;
                }
                _ => {}
            }
            state[j] = 1;
            walk.push(j);
            match parent[j] {
                None => break,
                Some(p) => match child_of[p] {
                    Some(pj) => j = pj,
                    None => break,
                },
            }
        }
        for &w in &walk {
            state[w] = 2;
        }
    }
    ok
}

/// Reports the cycle that the walk `walk` closes by coming back to joint `j`.
fn report_cycle(spec: &Spec, diags: &mut Diagnostics, walk: &[usize], j: usize) {
    // Cycle: the part of `walk` from `j` on.
    let pos = walk.iter().position(|&x| x == j).unwrap_or(0);
    let cycle = &walk[pos..];
    let first = *cycle.iter().min().unwrap_or(&j);
    let mut names: Vec<String> = cycle
        .iter()
        .map(|&x| format!("\"{}\"", spec.joints[x].name))
        .collect();
    if let Some(f) = names.first().cloned() {
        names.push(f);
    }
    let js = &spec.joints[first];
    diags.push(
        Diagnostic::error(format!(
            "kinematic cycle: following the parents, joints {} never reach \"base\"",
            names.join(" → ")
        ))
        .with_key(format!("{}.parent", js.key))
        .with_span(js.parent_span.clone())
        .with_hint(
            "every chain of parents must end at \"base\"; one of these joints needs another parent",
        ),
    );
}

/// Stable topological order: repeatedly the first declared joint whose parent is placed.
fn topological_order(
    spec: &Spec,
    skip: &Skip,
    parent: &[Option<usize>],
    child: &[usize],
) -> Option<Vec<usize>> {
    let n = spec.joints.len();
    let mut placed = skip.joint.clone();
    let mut body_placed = vec![false; spec.bodies.len()];
    let active = skip.joint.iter().filter(|s| !**s).count();
    let mut order = Vec::with_capacity(active);
    while order.len() < active {
        let next = (0..n).find(|&j| !placed[j] && parent[j].is_none_or(|p| body_placed[p]))?;
        placed[next] = true;
        body_placed[child[next]] = true;
        order.push(next);
    }
    Some(order)
}

/// `line:col` of a span's start, for hints.
pub(super) fn position(source: &str, span: &Span) -> String {
    match span {
        Some(s) => {
            let (line, col) = crate::diag::line_column(source, s.start.min(source.len()));
            format!("at line {line}, column {col}")
        }
        None => "earlier".into(),
    }
}

/// Where a spec body ended up: the model body it is rigidly part of (`None` = base) and the
/// pose of its user frame in that body's frame.
#[derive(Clone, Copy)]
pub(super) struct Attach {
    pub target: Option<usize>,
    pub pose: Transform,
}

/// The lowered tree with the bookkeeping the parallel lowering needs.
pub(super) struct Built {
    pub model: Model,
    /// Per spec body: where it ended up (`None` for skipped bodies).
    pub attach: Vec<Option<Attach>>,
    /// Per model joint: the spec joint it comes from.
    pub spec_joint: Vec<usize>,
}

/// The model under construction.
#[derive(Default)]
struct Builder {
    joints: Vec<Joint>,
    body_names: Vec<String>,
    parts: Vec<Vec<MassProps>>,
    /// Per joint: the spec joint it comes from.
    spec_joint: Vec<usize>,
    /// Names made up by the U/S expansion, with the span of the joint that made them.
    generated: Vec<(String, Span)>,
}

impl Builder {
    /// Adds `joint` moving a new body named `body_name`; `spec_joint` is the spec joint it
    /// comes from. Returns its index.
    fn add(&mut self, joint: Joint, body_name: String, spec_joint: usize) -> usize {
        self.spec_joint.push(spec_joint);
        self.joints.push(joint);
        self.body_names.push(body_name);
        self.parts.push(Vec::new());
        self.joints.len() - 1
    }
}

/// The placement of a joint: the joint frame in the parent's user frame, and (standard DH) the
/// pose of the child's user frame in the joint frame after the motion.
pub(super) fn placement_frames(p: &Placement) -> (Transform, Transform) {
    match p {
        Placement::Origin(t) => (*t, Transform::IDENTITY),
        Placement::Dh(dh) => (geom::dh_origin(dh), geom::dh_offset(dh)),
        Placement::Mdh(dh) => (geom::mdh_origin(dh), Transform::IDENTITY),
    }
}

pub(super) fn build(spec: &Spec, topo: &Topo, axes: &Axes, diags: &mut Diagnostics) -> Built {
    let mut attach: Vec<Option<Attach>> = vec![None; spec.bodies.len()];
    let mut m = Builder::default();
    let base = Attach {
        target: None,
        pose: Transform::IDENTITY,
    };

    for &ji in &topo.order {
        let j = &spec.joints[ji];
        let body = &spec.bodies[topo.child[ji]];
        let from = topo.parent[ji].and_then(|p| attach[p]).unwrap_or(base);
        let (origin_user, offset) = placement_frames(&j.placement);
        let origin = compose(&from.pose, &origin_user);
        let props = MassProps {
            mass: body.mass,
            com: body.com,
            inertia: body.inertia,
        };
        let ax = &axes[ji];
        let child_attach = match j.kind {
            Kind::Fixed => Attach {
                target: from.target,
                pose: compose(&origin, &offset),
            },
            Kind::Revolute | Kind::Prismatic => {
                let kind = if j.kind == Kind::Revolute {
                    JointKind::Revolute
                } else {
                    JointKind::Prismatic
                };
                let i = m.add(
                    Joint {
                        name: j.name.clone(),
                        kind,
                        parent: from.target,
                        origin,
                        axis: ax[0],
                        drive: spec.scene.drive(&j.drive),
                    },
                    body.name.clone(),
                    ji,
                );
                Attach {
                    target: Some(i),
                    pose: offset,
                }
            }
            Kind::Universal | Kind::Spherical => {
                let (suffixes, bodies): (&[&str], &[&str]) = if j.kind == Kind::Universal {
                    (&["_1", "_2"], &["_cross"])
                } else {
                    (&["_x", "_y", "_z"], &["_x_body", "_y_body"])
                };
                let mut parent = from.target;
                let mut o = origin;
                for (k, sfx) in suffixes.iter().enumerate() {
                    let bname = match bodies.get(k) {
                        Some(b) => {
                            let n = format!("{}{b}", j.name);
                            m.generated.push((n.clone(), j.span.clone()));
                            n
                        }
                        None => body.name.clone(),
                    };
                    let jname = format!("{}{sfx}", j.name);
                    m.generated.push((jname.clone(), j.span.clone()));
                    let joint = Joint {
                        name: jname,
                        kind: JointKind::Revolute,
                        parent,
                        origin: o,
                        axis: ax[k],
                        drive: spec.scene.drive(&j.drive),
                    };
                    let i = m.add(joint, bname, ji);
                    // The cross, in its body's frame (the joint frame after the first turn).
                    if k == 0
                        && let Some(c) = super::cross::props(j)
                    {
                        m.parts[i].push(c);
                    }
                    parent = Some(i);
                    o = Transform::IDENTITY;
                }
                Attach {
                    target: parent,
                    pose: offset,
                }
            }
        };
        // The body's own mass goes into the model body it is now part of (none for the base).
        if let Some(t) = child_attach.target {
            m.parts[t].push(props.transformed(&child_attach.pose));
        }
        attach[topo.child[ji]] = Some(child_attach);
    }

    // Clashes of generated names with user names or with each other.
    let user: Vec<&str> = spec
        .bodies
        .iter()
        .map(|b| b.name.as_str())
        .chain(spec.joints.iter().map(|j| j.name.as_str()))
        .collect();
    for (k, (name, span)) in m.generated.iter().enumerate() {
        let again = m.generated[..k].iter().any(|(n, _)| n == name);
        if user.contains(&name.as_str()) || again {
            diags.push(
                Diagnostic::error(format!(
                    "the generated name \"{name}\" clashes with another name"
                ))
                .with_span(span.clone())
                .with_hint("universal and spherical joints expand into revolutes named <joint>_1, <joint>_2 (body <joint>_cross) and <joint>_x, <joint>_y, <joint>_z (bodies <joint>_x_body, <joint>_y_body); rename the joint or the clashing entry"),
            );
        }
    }

    if m.joints.is_empty() {
        diags.push(
            Diagnostic::error("the mechanism has no movable joints")
                .with_span(spec.anchor.clone())
                .with_hint("add at least one revolute, prismatic, universal or spherical joint"),
        );
    }

    let bodies = m
        .body_names
        .into_iter()
        .zip(&m.parts)
        .map(|(name, p)| {
            let mp = MassProps::combine(p);
            Body {
                name,
                mass: mp.mass,
                com: mp.com,
                inertia: mp.inertia,
            }
        })
        .collect();
    Built {
        model: Model {
            name: spec.name.clone(),
            gravity: spec.gravity,
            bodies,
            joints: m.joints,
        },
        attach,
        spec_joint: m.spec_joint,
    }
}

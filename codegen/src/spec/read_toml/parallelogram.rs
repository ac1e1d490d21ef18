//! `[[parallelogram]]` entries: a Delta robot's forearm, two equal rods with ball joints at
//! both ends whose short sides (elbow and platform) stay parallel to the motor axis. Read, then
//! expanded into what the rest of the pipeline knows: the pair's equivalent rod (a body), a
//! universal joint at the elbow and a spherical joint at the platform (docs/spec.md,
//! "Parallelograms").
//!
//! Both rods of such a parallelogram have the same velocity field (the second rod is the first
//! shifted by a constant vector along the motor axis, and the platform only translates), so the
//! pair is one rod of twice the mass and twice the transverse inertia on the midline from the
//! elbow point `E` to the platform point `P`, with angular velocity `d × (Ṗ − Ė)/L` and no spin:
//! each rod's spin about its own axis is an idle freedom of its ball joints, removed with the
//! rods' spin inertia. The expansion's U (first axis along the motor axis, second along
//! `a × d` at home) lets the equivalent rod turn about its own axis, which carries no inertia,
//! so the dynamics are exactly those of the pair.

use std::ops::Range;

use runtime::model::{Transform, Vec3, mat_vec, transpose};
use toml::de::DeTable;

use super::keys::PARALLELOGRAM_KEYS;
use super::{Reader, Val, get};
use crate::diag::Diagnostic;
use crate::spec::geom::{self, compose};
use crate::spec::ir::{
    AxisSpec, BodySpec, Coordinates, DriveSpec, JointSpec, Kind, Placement, Spec,
};
use crate::spec::lower::placement_frames;

/// A `[[parallelogram]]` entry as read, with the spans its checks point at.
#[derive(Clone, Debug)]
pub(super) struct ParallelogramSpec {
    name: String,
    path: String,
    span: Range<usize>,
    name_span: Range<usize>,
    parent: String,
    parent_span: Range<usize>,
    child: String,
    child_span: Range<usize>,
    /// `E`: the midpoint of the elbow's short side, in the parent body's frame (m).
    elbow: Vec3,
    /// `P`: the midpoint of the platform's short side, in the platform frame (m).
    platform_point: Vec3,
    length: f64,
    length_span: Range<usize>,
    elbow_width: f64,
    platform_width: f64,
    platform_width_span: Range<usize>,
    rod_mass: f64,
    rod_mass_span: Range<usize>,
    rod_com: f64,
    /// Each rod's inertia about its mass centre, `x` along the rod.
    rod_inertia: [[f64; 3]; 3],
    rod_inertia_span: Range<usize>,
    /// `cross`: the elbow U's cross body `<name>_elbow_cross` (an elbow axle turning about the
    /// motor axis's direction), in the U's frame after its first turn (the parent's axes at
    /// `E`); `None` when not written (massless).
    cross: Option<BodySpec>,
}

fn unit(v: &Vec3) -> Vec3 {
    let n = geom::norm(v);
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        *v
    }
}

impl ParallelogramSpec {
    pub(super) fn parent(&self) -> &str {
        &self.parent
    }
    pub(super) fn child(&self) -> &str {
        &self.child
    }
    /// A pattern copy's turn `r` of the points on bodies outside the pattern: `elbow` when the
    /// parent is outside, `platform_point` when the child is.
    pub(super) fn turn(&mut self, r: &runtime::model::Mat3, parent: bool, child: bool) {
        if parent {
            self.elbow = mat_vec(r, &self.elbow);
            // The elbow U's frame has the parent's axes: the cross turns with the elbow.
            if let Some(c) = &mut self.cross {
                c.com = mat_vec(r, &c.com);
                c.inertia =
                    runtime::model::mat_mul(&runtime::model::mat_mul(r, &c.inertia), &transpose(r));
            }
        }
        if child {
            self.platform_point = mat_vec(r, &self.platform_point);
        }
    }
}

/// Relative tolerance of the parallelogram's equalities (widths, the rods' transverse moments,
/// the rod length against the home placement).
const TOLERANCE: f64 = 1e-9;

impl Reader<'_> {
    /// `[[parallelogram]]`: every key required but `rod_com` (default mid-length).
    pub(super) fn parallelogram(
        &mut self,
        i: usize,
        t: &DeTable<'_>,
        span: Range<usize>,
    ) -> Option<ParallelogramSpec> {
        let path = self.path(t, "parallelogram", i);
        self.unknown_keys(t, PARALLELOGRAM_KEYS, &path);
        let name = self.name(t, &path, span.clone());
        let name_span = get(t, "name").map_or(span.clone(), |v| v.span());
        let required = |r: &mut Self, k: &str, hint: &str| -> Option<&Val<'_>> {
            let v = get(t, k);
            if v.is_none() {
                r.missing(k, &path, span.clone(), hint);
            }
            v
        };
        let body = |r: &mut Self, k: &str, hint: &str| {
            let v = required(r, k, hint)?;
            Some((r.string(v, &format!("{path}.{k}"))?, v.span()))
        };
        let parent = body(
            self,
            "parent",
            "the upper arm: the body that carries the elbow",
        );
        let child = body(self, "child", "the platform body");
        let point = |r: &mut Self, k: &str, hint: &str| {
            let v = required(r, k, hint)?;
            r.triple(v, &format!("{path}.{k}"), false)
        };
        let elbow = point(
            self,
            "elbow",
            "elbow = [x, y, z]: the midpoint of the elbow's short side, in the parent's frame (m)",
        );
        let platform_point = point(
            self,
            "platform_point",
            "platform_point = [x, y, z]: the midpoint of the platform's short side, in the platform frame (m)",
        );
        let number = |r: &mut Self, k: &str, positive: bool, hint: &str| {
            let v = required(r, k, hint)?;
            let key = format!("{path}.{k}");
            let x = r.number(v, &key)?;
            if !(x.is_finite() && (x > 0.0 || (!positive && x == 0.0))) {
                let what = if positive { "positive" } else { "not negative" };
                r.err(
                    format!("{k} must be finite and {what}, found {x}"),
                    &key,
                    v.span(),
                )
                .hint = Some(hint.into());
                return None;
            }
            Some((x, v.span()))
        };
        let length = number(
            self,
            "length",
            true,
            "each rod's length, ball centre to ball centre (m)",
        );
        let elbow_width = number(
            self,
            "elbow_width",
            false,
            "the distance of the two rods' elbow balls, along the motor axis (m)",
        );
        let platform_width = number(
            self,
            "platform_width",
            false,
            "the distance of the two rods' platform balls, along the motor axis (m)",
        );
        let rod_mass = number(self, "rod_mass", false, "each rod's mass (kg)");
        let rod_com = match get(t, "rod_com") {
            None => length.as_ref().map(|l| l.0 / 2.0),
            Some(v) => self.number(v, &format!("{path}.rod_com")),
        };
        let rod_inertia = required(
            self,
            "rod_inertia",
            "each rod's inertia about its mass centre, x along the rod: { ixx, iyy, izz }",
        )
        .and_then(|v| Some((self.inertia(v, &format!("{path}.rod_inertia"))?, v.span())));
        // The elbow's cross, read as a universal joint's `cross` is (docs/spec.md,
        // "Parallelograms").
        let cross = get(t, "cross").and_then(|v| {
            let key = format!("{path}.cross");
            let c = self.table(v, &key)?;
            let joint = format!("{}_elbow", name.as_deref().unwrap_or("parallelogram"));
            Some(self.cross(&joint, c, key, v.span()))
        });
        let (parent, parent_span) = parent?;
        let (child, child_span) = child?;
        let (length, length_span) = length?;
        let (platform_width, platform_width_span) = platform_width?;
        let (rod_mass, rod_mass_span) = rod_mass?;
        let (rod_inertia, rod_inertia_span) = rod_inertia?;
        Some(ParallelogramSpec {
            name: name?,
            path: path.clone(),
            span,
            name_span,
            parent,
            parent_span,
            child,
            child_span,
            elbow: elbow?,
            platform_point: platform_point?,
            length,
            length_span,
            elbow_width: elbow_width?.0,
            platform_width,
            platform_width_span,
            rod_mass,
            rod_mass_span,
            rod_com: rod_com?,
            rod_inertia,
            rod_inertia_span,
            cross,
        })
    }

    /// Expands the parallelograms into `spec` (see the module docs), with the checks that
    /// need the home placement: equal widths, equal transverse moments of the rods, the rod
    /// length against the home distance of `E` and `P`, a revolute joint moving the parent
    /// (whose axis the short sides follow), and a translational platform.
    pub(super) fn expand_parallelograms(&mut self, spec: &mut Spec, pgs: Vec<ParallelogramSpec>) {
        for pg in pgs {
            if let Some((body, joints)) = self.expand(spec, &pg) {
                spec.bodies.push(body);
                spec.joints.extend(joints);
            }
            spec.parallelogram_widths.push(pg.elbow_width);
            spec.parallelograms.push(pg.name);
        }
    }

    /// The checks, each reported at its key; the expansion goes ahead after those whose
    /// values it does not need (so that the legs' checks do not echo them), with the rod
    /// placed at the home distance of `E` and `P`.
    fn expand(
        &mut self,
        spec: &Spec,
        pg: &ParallelogramSpec,
    ) -> Option<(BodySpec, [JointSpec; 2])> {
        let key = |k: &str| format!("{}.{k}", pg.path);
        let ps = spec.platform.as_ref()?;
        if !matches!(
            ps.coordinates,
            Some(Coordinates::Translation | Coordinates::Schoenflies)
        ) {
            self.err(
                "a parallelogram needs a translational platform",
                &pg.path,
                pg.span.clone(),
            )
            .hint = Some("write [platform] coordinates = \"translation\" (a Delta robot): the rods' short sides stay parallel only while the platform does not turn".into());
        }
        let w = pg.elbow_width.max(pg.platform_width).max(pg.length);
        if (pg.elbow_width - pg.platform_width).abs() > TOLERANCE * w {
            self.err(
                format!(
                    "the parallelogram's short sides differ: elbow_width = {} m but platform_width = {} m",
                    geom::num(pg.elbow_width),
                    geom::num(pg.platform_width)
                ),
                &key("platform_width"),
                pg.platform_width_span.clone(),
            )
            .hint = Some("the two rods form a parallelogram only when the elbow's and the platform's ball pairs are the same distance apart; make the widths equal".into());
        }
        let i = pg.rod_inertia;
        let off = i[0][1].abs() + i[0][2].abs() + i[1][2].abs();
        let big = i[1][1].abs().max(i[2][2].abs()).max(i[0][0].abs());
        if (i[1][1] - i[2][2]).abs() > TOLERANCE * big || off > TOLERANCE * big {
            self.err(
                "a parallelogram's rods must be symmetric about their own axis: rod_inertia needs iyy = izz and no products",
                &key("rod_inertia"),
                pg.rod_inertia_span.clone(),
            )
            .hint = Some("the rods' spin about their own axis is an idle freedom of their ball joints, so the model holds only for rods whose transverse moments are equal (x is the rod axis)".into());
        }
        let (parent_pose, axis) = self.motor(spec, pg)?;
        let e = parent_pose.apply(&pg.elbow);
        let p = ps.home.apply(&pg.platform_point);
        let d = [p[0] - e[0], p[1] - e[1], p[2] - e[2]];
        let dist = geom::norm(&d);
        let mismatch = (dist - pg.length).abs();
        if mismatch > TOLERANCE * w.max(dist)
            && mismatch <= runtime::closed::HOME_CORRECTION * w.max(dist)
        {
            // Rounded numbers: the home geometry decides (the rods run from the elbow point to
            // the platform point; `length` is only checked).
            self.diags.push(
                Diagnostic::warning(format!(
                    "the rods are {} m long, but at home the elbow point and the platform point are {} m apart: the rods are taken as {} m, the home geometry",
                    geom::num(pg.length),
                    geom::num(dist),
                    geom::num(dist)
                ))
                .with_key(key("length"))
                .with_span(pg.length_span.clone())
                .with_fix("length", geom::toml_num(dist))
                .with_hint(format!(
                    "differences up to {:.0e} × the parallelogram's size are accepted so, as rounded numbers leave them; write length = {} to silence this (`codegen fix-home FILE` does)",
                    runtime::closed::HOME_CORRECTION,
                    geom::num(dist)
                )),
            );
        } else if mismatch > TOLERANCE * w.max(dist) {
            self.err(
                format!(
                    "the rods are {} m long, but at home the elbow point and the platform point are {} m apart",
                    geom::num(pg.length),
                    geom::num(dist)
                ),
                &key("length"),
                pg.length_span.clone(),
            )
            .hint = Some("place the upper arm and the platform's home so that the parallelogram closes: |P − E| = length (elbow in the parent's frame, platform_point in the platform frame at platform.home)".into());
        }
        if dist == 0.0 {
            return None;
        }
        // Rod direction and motor axis in the parent's frame.
        let rt = transpose(&parent_pose.rotation);
        let d = mat_vec(&rt, &[d[0] / dist, d[1] / dist, d[2] / dist]);
        let a = mat_vec(&rt, &axis);
        let n = geom::cross(&a, &d);
        let nn = geom::norm(&n);
        if nn < 1e-6 {
            self.err(
                "at home the rods lie along the motor axis",
                &key("elbow"),
                pg.span.clone(),
            )
            .hint = Some("the parallelogram degenerates when its rods are parallel to its short sides; choose a home where the rods cross the motor axis".into());
            return None;
        }
        let n = [n[0] / nn, n[1] / nn, n[2] / nn];
        Some(self.equivalent(pg, a, n, d, dist))
    }

    /// The parent's pose at home (base frame) and the axis of the revolute joint that moves it
    /// (base frame): the short sides' direction.
    fn motor(&mut self, spec: &Spec, pg: &ParallelogramSpec) -> Option<(Transform, Vec3)> {
        let mover = spec.joints.iter().find(|j| j.child == pg.parent);
        let Some(mj) = mover.filter(|j| j.kind == Kind::Revolute) else {
            self.err(
                format!(
                    "the parallelogram's parent \"{}\" must be moved by a revolute joint (the motor)",
                    pg.parent
                ),
                &format!("{}.parent", pg.path),
                pg.parent_span.clone(),
            )
            .hint = Some("a Delta leg is a revolute crank (the upper arm) carrying the parallelogram; its short sides follow the crank's axis".into());
            return None;
        };
        // The parent's pose at home: its joints' frames composed down to the base.
        let mut pose = Transform::IDENTITY;
        let mut at = pg.parent.as_str();
        for _ in 0..=spec.joints.len() {
            if at == crate::spec::ir::BASE {
                break;
            }
            let j = spec.joints.iter().find(|j| j.child == at)?;
            let (origin, offset) = placement_frames(&j.placement);
            pose = compose(&compose(&origin, &offset), &pose);
            at = j.parent.as_str();
        }
        let (_, offset) = placement_frames(&mj.placement);
        let joint_axis = match mj.placement {
            Placement::Origin(_) => mj.axes.first().map_or([0.0, 0.0, 1.0], |a| a.v),
            _ => [0.0, 0.0, 1.0],
        };
        // The joint frame is the parent's pose without the joint's offset.
        let frame_rot = runtime::model::mat_mul(&pose.rotation, &transpose(&offset.rotation));
        Some((pose, mat_vec(&frame_rot, &unit(&joint_axis))))
    }

    /// The equivalent rod (body), the U at the elbow and the S at the platform.
    fn equivalent(
        &mut self,
        pg: &ParallelogramSpec,
        a: Vec3,
        n: Vec3,
        d: Vec3,
        l: f64,
    ) -> (BodySpec, [JointSpec; 2]) {
        let rods = format!("{}_rods", pg.name);
        let it = 2.0 * pg.rod_inertia[1][1];
        let inertia: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|c| it * (f64::from(u8::from(r == c)) - d[r] * d[c]))
        });
        let body = BodySpec {
            name: rods.clone(),
            key: pg.path.clone(),
            span: Some(pg.name_span.clone()),
            mass: 2.0 * pg.rod_mass,
            mass_span: Some(pg.rod_mass_span.clone()),
            com: [pg.rod_com * d[0], pg.rod_com * d[1], pg.rod_com * d[2]],
            inertia,
            inertia_span: Some(pg.rod_inertia_span.clone()),
            own_inertia: None,
            own_frame: Transform::IDENTITY,
        };
        let at = |t: Vec3| Transform {
            rotation: Transform::IDENTITY.rotation,
            translation: t,
        };
        let axis = |v: Vec3| AxisSpec {
            v,
            key: pg.path.clone(),
            span: Some(pg.span.clone()),
        };
        let joint = |name: String, kind, parent: String, child: String| JointSpec {
            name,
            key: pg.path.clone(),
            span: Some(pg.name_span.clone()),
            kind,
            kind_span: Some(pg.span.clone()),
            parent,
            parent_span: Some(pg.parent_span.clone()),
            child,
            child_span: Some(pg.child_span.clone()),
            placement: Placement::Origin(Transform::IDENTITY),
            axes: Vec::new(),
            actuated: false,
            actuated_span: None,
            child_origin: None,
            child_origin_span: None,
            home: 0.0,
            home_span: None,
            drive: DriveSpec::default(),
            cross: None,
            limit: None,
        };
        let mut u = joint(
            format!("{}_elbow", pg.name),
            Kind::Universal,
            pg.parent.clone(),
            rods.clone(),
        );
        u.placement = Placement::Origin(at(pg.elbow));
        u.axes = vec![axis(a), axis(n)];
        u.cross = pg.cross.clone();
        let mut s = joint(pg.name.clone(), Kind::Spherical, rods, pg.child.clone());
        s.placement = Placement::Origin(at([l * d[0], l * d[1], l * d[2]]));
        s.child_origin = Some(at(pg.platform_point));
        s.child_origin_span = Some(pg.span.clone());
        (body, [u, s])
    }
}

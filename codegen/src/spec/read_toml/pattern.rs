//! `[[pattern]]`: a group of bodies, joints, parallelograms and springs written once and
//! repeated `copies` times, each copy turned about `axis` by `angle` more than the one before
//! (docs/spec.md, "Leg patterns"). In copy `i` (from 1), `{i}` in a name or a body reference
//! becomes the copy's number, and expressions see `i` and the pattern's own `parameters`.
//!
//! The turn applies where a copy meets a body outside the pattern (the base, the platform):
//! a joint's `origin` when its parent is outside, its `child_origin` when its child is
//! outside, a parallelogram's `elbow` and `platform_point`, a spring's points, each in the
//! outside body's frame, about `axis` through that frame's origin. Placements between bodies
//! of the same copy are the same in every copy.

use std::ops::Range;

use runtime::model::{Mat3, Transform, mat_mul, mat_vec};
use toml::de::{DeTable, DeValue};

use super::keys::PATTERN_KEYS;
use super::parallelogram::ParallelogramSpec;
use super::{Reader, get, key_span};
use crate::spec::expr::Value;
use crate::spec::ir::{BodySpec, JointSpec, Placement, SpringSpec};

/// The largest number of copies (a typo such as `copies = 30000` fails fast).
const MAX_COPIES: usize = 64;

/// The copy being read: its number (from 1), its own parameters, its turn and the names of
/// its bodies (after `{i}` is replaced).
pub(super) struct PatternCopy {
    pub index: usize,
    pub params: Vec<(String, Value)>,
    turn: Mat3,
    members: Vec<String>,
}

/// What the copies of all patterns add to the file's own entries, in file order.
#[derive(Default)]
pub(super) struct Copies {
    pub bodies: Vec<BodySpec>,
    pub joints: Vec<JointSpec>,
    pub springs: Vec<SpringSpec>,
    pub parallelograms: Vec<ParallelogramSpec>,
}

fn turned(r: &Mat3, t: &Transform) -> Transform {
    Transform {
        rotation: mat_mul(r, &t.rotation),
        translation: mat_vec(r, &t.translation),
    }
}

impl PatternCopy {
    fn outside(&self, body: &str) -> bool {
        !self.members.iter().any(|m| m == body)
    }
}

impl Reader<'_> {
    /// `{i}` replaced by the copy's number, inside a pattern; `s` itself outside.
    pub(super) fn substitute(&self, s: &str) -> String {
        match &self.copy {
            Some(c) => s.replace("{i}", &c.index.to_string()),
            None => s.to_owned(),
        }
    }

    /// Every `[[pattern]]`, expanded.
    pub(super) fn patterns(&mut self, root: &DeTable<'_>) -> Copies {
        let mut out = Copies::default();
        for (k, t, span) in self.entries(root, "pattern") {
            self.pattern(k, t, span, &mut out);
        }
        out
    }

    fn pattern(&mut self, k: usize, t: &DeTable<'_>, span: Range<usize>, out: &mut Copies) {
        if !self.pattern_copies(k, t, span, out) {
            // The pattern's copies are missing (the reason reported): the whole-mechanism
            // checks (the actuator count, the mobility, joints into the platform, bodies left
            // unattached) would only echo that error, ahead of it in the file.
            self.joints_incomplete = true;
        }
    }

    /// The copies of one pattern into `out`; `false` when some are missing: none could be made
    /// (an error in `copies`, `axis` or `angle`, or nothing to repeat), or an error in an entry
    /// stopped them after the first copy (reported once, not once per copy).
    fn pattern_copies(
        &mut self,
        k: usize,
        t: &DeTable<'_>,
        span: Range<usize>,
        out: &mut Copies,
    ) -> bool {
        let path = match get(t, "name").map(|v| v.get_ref()) {
            Some(DeValue::String(s)) => format!("pattern \"{s}\""),
            _ => format!("pattern[{k}]"),
        };
        self.unknown_keys(t, PATTERN_KEYS, &path);
        if let Some(v) = get(t, "name") {
            self.string(v, &format!("{path}.name"));
        }
        let copies = match get(t, "copies") {
            None => {
                self.missing(
                    "copies",
                    &path,
                    span.clone(),
                    "copies = N: how many times the pattern's entries are repeated",
                );
                return false;
            }
            Some(v) => match v.get_ref() {
                DeValue::Integer(n) => match i64::from_str_radix(n.as_str(), n.radix()) {
                    Ok(n) if (1..=MAX_COPIES as i64).contains(&n) => n as usize,
                    _ => {
                        self.err(
                            format!("copies must be a whole number from 1 to {MAX_COPIES}"),
                            &format!("{path}.copies"),
                            v.span(),
                        );
                        return false;
                    }
                },
                _ => {
                    self.type_error("a whole number", v, &format!("{path}.copies"));
                    return false;
                }
            },
        };
        let axis = match get(t, "axis") {
            None => Some([0.0, 0.0, 1.0]),
            Some(v) => {
                let key = format!("{path}.axis");
                self.triple(v, &key, false).and_then(|a| {
                    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
                    if n > 1e-9 {
                        Some([a[0] / n, a[1] / n, a[2] / n])
                    } else {
                        self.err("the pattern's axis is zero", &key, v.span()).hint =
                            Some("give the axis the copies turn about, e.g. [0, 0, 1]".into());
                        None
                    }
                })
            }
        };
        let step = match get(t, "angle") {
            None => Some(2.0 * core::f64::consts::PI / copies as f64),
            Some(v) => self.angle(v, &format!("{path}.angle")),
        };
        let (Some(axis), Some(step)) = (axis, step) else {
            return false;
        };
        let params = match get(t, "parameters") {
            Some(v) => self.table(v, &format!("{path}.parameters")),
            None => None,
        };
        let bodies = self.entries(t, "body");
        let joints = self.entries(t, "joint");
        let springs = self.entries(t, "spring");
        let parallelograms = self.entries(t, "parallelogram");
        if bodies.is_empty() && joints.is_empty() && parallelograms.is_empty() {
            let s = key_span(t, "copies").unwrap_or(span);
            self.err("the pattern repeats nothing", &path, s).hint = Some(
                "write its entries under [[pattern.body]], [[pattern.joint]], [[pattern.parallelogram]] or [[pattern.spring]] after the [[pattern]] header".into(),
            );
            return false;
        }
        for index in 1..=copies {
            let errors = self.diags.error_count();
            self.copy = Some(PatternCopy {
                index,
                params: Vec::new(),
                turn: crate::spec::geom::rotation(&axis, step * (index - 1) as f64),
                members: Vec::new(),
            });
            if let Some(p) = params {
                self.parameter_table(p, &format!("{path}.parameters"));
            }
            let members: Vec<String> = bodies
                .iter()
                .filter_map(|(_, b, _)| match get(b, "name").map(|v| v.get_ref()) {
                    Some(DeValue::String(s)) => Some(self.substitute(s)),
                    _ => None,
                })
                .collect();
            if let Some(c) = &mut self.copy {
                c.members = members;
            }
            for (i, b, s) in &bodies {
                if let Some(b) = self.body(*i, b, s.clone()) {
                    out.bodies.push(b);
                }
            }
            for (i, j, s) in &joints {
                if let Some(j) = self.joint(*i, j, s.clone()) {
                    let j = self.turn_joint(j, &path);
                    out.joints.push(j);
                }
            }
            for (i, sp, s) in &springs {
                if let Some(mut sp) = self.spring(*i, sp, s.clone()) {
                    let c = self.copy.as_ref().expect("inside a copy");
                    if c.outside(&sp.body_a.name) {
                        sp.point_a = mat_vec(&c.turn, &sp.point_a);
                    }
                    if c.outside(&sp.body_b.name) {
                        sp.point_b = mat_vec(&c.turn, &sp.point_b);
                    }
                    out.springs.push(sp);
                }
            }
            for (i, p, s) in &parallelograms {
                if let Some(mut p) = self.parallelogram(*i, p, s.clone()) {
                    let c = self.copy.as_ref().expect("inside a copy");
                    p.turn(&c.turn, c.outside(p.parent()), c.outside(p.child()));
                    out.parallelograms.push(p);
                }
            }
            self.copy = None;
            // An error in the pattern's text would repeat in every copy: report it once (the
            // other copies are then missing too).
            if self.diags.error_count() > errors {
                return false;
            }
        }
        true
    }

    /// A copy's joint with its placements on outside bodies turned.
    fn turn_joint(&mut self, mut j: JointSpec, path: &str) -> JointSpec {
        let c = self.copy.as_ref().expect("inside a copy");
        let (r, parent_out, child_out) = (c.turn, c.outside(&j.parent), c.outside(&j.child));
        if parent_out {
            match &mut j.placement {
                Placement::Origin(t) => *t = turned(&r, t),
                Placement::Dh(_) | Placement::Mdh(_) => {
                    if r != Transform::IDENTITY.rotation {
                        let span = j.span.clone().unwrap_or(0..0);
                        self.err(
                            format!(
                                "joint \"{}\" of {path} meets \"{}\" outside the pattern with a DH placement, which a pattern cannot turn",
                                j.name, j.parent
                            ),
                            &j.key,
                            span,
                        )
                        .hint = Some("place it with `origin = { xyz, rpy }`".into());
                    }
                }
            }
        }
        if child_out && let Some(t) = &mut j.child_origin {
            *t = turned(&r, t);
        }
        j
    }
}

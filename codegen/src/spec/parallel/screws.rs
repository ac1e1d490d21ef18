//! The declared motion against the motion the legs allow, by screw theory at home
//! (docs/method.md, "The declared platform motion, checked by reciprocal screws"; Tsai, *Robot
//! Analysis*, 1999, §4.7; Kong & Gosselin, *Type Synthesis of Parallel Mechanisms*, 2007, ch. 2).
//!
//! `[platform] coordinates` is the user's word for how the platform moves, and the evaluators
//! trust it (a translational platform is given `ω = 0`). Here it is checked: each leg's joints
//! allow the platform a space of twists; the leg's constraint wrenches are its reciprocal; the
//! platform's allowed twists are the reciprocal of all the legs' wrenches together, and they
//! must be the span of the declared motion's `S` at home.
//!
//! Conventions: a twist is `[ω; v]` (the module's order), `v` the velocity of the point at the
//! base origin: a revolute about the line through `p` along `e` is `[e; p × e]`, a prismatic
//! joint along `e` is `[0; e]`. A wrench `(f, m)` (force, moment about the base origin) is
//! written in axis coordinates `[m; f]`, so that its power on a twist is the plain dot product
//! `ω·m + v·f` and the reciprocal of a set of screws is the null space of their rows. Lengths
//! are divided by the mechanism's size first, so that one tolerance serves both halves.
//!
//! This runs in the spec lowering because a `[[parallelogram]]`'s two rods are known only here
//! (the model holds its equivalent rod, whose U and S would allow the platform everything).

use nalgebra::{DMatrix, SVD};
use runtime::model::{JointKind, Transform, Vec3, mat_mul, mat_vec};
use runtime::parallel::{LegEnd, ParallelModel, PlatformMotion, leg_home_poses};

use super::legs::Tree;
use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom;
use crate::spec::ir::{Kind, PlatformSpec};
use crate::spec::lower::Axes;

/// A twist `[ω; v]` or a wrench in axis coordinates `[m; f]`.
type Screw = [f64; 6];

/// Rank tolerance of the (size-scaled, unit-direction) screw matrices: singular values below it
/// count as zero. The screws' entries are of order one, and exact geometry rounds at 1e-16.
const RANK_TOLERANCE: f64 = 1e-9;

fn revolute(p: &Vec3, e: &Vec3) -> Screw {
    let m = geom::cross(p, e);
    [e[0], e[1], e[2], m[0], m[1], m[2]]
}

fn prismatic(e: &Vec3) -> Screw {
    [0.0, 0.0, 0.0, e[0], e[1], e[2]]
}

fn unit(v: &Vec3) -> Vec3 {
    let n = geom::norm(v);
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        *v
    }
}

fn scaled(p: &Vec3, size: f64) -> Vec3 {
    [p[0] / size, p[1] / size, p[2] / size]
}

/// An orthonormal basis of the span of `rows` (empty for no rows).
fn span(rows: &[Screw]) -> Vec<Screw> {
    split(rows).0
}

/// An orthonormal basis of the null space of `rows`: the screws reciprocal to all of them.
fn reciprocal(rows: &[Screw]) -> Vec<Screw> {
    split(rows).1
}

/// The right singular vectors of `rows` (padded to six rows): those of the range and those of
/// the null space.
fn split(rows: &[Screw]) -> (Vec<Screw>, Vec<Screw>) {
    let n = rows.len().max(6);
    let m = DMatrix::from_fn(n, 6, |r, c| rows.get(r).map_or(0.0, |s| s[c]));
    let svd = SVD::new(m, false, true);
    let (mut range, mut null) = (Vec::new(), Vec::new());
    let Some(vt) = svd.v_t else {
        return (range, null);
    };
    for (i, s) in svd.singular_values.iter().enumerate() {
        let v: Screw = std::array::from_fn(|c| vt[(i, c)]);
        if *s > RANK_TOLERANCE {
            range.push(v);
        } else {
            null.push(v);
        }
    }
    (range, null)
}

/// The rows of `a` less their projections on the orthonormal `basis`.
fn outside(a: &[Screw], basis: &[Screw]) -> Vec<Screw> {
    a.iter()
        .map(|r| {
            let mut out = *r;
            for b in basis {
                let d: f64 = (0..6).map(|i| r[i] * b[i]).sum();
                for i in 0..6 {
                    out[i] -= d * b[i];
                }
            }
            out
        })
        .collect()
}

/// The declared motion: the span of its `S` at home (size-scaled twists) and its words (the
/// `coordinates` value, what it does to the platform), or `None` for a motion the check does
/// not cover. One arm per [`PlatformMotion`].
fn declared(motion: &PlatformMotion, size: f64) -> Option<Declared> {
    let e = |i: usize| -> Vec3 { std::array::from_fn(|k| f64::from(u8::from(k == i))) };
    match motion {
        PlatformMotion::Pose => Some((
            (0..6)
                .map(|i| std::array::from_fn(|k| f64::from(u8::from(k == i))))
                .collect(),
            "pose",
            "moves it freely",
        )),
        PlatformMotion::Orientation { centre } => Some((
            (0..3)
                .map(|i| revolute(&scaled(centre, size), &e(i)))
                .collect(),
            "orientation",
            "only turns it about the centre",
        )),
        PlatformMotion::Translation { .. } => Some((
            (0..3).map(|i| prismatic(&e(i))).collect(),
            "translation",
            "holds its orientation fixed",
        )),
        // The carrier translates (the tool's turn is the shaft leg's own, past the tool's
        // revolute: that leg constrains the carrier in nothing).
        PlatformMotion::Schoenflies { .. } => Some((
            (0..3).map(|i| prismatic(&e(i))).collect(),
            "schoenflies",
            "holds the carrier's orientation fixed",
        )),
        // A point platform has no orientation: its legs end in revolutes about the plane normal
        // at the point, whose spin of the "platform" is idle, and a point's motion is not a
        // rigid body's twist. The planar five-bar's legs are checked by their type instead
        // (every axis along z).
        PlatformMotion::PlanarPoint { .. } => None,
        // A 1T2R platform's S is built from the legs' own plane constraints
        // (runtime/src/parallel/noc/parasitic.rs): with the leg geometry its leg-type check
        // requires (each revolute axis perpendicular to its rail, the S centre in the
        // revolute's plane) the legs allow exactly its span, and the check would compare the
        // legs with themselves.
        PlatformMotion::HeaveTilt { .. } => None,
        // In-plane translations and the turn about the plane normal (through any point: with
        // the translations they span the same).
        PlatformMotion::PlanarPose { .. } => Some((
            vec![
                prismatic(&e(0)),
                prismatic(&e(1)),
                revolute(&[0.0; 3], &e(2)),
            ],
            "planar_pose",
            "keeps it in its plane, turning only about the plane's normal",
        )),
    }
}

/// The declared twists, the `coordinates` word and what the motion does to the platform.
type Declared = (Vec<Screw>, &'static str, &'static str);

/// The twists the joints of leg `li` allow the platform at home (size-scaled): its joint screws
/// and those of its end, with a parallelogram's two rods in place of its equivalent rod's
/// U and S.
fn leg_twists(
    tree: &Tree<'_>,
    axes: &Axes,
    pm: &ParallelModel,
    li: usize,
    size: f64,
) -> Vec<Screw> {
    let leg = &pm.legs[li];
    let c = tree.closing[li];
    let j = &tree.spec.joints[c];
    let poses = leg_home_poses(leg);
    let tip = poses.last().copied().unwrap_or(Transform::IDENTITY);
    let frame = tree.frame_in_tip(c);
    let end = scaled(&tip.apply(&frame.translation), size);
    let pg = tree.spec.parallelograms.iter().position(|n| *n == j.name);
    // A parallelogram's equivalent rod hangs from a U at the elbow: its two model joints.
    let keep = match pg {
        Some(_) => leg.joints.len().saturating_sub(2),
        None => leg.joints.len(),
    };
    let mut out: Vec<Screw> = leg.joints[..keep]
        .iter()
        .zip(&poses)
        .map(|(joint, pose)| {
            let e = unit(&mat_vec(&pose.rotation, &joint.axis));
            match joint.kind {
                JointKind::Revolute => revolute(&scaled(&pose.translation, size), &e),
                JointKind::Prismatic => prismatic(&e),
            }
        })
        .collect();
    if let Some(i) = pg {
        // The two rods, ball to ball, each a force along itself on the distal bar: the pair
        // allows the 4-dim reciprocal of the two forces relative to the elbow (the rods' idle
        // spins move nothing).
        let (Some(u), Some(first)) = (poses.get(keep), leg.joints.get(keep)) else {
            return out;
        };
        let elbow = scaled(&u.translation, size);
        let a = unit(&mat_vec(&u.rotation, &first.axis));
        let d = unit(&[end[0] - elbow[0], end[1] - elbow[1], end[2] - elbow[2]]);
        let half = tree
            .spec
            .parallelogram_widths
            .get(i)
            .copied()
            .unwrap_or(0.0)
            / 2.0
            / size;
        let rods: Vec<Screw> = [-half, half]
            .iter()
            .map(|s| {
                let q = [
                    elbow[0] + s * a[0],
                    elbow[1] + s * a[1],
                    elbow[2] + s * a[2],
                ];
                let m = geom::cross(&q, &d);
                [m[0], m[1], m[2], d[0], d[1], d[2]]
            })
            .collect();
        out.extend(reciprocal(&rods));
        return out;
    }
    let rot = mat_mul(&tip.rotation, &frame.rotation);
    match (j.kind, leg.end) {
        (Kind::Universal, _) => {
            for ax in axes.get(c).into_iter().flatten() {
                out.push(revolute(&end, &unit(&mat_vec(&rot, ax))));
            }
        }
        // A revolute into the platform at a point (a planar leg's end, a `LegEnd::Spherical`
        // point in the model): its own axis.
        (Kind::Revolute, LegEnd::Spherical { .. }) => {
            for ax in axes.get(c).into_iter().flatten().take(1) {
                out.push(revolute(&end, &unit(&mat_vec(&rot, ax))));
            }
        }
        (_, LegEnd::Revolute { on_leg, .. }) => {
            out.push(revolute(&end, &unit(&mat_vec(&tip.rotation, &on_leg))));
        }
        (_, LegEnd::Spherical { .. }) => {
            for k in 0..3 {
                let e: Vec3 = std::array::from_fn(|i| f64::from(u8::from(i == k)));
                out.push(revolute(&end, &e));
            }
        }
    }
    out
}

fn direction(v: &[f64]) -> String {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    // The sign that makes the largest component positive: one way of naming an axis.
    let big = v
        .iter()
        .fold(0.0f64, |b, x| if x.abs() > b.abs() { *x } else { b });
    let s = if big < 0.0 { -1.0 } else { 1.0 } / n.max(f64::MIN_POSITIVE);
    let c: Vec<String> = v
        .iter()
        .map(|x| {
            let r = (s * x * 1e3).round() / 1e3;
            format!("{}", if r == 0.0 { 0.0 } else { r })
        })
        .collect();
    format!("({})", c.join(", "))
}

/// `a`, `a and b`, `a, b and c`.
fn list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The platform's allowed twists at home against the declared motion's; an error at
/// `[platform] coordinates` when they differ.
pub(super) fn check_declared_motion(
    tree: &Tree<'_>,
    axes: &Axes,
    ps: &PlatformSpec,
    pm: &ParallelModel,
    diags: &mut Diagnostics,
) {
    let size = pm.size();
    let Some((declared, word, holds)) = declared(&pm.motion, size) else {
        return;
    };
    let declared = span(&declared);
    let wrenches: Vec<Screw> = (0..pm.legs.len().min(tree.closing.len()))
        .flat_map(|li| reciprocal(&leg_twists(tree, axes, pm, li, size)))
        .collect();
    let allowed = reciprocal(&wrenches);
    let missing = span(&outside(&declared, &allowed));
    let extra = span(&outside(&allowed, &declared));
    if missing.is_empty() && extra.is_empty() {
        return;
    }
    let mut parts: Vec<String> = Vec::new();
    if !extra.is_empty() {
        let mut turns: Vec<String> = Vec::new();
        let mut moves: Vec<String> = Vec::new();
        for t in &extra {
            if t[..3].iter().map(|x| x * x).sum::<f64>().sqrt() > 1e-6 {
                turns.push(direction(&t[..3]));
            } else {
                moves.push(direction(&t[3..]));
            }
        }
        let mut what: Vec<String> = Vec::new();
        if !turns.is_empty() {
            what.push(format!("rotate about {}", list(&turns)));
        }
        if !moves.is_empty() {
            what.push(format!("translate along {}", list(&moves)));
        }
        parts.push(format!(
            "the legs let the platform {} but coordinates = \"{word}\" {holds}",
            what.join(" and ")
        ));
    }
    if !missing.is_empty() {
        parts.push(format!(
            "the legs allow only {} of the declared {} motions",
            declared.len() - missing.len(),
            declared.len()
        ));
    }
    let msg = parts.join("; and ");
    // Too few motions with legs of the right type: a leg whose own joint screws are dependent
    // at home (two axes in line, a leg of zero length) has lost a freedom there. Not for a
    // parallelogram leg, whose rods' twists are not joint screws.
    let singular_leg = (!missing.is_empty())
        .then(|| {
            (0..pm.legs.len().min(tree.closing.len())).find_map(|li| {
                let c = tree.closing[li];
                let name = &tree.spec.joints[c].name;
                if tree.spec.parallelograms.contains(name) {
                    return None;
                }
                let t = leg_twists(tree, axes, pm, li, size);
                let r = span(&t).len();
                (r < t.len()).then(|| (name.clone(), t.len(), r))
            })
        })
        .flatten();
    let hint = match singular_leg {
        Some((name, n, r)) => format!(
            "leg \"{name}\" is at a singularity of its own at home: its {n} joint screws span only {r} motions (two of its axes in line, or a leg of zero length); choose a platform.home away from it, or change the leg"
        ),
        None => {
            let examples = match word {
                "translation" => {
                    " (a Delta's [[parallelogram]]s, or Tsai's 3-UPU with the base U's first axis parallel to the platform U's second and the inner axes parallel)"
                }
                "orientation" => " (every joint axis through the centre)",
                _ => "",
            };
            format!(
                "the platform's motion is what the legs' constraint wrenches leave it: coordinates = \"{word}\" needs legs that allow exactly that{examples}; choose the coordinates of the motion the legs allow, or change the legs (docs/spec.md, \"The declared motion\")"
            )
        }
    };
    diags.push(
        Diagnostic::error(format!("{msg} (at home, by reciprocal screws)"))
            .with_key("platform.coordinates")
            .with_span(ps.coordinates_span.clone())
            .with_hint(hint),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dot(a: &Screw, b: &Screw) -> f64 {
        (0..6).map(|i| a[i] * b[i]).sum()
    }

    /// `t` lies in the span of the orthonormal `basis`.
    fn inside(t: &Screw, basis: &[Screw]) -> bool {
        outside(&[*t], basis)[0].iter().all(|x| x.abs() < 1e-12)
    }

    /// A leg of Tsai's 3-UPU (outer axes `e₀` parallel, inner axes `e₁` parallel) is held by one
    /// couple, along `e₀ × e₁` (Tsai, Robot Analysis, §4.7): `[m; f] = [e₀ × e₁; 0]`.
    #[test]
    fn a_upu_leg_is_held_by_one_couple() {
        let (b, t) = ([0.3, 0.0, 0.0], [0.15, 0.1, 0.4]);
        let e0 = [0.0, 1.0, 0.0];
        let s = unit(&[t[0] - b[0], t[1] - b[1], t[2] - b[2]]);
        let e1 = unit(&geom::cross(&e0, &s));
        let twists = [
            revolute(&b, &e0),
            revolute(&b, &e1),
            prismatic(&s),
            revolute(&t, &e1),
            revolute(&t, &e0),
        ];
        let w = reciprocal(&twists);
        assert_eq!(w.len(), 1);
        let c = geom::cross(&e0, &e1);
        let couple = [c[0], c[1], c[2], 0.0, 0.0, 0.0];
        assert!(inside(&couple, &w), "{w:?}");
        // The platform U's axes swapped leave the couple at home (the axis order is checked apart).
        let swapped = [
            twists[0],
            twists[1],
            twists[2],
            revolute(&t, &e0),
            revolute(&t, &e1),
        ];
        assert!(inside(&couple, &reciprocal(&swapped)));
    }

    /// A parallelogram's two rods (forces along `d` through `E ± (w/2) a`) allow the distal bar
    /// the rotations about `a` and `d` through `E` and the translations along `a` and `a × d`,
    /// but not the rotation about `a × d` nor the translation along `d`.
    #[test]
    fn a_parallelogram_allows_four_motions() {
        let (e, a, d) = ([0.5, 0.2, -0.1], [0.0, 1.0, 0.0], unit(&[-0.3, 0.0, -1.0]));
        let n = geom::cross(&a, &d);
        let rods: Vec<Screw> = [-0.05, 0.05]
            .iter()
            .map(|h| {
                let q = [e[0] + h * a[0], e[1] + h * a[1], e[2] + h * a[2]];
                let m = geom::cross(&q, &d);
                [m[0], m[1], m[2], d[0], d[1], d[2]]
            })
            .collect();
        let allowed = reciprocal(&rods);
        assert_eq!(allowed.len(), 4);
        for t in [
            revolute(&e, &a),
            revolute(&e, &d),
            prismatic(&a),
            prismatic(&n),
        ] {
            assert!(inside(&t, &allowed));
        }
        for t in [revolute(&e, &n), prismatic(&d)] {
            assert!(!inside(&t, &allowed));
        }
        // The allowed twists do no work against either rod force.
        for t in &allowed {
            for r in &rods {
                assert!(dot(t, r).abs() < 1e-12);
            }
        }
    }
}

//! The `[platform]` table of a parallel mechanism: `body`, `coordinates`, `home`, `centre`.

use std::ops::Range;

use runtime::model::Transform;

use super::keys::PLATFORM_KEYS;
use super::{Reader, Val, get};
use crate::spec::ir::{Coordinates, Placement, PlatformSpec};
use crate::spec::suggest_hint;

impl Reader<'_> {
    /// The `[platform]` table of a parallel mechanism.
    /// `Some` whenever the key is present, so that the spec is treated as a parallel one (a
    /// platform that could not be read has no body, and lowering stops early).
    pub(super) fn platform(&mut self, v: &Val<'_>, span: Range<usize>) -> Option<PlatformSpec> {
        let mut p = PlatformSpec {
            span: Some(span.clone()),
            body: None,
            body_span: Some(span.clone()),
            coordinates: None,
            coordinates_span: Some(span.clone()),
            home: Transform::IDENTITY,
            home_span: Some(span.clone()),
            centre: None,
            centre_span: Some(span.clone()),
        };
        let Some(t) = self.table(v, "platform") else {
            return Some(p);
        };
        self.unknown_keys(t, PLATFORM_KEYS, "platform");
        match get(t, "body") {
            None => self.missing(
                "body",
                "platform",
                span.clone(),
                "the moving platform is one of the [[body]] entries: body = \"<its name>\"",
            ),
            Some(b) => {
                p.body_span = Some(b.span());
                p.body = self.string(b, "platform.body");
            }
        }
        match get(t, "coordinates") {
            None => self.missing(
                "coordinates",
                "platform",
                span.clone(),
                "coordinates = \"pose\" (6 DOF) or \"orientation\" (3 DOF about a fixed centre)",
            ),
            Some(c) => {
                p.coordinates_span = Some(c.span());
                p.coordinates = self.coordinates(c);
            }
        }
        if let Some(h) = get(t, "home") {
            p.home_span = Some(h.span());
            if let Some(Placement::Origin(x)) = self.origin(h, "platform.home") {
                p.home = x;
            }
        }
        if let Some(c) = get(t, "centre") {
            p.centre_span = Some(c.span());
            p.centre = self.triple(c, "platform.centre", false);
        }
        Some(p)
    }

    /// `platform.coordinates`: `"pose"`, `"orientation"`, `"planar"`, `"translation"` or
    /// `"planar_pose"`, `"heave_tilt"` or `"schoenflies"`.
    fn coordinates(&mut self, c: &Val<'_>) -> Option<Coordinates> {
        let s = self.string(c, "platform.coordinates")?;
        match s.as_str() {
            "pose" => Some(Coordinates::Pose),
            "orientation" => Some(Coordinates::Orientation),
            "planar" => Some(Coordinates::Planar),
            "translation" => Some(Coordinates::Translation),
            "planar_pose" => Some(Coordinates::PlanarPose),
            "heave_tilt" => Some(Coordinates::HeaveTilt),
            "schoenflies" => Some(Coordinates::Schoenflies),
            other => {
                let hint = suggest_hint(
                    &other.to_ascii_lowercase(),
                    &[
                        "pose",
                        "orientation",
                        "planar",
                        "translation",
                        "planar_pose",
                        "heave_tilt",
                        "schoenflies",
                    ],
                )
                .unwrap_or_else(|| {
                    "coordinates is \"pose\" (position and orientation, 6 DOF), \"orientation\" (rotation about a fixed centre, 3 DOF), \"planar\" (a point in a plane, 2 DOF), \"translation\" (position, orientation fixed, 3 DOF) \"planar_pose\" (position in a plane and rotation about its normal, 3 DOF) \"heave_tilt\" (heave and two tilts with parasitic motion, 3 DOF: a 3-PRS or 3-RPS head) or \"schoenflies\" (a translating carrier and a tool turning about z, 4 DOF: a 4-axis Delta)".into()
                });
                self.err(
                    format!("unknown platform coordinates {other:?}"),
                    "platform.coordinates",
                    c.span(),
                )
                .hint = Some(hint);
                None
            }
        }
    }
}

//! The keys each table allows, and the first check every table runs: its unknown keys, each
//! with a suggestion (a common misnomer's meaning, the closest allowed key, or the list).

use toml::de::DeTable;

use super::Reader;
use crate::spec::suggest_hint;

pub(super) const TOP_KEYS: &[&str] = &[
    "mechanism",
    "platform",
    "scene",
    "body",
    "joint",
    "spring",
    "parallelogram",
    "parameters",
    "pattern",
];
pub(super) const PATTERN_KEYS: &[&str] = &[
    "name",
    "copies",
    "axis",
    "angle",
    "parameters",
    "body",
    "joint",
    "parallelogram",
    "spring",
];
pub(super) const PARALLELOGRAM_KEYS: &[&str] = &[
    "name",
    "parent",
    "child",
    "elbow",
    "platform_point",
    "length",
    "elbow_width",
    "platform_width",
    "rod_mass",
    "rod_com",
    "rod_inertia",
    "cross",
];
pub(super) const SPRING_KEYS: &[&str] = &[
    "name",
    "body_a",
    "point_a",
    "body_b",
    "point_b",
    "stiffness",
    "rest_length",
    "damping",
];
pub(super) const SCENE_KEYS: &[&str] = &[
    "functions",
    "gravity",
    "point_mass",
    "massless",
    "payload",
    "locked",
    "friction",
    "rotor_inertia",
    "armature",
    "coulomb_velocity",
    "snap",
    "parameters",
    "runtime_inertia",
    "delta_model",
    "forearm_split",
    "frames",
];
pub(super) const PAYLOAD_KEYS: &[&str] = &["body", "mass", "com", "inertia"];
pub(super) const PLATFORM_KEYS: &[&str] = &["body", "coordinates", "home", "centre"];
pub(super) const MECH_KEYS: &[&str] = &["name", "gravity", "source"];
pub(super) const BODY_KEYS: &[&str] = &["name", "mass", "com", "inertia", "inertia_rpy"];
/// A universal joint's `cross`: a body's inertial keys.
pub(super) const CROSS_KEYS: &[&str] = &["mass", "com", "inertia", "inertia_rpy"];
pub(super) const INERTIA_KEYS: &[&str] = &["ixx", "iyy", "izz", "ixy", "ixz", "iyz"];
pub(super) const JOINT_KEYS: &[&str] = &[
    "name",
    "kind",
    "parent",
    "child",
    "origin",
    "axis",
    "axes",
    "dh",
    "mdh",
    "actuated",
    "child_origin",
    "home",
    "damping",
    "friction",
    "armature",
    "cross",
    "limit",
];
/// A joint's `limit` table.
pub(super) const LIMIT_KEYS: &[&str] = &["lower", "upper", "velocity"];
pub(super) const ORIGIN_KEYS: &[&str] = &["xyz", "rpy", "quat", "matrix", "axis_angle"];
/// The ways an origin gives its rotation (at most one).
pub(super) const ROTATION_KEYS: &[&str] = &["rpy", "quat", "matrix", "axis_angle"];
pub(super) const DH_KEYS: &[&str] = &["a", "alpha", "d", "theta"];

/// Common misnomers: (written, meant).
const ALIASES: &[(&str, &str)] = &[
    ("type", "kind"),
    ("bodies", "body"),
    ("link", "body"),
    ("links", "body"),
    ("joints", "joint"),
    ("inertial", "inertia"),
    ("center_of_mass", "com"),
    ("centre_of_mass", "com"),
    ("cog", "com"),
    ("robot", "mechanism"),
    ("g", "gravity"),
    ("center", "centre"),
    ("actuator", "actuated"),
    ("active", "actuated"),
    ("viscous", "damping"),
    ("coulomb", "friction"),
    ("rotor_inertia", "armature"),
];

impl Reader<'_> {
    /// Reports keys of `t` not in `allowed`, with the closest allowed key as hint.
    pub(super) fn unknown_keys(&mut self, t: &DeTable<'_>, allowed: &[&str], path: &str) {
        let mut keys: Vec<_> = t.iter().map(|(k, _)| k).collect();
        keys.sort_by_key(|k| k.span().start);
        for k in keys {
            let name = k.get_ref().as_ref();
            if allowed.contains(&name) {
                continue;
            }
            let alias = ALIASES
                .iter()
                .find(|(w, m)| *w == name && allowed.contains(m))
                .map(|(_, m)| format!("did you mean \"{m}\"?"));
            let hint = alias
                .or_else(|| suggest_hint(name, allowed))
                .unwrap_or_else(|| {
                    format!(
                        "valid keys here: {}",
                        allowed
                            .iter()
                            .map(|a| format!("\"{a}\""))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                });
            let key = if path.is_empty() {
                name.to_owned()
            } else {
                format!("{path}.{name}")
            };
            self.err(format!("unknown key \"{name}\""), &key, k.span())
                .hint = Some(hint);
        }
    }
}

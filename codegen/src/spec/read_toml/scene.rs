//! The `[scene]` table: which functions, gravity, the bodies' mass overrides, the payload,
//! drives (friction, rotor inertia), run-time parameters, snapping, locked joints and the
//! frames whose kinematics the module offers.

use runtime::model::Vec3;
use toml::de::{DeTable, DeValue};

use super::keys::{PAYLOAD_KEYS, SCENE_KEYS};
use super::{Reader, Val, get};
use crate::diag::Diagnostic;
use crate::spec::ir::{Named, Payload, RuntimeInertia, SceneSpec};

/// The smallest `[scene] coulomb_velocity`: the law `c·q̇/√(q̇² + v_s²)` needs `v_s²` above
/// zero in the generated code's scalar type (`f32` too), or it is `0/0 = NaN` at rest
/// (`1e-200` gave `inverse_dynamics(q, 0, 0)` NaN).
const MIN_COULOMB_VELOCITY: f64 = 1e-12;

impl Reader<'_> {
    /// The keys of `[scene]` (table `t`) in their fixed order; `gravity` overrides the
    /// mechanism's.
    pub(super) fn scene(&mut self, t: &DeTable<'_>, scene: &mut SceneSpec, gravity: &mut Vec3) {
        self.unknown_keys(t, SCENE_KEYS, "scene");
        if let Some(f) = get(t, "functions") {
            scene.functions = self.names(f, "scene.functions");
        }
        if let Some(g) = get(t, "gravity")
            && let Some(g) = self.triple(g, "scene.gravity", false)
        {
            *gravity = g;
        }
        if let Some(b) = get(t, "point_mass") {
            scene.point_mass = self.names(b, "scene.point_mass").unwrap_or_default();
        }
        if let Some(b) = get(t, "massless") {
            scene.massless = self.names(b, "scene.massless").unwrap_or_default();
        }
        if let Some(p) = get(t, "payload") {
            scene.payload = self.payload(p);
        }
        if let Some(v) = get(t, "friction") {
            scene.friction = self.boolean(v, "scene.friction").unwrap_or(false);
        }
        if let Some(v) = get(t, "rotor_inertia") {
            scene.rotor_inertia = self.boolean(v, "scene.rotor_inertia").unwrap_or(false);
        }
        if let Some(v) = get(t, "armature") {
            self.armature(v, scene);
        }
        if let Some(v) = get(t, "coulomb_velocity") {
            self.coulomb_velocity(v, scene);
        }
        if let Some(v) = get(t, "parameters") {
            self.parameters(v, scene);
        }
        if let Some(v) = get(t, "runtime_inertia") {
            self.runtime_inertia(v, scene);
        }
        if let Some(v) = get(t, "snap") {
            self.snap(v, scene);
        }
        if let Some(l) = get(t, "locked") {
            self.locked(l, scene);
        }
        if let Some(v) = get(t, "delta_model") {
            self.delta_model(v, scene);
        }
        if let Some(v) = get(t, "forearm_split") {
            self.forearm_split(v, scene);
        }
        if let Some(v) = get(t, "frames")
            && let Some(names) = self.names(v, "scene.frames")
        {
            scene.frames = Some((names, Some(v.span())));
        }
    }

    /// `scene.delta_model`: `"exact"` (the default) or `"codourey"`.
    fn delta_model(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let Some(x) = self.string(v, "scene.delta_model") else {
            return;
        };
        match x.as_str() {
            "exact" => {}
            "codourey" => scene.codourey = Some(Some(v.span())),
            _ => self.diags.push(
                Diagnostic::error(format!("unknown Delta model {x:?}"))
                    .with_key("scene.delta_model")
                    .with_span(Some(v.span()))
                    .with_hint("\"exact\" (the default: every rod as the spec gives it) or \"codourey\" (Codourey's simplified Delta: the forearms' mass lumped at the elbows and the platform, the upper arms thin rods)"),
            ),
        }
    }

    /// `scene.forearm_split`: a fraction in [0, 1].
    fn forearm_split(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let Some(x) = self.number(v, "scene.forearm_split") else {
            return;
        };
        if (0.0..=1.0).contains(&x) {
            scene.forearm_split = Some((x, Some(v.span())));
        } else {
            self.diags.push(
                Diagnostic::error(format!("`forearm_split` = {x} is not in [0, 1]"))
                    .with_key("scene.forearm_split")
                    .with_span(Some(v.span()))
                    .with_hint("the fraction of each forearm pair's mass lumped at the elbow (the rest goes to the platform); Codourey's is 2/3"),
            );
        }
    }

    /// `scene.coulomb_velocity`: a positive number, at least [`MIN_COULOMB_VELOCITY`].
    fn coulomb_velocity(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let Some(x) = self.number(v, "scene.coulomb_velocity") else {
            return;
        };
        if x >= MIN_COULOMB_VELOCITY && x.is_finite() {
            scene.coulomb_velocity = x;
        } else {
            self.diags.push(
                Diagnostic::error(format!(
                    "`coulomb_velocity` must be a positive number, at least {MIN_COULOMB_VELOCITY:e}"
                ))
                    .with_key("scene.coulomb_velocity")
                    .with_span(Some(v.span()))
                    .with_hint("the speed scale v_s of the Coulomb law c·q̇/√(q̇² + v_s²), in rad/s or m/s; the default is 1e-4"),
            );
        }
    }

    /// `scene.parameters`: `"constants"` or `"runtime"`.
    fn parameters(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let Some(x) = self.string(v, "scene.parameters") else {
            return;
        };
        match x.as_str() {
            "constants" => {}
            "runtime" => {
                scene.runtime_params = true;
                scene.runtime_params_span = Some(v.span());
            }
            _ => self.diags.push(
                Diagnostic::error(format!("unknown parameter mode {x:?}"))
                    .with_key("scene.parameters")
                    .with_span(Some(v.span()))
                    .with_hint("\"constants\" (the default: folded into the code) or \"runtime\" (a generated `Params` struct with the payload and the joints' damping, friction and armature, passed to every function)"),
            ),
        }
    }

    /// `scene.runtime_inertia`: `"all"` or a list of body names.
    fn runtime_inertia(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let span = Some(v.span());
        let which = match v.get_ref() {
            DeValue::String(x) if x.as_ref() == "all" => Some(RuntimeInertia::All),
            DeValue::String(x) => {
                self.diags.push(
                    Diagnostic::error(format!("unknown `runtime_inertia` value {:?}", x.as_ref()))
                        .with_key("scene.runtime_inertia")
                        .with_span(span.clone())
                        .with_hint("write \"all\" (every body with mass) or a list of body names, e.g. [\"link5\", \"link6\"]"),
                );
                None
            }
            _ => self
                .names(v, "scene.runtime_inertia")
                .map(RuntimeInertia::Bodies),
        };
        scene.runtime_inertia = which.map(|w| (w, span));
    }

    /// `scene.snap`: a tolerance in (0, 0.01].
    fn snap(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let Some(x) = self.number(v, "scene.snap") else {
            return;
        };
        if crate::spec::is_snap_tolerance(x) {
            scene.snap = Some(x);
        } else {
            self.diags.push(
                Diagnostic::error("`snap` must be a tolerance in (0, 0.01]")
                    .with_key("scene.snap")
                    .with_span(Some(v.span()))
                    .with_hint(crate::spec::SNAP_HINT),
            );
        }
    }

    /// `scene.locked`: a table of joint names and angles.
    fn locked(&mut self, l: &Val<'_>, scene: &mut SceneSpec) {
        let Some(lt) = self.table(l, "scene.locked") else {
            return;
        };
        for (k, v) in lt.iter() {
            let key = format!("scene.locked.{}", k.get_ref());
            if let Some(x) = self.angle(v, &key) {
                scene.locked.push((
                    Named {
                        name: k.get_ref().to_string(),
                        key,
                        span: Some(k.span()),
                    },
                    x,
                ));
            }
        }
    }

    /// `scene.armature`: a table of joint names and non-negative numbers (kg·m² or kg).
    fn armature(&mut self, v: &Val<'_>, scene: &mut SceneSpec) {
        let Some(t) = self.table(v, "scene.armature") else {
            return;
        };
        for (k, v) in t.iter() {
            let key = format!("scene.armature.{}", k.get_ref());
            let Some(x) = self.number(v, &key) else {
                continue;
            };
            if !(x.is_finite() && x >= 0.0) {
                self.diags.push(
                    Diagnostic::error(format!("armature {x} is not a finite, non-negative number"))
                        .with_key(key)
                        .with_span(Some(v.span()))
                        .with_hint("the rotor inertia reflected to the joint, I_a = J_rotor·N², in kg·m² (kg for a prismatic joint)"),
                );
                continue;
            }
            scene.armature.push((
                Named {
                    name: k.get_ref().to_string(),
                    key,
                    span: Some(k.span()),
                },
                x,
            ));
        }
    }

    /// `[scene] payload`: `body` (required), `mass`, `com`, `inertia` (default zero).
    fn payload(&mut self, v: &Val<'_>) -> Option<Payload> {
        let path = "scene.payload";
        let t = self.table(v, path)?;
        self.unknown_keys(t, PAYLOAD_KEYS, path);
        // Every entry is read before any is given up on, so that each mistake is reported.
        let b = get(t, "body");
        let name = match b {
            Some(b) => self.string(b, "scene.payload.body"),
            None => {
                self.missing(
                    "body",
                    path,
                    v.span(),
                    "the body that carries the payload: body = \"<its name>\"",
                );
                None
            }
        };
        let mass = match get(t, "mass") {
            Some(m) => self.number(m, "scene.payload.mass"),
            None => Some(0.0),
        };
        let com = match get(t, "com") {
            Some(c) => self.triple(c, "scene.payload.com", false),
            None => Some([0.0; 3]),
        };
        let inertia = match get(t, "inertia") {
            Some(i) => self.inertia(i, "scene.payload.inertia"),
            None => Some([[0.0; 3]; 3]),
        };
        let (b, name, mass, com, inertia) = (b?, name?, mass?, com?, inertia?);
        Some(Payload {
            body: Named {
                name,
                key: "scene.payload.body".into(),
                span: Some(b.span()),
            },
            mass,
            com,
            inertia,
            mass_span: Some(get(t, "mass").unwrap_or(b).span()),
            inertia_span: Some(get(t, "inertia").unwrap_or(b).span()),
        })
    }
}

//! The base regressor of either kind of spec the identification tools take: a tree's
//! ([`TreeRegressor`]: joints, `q, q̇, q̈`) or a platform's ([`PlatformRegressor`]: actuators,
//! `x, u, u̇`) or a closed loop's ([`ClosedRegressor`]: independent coordinates, `x, u, u̇`
//! with `x` assembled from the independent `q`), so that `identify` and `excite` are written
//! once.

use codegen::spec::Mechanism;

mod stack;

use super::closed_regressor::ClosedRegressor;
use super::platform_regressor::{NoRegressor, PlatformRegressor};
use super::samples::{Columns, Samples};
use super::tree_regressor::TreeRegressor;

/// A spec's base regressor.
pub enum Regressor {
    /// A tree (serial or branched chain).
    Tree(Box<TreeRegressor>),
    /// A parallel mechanism (`[platform]`).
    Platform(Box<PlatformRegressor>),
    /// A closed-loop mechanism in joint coordinates.
    Closed(Box<ClosedRegressor>),
}

impl Regressor {
    /// Load a spec's text (with its `[scene]`, or for a URDF the `sidecar` scene file, as
    /// generation reads it): its regressor and the loader's rendered warnings. The error is
    /// rendered text (exit code 2).
    pub fn compile(
        name: &str,
        source: &str,
        sidecar: Option<codegen::spec::SceneFile>,
    ) -> Result<(Regressor, String), String> {
        Self::compile_with_limits(name, source, sidecar).map(|(r, w, _)| (r, w))
    }

    /// [`Self::compile`], with the tree joints' limits as the spec writes them
    /// ([`codegen::spec::Loaded::limits`]) in the order of [`Self::dof`] (`None`: no limit;
    /// all `None` for platforms and closed loops).
    pub fn compile_with_limits(
        name: &str,
        source: &str,
        sidecar: Option<codegen::spec::SceneFile>,
    ) -> Result<(Regressor, String, Vec<Option<codegen::spec::JointLimit>>), String> {
        let overrides = codegen::spec::SceneOverrides {
            sidecar,
            ..Default::default()
        };
        let loaded = codegen::spec::load(name, source, &overrides).map_err(|d| d.render())?;
        let warnings = if loaded.warnings.is_empty() {
            String::new()
        } else {
            loaded.warnings.render()
        };
        let limits: Vec<Option<codegen::spec::JointLimit>> = match &loaded.mechanism {
            Mechanism::Tree(m) => m
                .joints
                .iter()
                .map(|j| loaded.limits.iter().find(|l| l.joint == j.name).cloned())
                .collect(),
            _ => Vec::new(),
        };
        let r = match loaded.mechanism {
            Mechanism::Tree(m) => Regressor::Tree(Box::new(TreeRegressor::new(m))),
            Mechanism::Parallel(m) => Regressor::Platform(Box::new(PlatformRegressor::new(m)?)),
            Mechanism::Closed(m) => Regressor::Closed(Box::new(ClosedRegressor::new(m)?)),
        };
        let mut limits = limits;
        limits.resize(r.dof(), None);
        Ok((r, warnings, limits))
    }

    /// The mechanism's name.
    pub fn mechanism(&self) -> &str {
        match self {
            Regressor::Tree(r) => &r.model.name,
            Regressor::Platform(r) => &r.model.name,
            Regressor::Closed(r) => &r.model.name,
        }
    }

    /// Efforts per sample (joints or actuators).
    pub fn dof(&self) -> usize {
        match self {
            Regressor::Tree(r) => r.dof(),
            Regressor::Platform(r) => r.dof(),
            Regressor::Closed(r) => r.dof(),
        }
    }

    /// Number of base parameters.
    pub fn nbp(&self) -> usize {
        self.values().len()
    }

    /// Number of standard parameters (the columns the base parameters group).
    pub fn standard_count(&self) -> usize {
        match self {
            Regressor::Tree(r) => r.grouping.standard_names.len(),
            Regressor::Platform(r) => r.grouping.standard_names.len(),
            Regressor::Closed(r) => r.grouping.standard_names.len(),
        }
    }

    /// The kind of mechanism: `tree`, `platform` or `closed loop`.
    pub fn kind(&self) -> &'static str {
        match self {
            Regressor::Tree(_) => "tree",
            Regressor::Platform(_) => "platform",
            Regressor::Closed(_) => "closed loop",
        }
    }

    /// `BASE_PARAMETER_NAMES`.
    pub fn names(&self) -> &[String] {
        match self {
            Regressor::Tree(r) => &r.names,
            Regressor::Platform(r) => &r.names,
            Regressor::Closed(r) => &r.names,
        }
    }

    /// `BASE_PARAMETERS` of the spec.
    pub fn values(&self) -> &[f64] {
        match self {
            Regressor::Tree(r) => &r.values,
            Regressor::Platform(r) => &r.values,
            Regressor::Closed(r) => &r.values,
        }
    }

    /// What the efforts act at: `"joint"` or `"actuator"`.
    pub fn effort_kind(&self) -> &'static str {
        match self {
            Regressor::Tree(_) | Regressor::Closed(_) => "joint",
            Regressor::Platform(_) => "actuator",
        }
    }

    /// The names of the efforts' joints (the actuated joints of a platform, the independent
    /// joints of a closed loop).
    pub fn effort_names(&self) -> Vec<String> {
        match self {
            Regressor::Tree(r) => r.model.joints.iter().map(|j| j.name.clone()).collect(),
            Regressor::Platform(r) => r.actuators(),
            Regressor::Closed(r) => r.independent(),
        }
    }

    /// The columns of a measurement file (a closed loop's independent coordinates `q`).
    pub fn columns(&self) -> Columns {
        match self {
            Regressor::Tree(_) => Columns::joints(&self.effort_names()),
            Regressor::Closed(r) => Columns {
                kinds: ["q", "u", "ud", "tau"],
                counts: [r.dof(); 4],
                names: std::array::from_fn(|_| r.independent()),
                differentiable: true,
            },
            Regressor::Platform(r) => {
                let (n, nx) = (r.dof(), r.nx());
                Columns {
                    kinds: ["x", "u", "ud", "tau"],
                    counts: [nx, n, n, n],
                    names: [Vec::new(), Vec::new(), Vec::new(), r.actuators()],
                    differentiable: false,
                }
            }
        }
    }

    /// The columns of the measurement file `text`: [`Regressor::columns`], except that a
    /// closed loop's file whose header has `x1` gives all tree joint coordinates
    /// `x1..xNX, u1.., ud1.., tau1..`.
    pub fn columns_of(&self, text: &str) -> Columns {
        if let Regressor::Closed(r) = self {
            let header = text
                .lines()
                .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
                .unwrap_or("");
            if header.split(',').any(|h| h.trim() == "x1") {
                let n = r.dof();
                return Columns {
                    kinds: ["x", "u", "ud", "tau"],
                    counts: [r.nx(), n, n, n],
                    names: [Vec::new(), Vec::new(), Vec::new(), r.independent()],
                    differentiable: false,
                };
            }
        }
        self.columns()
    }

    /// Complete the positions read from `file`: a closed loop's independent coordinates are
    /// assembled into all `x`, each row by Newton from the previous row's configuration (the
    /// first from home); a row that does not assemble is an error at its line.
    pub fn assemble_positions(&self, file: &str, data: &mut Samples) -> Result<(), String> {
        let Regressor::Closed(r) = self else {
            return Ok(());
        };
        if data.q.first().is_none_or(|q| q.len() == r.nx()) {
            return Ok(());
        }
        let mut from: Option<Vec<f64>> = None;
        for (q, line) in data.q.iter_mut().zip(&data.lines) {
            let Some(x) = r.assemble(q, from.as_deref()) else {
                return Err(format!(
                    "error: {file}:{line}: the loops do not close at q = [{}] (Newton from the previous row's configuration fails: a position out of the mechanism's range, or a jump from the row before)",
                    q.iter()
                        .map(|v| format!("{v}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            };
            *q = x.clone();
            from = Some(x);
        }
        Ok(())
    }

    /// `Y` at positions `p`, speeds `v`, accelerations `a` into `out` (`DOF × NBP`,
    /// row-major); `buf` is scratch space. A tree always has one.
    pub fn rows(
        &self,
        p: &[f64],
        v: &[f64],
        a: &[f64],
        buf: &mut Vec<f64>,
        out: &mut [f64],
    ) -> Result<(), NoRegressor> {
        match self {
            Regressor::Tree(r) => {
                r.rows(p, v, a, buf, out);
                Ok(())
            }
            Regressor::Platform(r) => r.rows(p, v, a, buf, out),
            Regressor::Closed(r) => r.rows(p, v, a, buf, out),
        }
    }

    /// Whether coordinate `j` of a trajectory is a turn (a platform's angle, bounded by
    /// `--turn`) rather than a move (`--reach`); `None` for a tree's or a closed loop's joints
    /// (`--q-max`).
    pub fn turns(&self, j: usize) -> Option<bool> {
        match self {
            Regressor::Tree(_) | Regressor::Closed(_) => None,
            Regressor::Platform(r) => Some(super::platform_path::angular(r.model.motion, j)),
        }
    }

    /// The state at trajectory coordinates `d` (rates `dd`, `ddd`): a tree's `(q, q̇, q̈)`
    /// are the coordinates, a platform's `(x, u, u̇)` are around home
    /// ([`super::platform_path`]), a closed loop's independent coordinates are around home and
    /// `x` is assembled by Newton from `from` (the previous state's positions; home when
    /// `None`). `None` where a closed loop does not assemble.
    pub fn state(
        &self,
        d: &[f64],
        dd: &[f64],
        ddd: &[f64],
        from: Option<&[f64]>,
    ) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        match self {
            Regressor::Tree(_) => Some((d.to_vec(), dd.to_vec(), ddd.to_vec())),
            Regressor::Platform(r) => Some(super::platform_path::state(
                r.model.motion,
                &r.home,
                d,
                dd,
                ddd,
            )),
            Regressor::Closed(r) => {
                let q: Vec<f64> = r
                    .home_coordinates()
                    .iter()
                    .zip(d)
                    .map(|(h, d)| h + d)
                    .collect();
                Some((r.assemble(&q, from)?, dd.to_vec(), ddd.to_vec()))
            }
        }
    }

    /// The positions a measurement file has of the state's positions `p`: a closed loop's
    /// independent coordinates, the others' `p`.
    pub fn written_positions(&self, p: &[f64]) -> Vec<f64> {
        match self {
            Regressor::Closed(r) => r.coordinates(p),
            _ => p.to_vec(),
        }
    }

    /// The efforts by the runtime's own inverse dynamics (independent of the regressor);
    /// `None` where a platform's evaluator finds the state singular.
    pub fn inverse_dynamics(&self, p: &[f64], v: &[f64], a: &[f64]) -> Option<Vec<f64>> {
        match self {
            Regressor::Tree(r) => Some(r.inverse_dynamics(p, v, a)),
            Regressor::Platform(r) => r.inverse_dynamics(p, v, a),
            Regressor::Closed(r) => r.inverse_dynamics(p, v, a),
        }
    }

    /// The base parameters of another spec text of the same structure (its `[scene]`
    /// applied, or a URDF's `sidecar`), on this regressor's grouping.
    pub fn base_of_spec(
        &self,
        file: &str,
        text: &str,
        sidecar: Option<&codegen::spec::SceneFile>,
    ) -> Result<Vec<f64>, String> {
        let overrides = codegen::spec::SceneOverrides {
            sidecar: sidecar.cloned(),
            ..Default::default()
        };
        let loaded = codegen::spec::load(file, text, &overrides).map_err(|d| d.render())?;
        match (self, loaded.mechanism) {
            (Regressor::Tree(r), Mechanism::Tree(m)) => Ok(r.base_of(&m)),
            (Regressor::Platform(r), Mechanism::Parallel(m)) => Ok(r.base_of(&m)),
            (Regressor::Closed(r), Mechanism::Closed(m)) => Ok(r.base_of(&m)),
            _ => Err(format!("error: {file}: not the same kind of mechanism")),
        }
    }
}

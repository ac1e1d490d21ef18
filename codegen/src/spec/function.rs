//! The public functions a generated module offers, by name, and which of them `[scene]
//! functions` may choose for each kind of mechanism: the one list every stage reads.

use std::fmt;
use std::str::FromStr;

/// A public function of a generated module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Function {
    /// `mass_matrix`: the generalized inertia `I`.
    MassMatrix,
    /// `coriolis`: `C q̇` (trees).
    Coriolis,
    /// `gravity`: `−γ` (trees).
    Gravity,
    /// `inverse_dynamics`: the efforts of a motion.
    InverseDynamics,
    /// `forward_dynamics`: the accelerations of given efforts.
    ForwardDynamics,
    /// `friction`: the joints' friction efforts (trees with `[scene] friction`).
    Friction,
    /// `inverse_dynamics_derivatives`: `(∂τ/∂q, ∂τ/∂q̇)` (trees).
    InverseDynamicsDerivatives,
    /// `forward_dynamics_derivatives`: `(∂q̈/∂q, ∂q̈/∂q̇, I⁻¹)` (trees).
    ForwardDynamicsDerivatives,
    /// `regressor`: `Y(q, q̇, q̈)` over the base parameters, `τ = Y · BASE_PARAMETERS` (trees).
    Regressor,
    /// `frames`: the pose, Jacobian and `J̇ q̇` (`J̇ u`) of each frame `[scene] frames` names
    /// (trees, parallel platforms; a closed loop's body poses).
    Frames,
    /// `joint_rates`: every tree joint's rate (closed loops).
    JointRates,
    /// `actuator_rates`: `q̇ = A u`.
    ActuatorRates,
    /// `actuator_mass_matrix`: `A⁻ᵀ I A⁻¹`.
    ActuatorMassMatrix,
    /// `inverse_kinematics`: the actuated joint positions of `x`.
    InverseKinematics,
    /// `forward_kinematics`: `x` from the actuated joint positions.
    ForwardKinematics,
}

impl Function {
    /// Every function, in the order of the enum.
    pub const ALL: [Function; 15] = [
        Function::MassMatrix,
        Function::Coriolis,
        Function::Gravity,
        Function::InverseDynamics,
        Function::ForwardDynamics,
        Function::Friction,
        Function::InverseDynamicsDerivatives,
        Function::ForwardDynamicsDerivatives,
        Function::Regressor,
        Function::Frames,
        Function::JointRates,
        Function::ActuatorRates,
        Function::ActuatorMassMatrix,
        Function::InverseKinematics,
        Function::ForwardKinematics,
    ];

    /// The function's name in generated code and in `[scene] functions`.
    pub fn name(self) -> &'static str {
        match self {
            Function::MassMatrix => "mass_matrix",
            Function::Coriolis => "coriolis",
            Function::Gravity => "gravity",
            Function::InverseDynamics => "inverse_dynamics",
            Function::ForwardDynamics => "forward_dynamics",
            Function::Friction => "friction",
            Function::InverseDynamicsDerivatives => "inverse_dynamics_derivatives",
            Function::ForwardDynamicsDerivatives => "forward_dynamics_derivatives",
            Function::Regressor => "regressor",
            Function::Frames => "frames",
            Function::JointRates => "joint_rates",
            Function::ActuatorRates => "actuator_rates",
            Function::ActuatorMassMatrix => "actuator_mass_matrix",
            Function::InverseKinematics => "inverse_kinematics",
            Function::ForwardKinematics => "forward_kinematics",
        }
    }
}

impl FromStr for Function {
    type Err = ();
    fn from_str(s: &str) -> Result<Function, ()> {
        Function::ALL.into_iter().find(|f| f.name() == s).ok_or(())
    }
}

impl fmt::Display for Function {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The kinds of mechanism, as far as their modules' functions go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Serial chains and kinematic trees.
    Tree,
    /// Parallel platforms in platform coordinates.
    Parallel,
    /// Closed loops in joint coordinates.
    Closed,
}

impl Kind {
    /// The public functions `[scene] functions` can leave out, in their order in the module.
    pub fn selectable(self) -> &'static [Function] {
        use Function::*;
        match self {
            Kind::Tree => &[
                MassMatrix,
                Coriolis,
                Gravity,
                InverseDynamics,
                ForwardDynamics,
                InverseDynamicsDerivatives,
                ForwardDynamicsDerivatives,
                Friction,
                Regressor,
                Frames,
            ],
            Kind::Parallel => &[
                ActuatorRates,
                InverseDynamics,
                MassMatrix,
                ActuatorMassMatrix,
                ForwardDynamics,
                InverseDynamicsDerivatives,
                ForwardDynamicsDerivatives,
                Gravity,
                Coriolis,
                Friction,
                Regressor,
                Frames,
            ],
            Kind::Closed => &[
                JointRates,
                InverseDynamics,
                MassMatrix,
                ForwardDynamics,
                InverseDynamicsDerivatives,
                ForwardDynamicsDerivatives,
                Gravity,
                Coriolis,
                Friction,
                Regressor,
                Frames,
            ],
        }
    }

    /// The functions a module always has, which `[scene] functions` may name (they are
    /// emitted whatever it says). A closed-loop module's `actuator_rates` and
    /// `actuator_mass_matrix` come with `inverse_kinematics` and `mass_matrix`.
    pub fn always(self) -> &'static [Function] {
        use Function::*;
        match self {
            Kind::Tree => &[],
            Kind::Parallel | Kind::Closed => &[InverseKinematics, ForwardKinematics],
        }
    }
}

/// What `[scene] functions` chose: every function, or only those listed (and the ones a
/// module always has).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FunctionSet(Option<Vec<Function>>);

impl FunctionSet {
    /// Every function.
    pub fn all() -> FunctionSet {
        FunctionSet(None)
    }

    /// Only `functions` (of the selectable ones).
    pub fn only(functions: Vec<Function>) -> FunctionSet {
        FunctionSet(Some(functions))
    }

    /// The same set without `omit` (for a module of `kind`).
    pub fn without(self, kind: Kind, omit: &[Function]) -> FunctionSet {
        if omit.is_empty() {
            return self;
        }
        let kept = match self.0 {
            Some(fs) => fs,
            None => kind.selectable().to_vec(),
        };
        FunctionSet(Some(
            kept.into_iter().filter(|f| !omit.contains(f)).collect(),
        ))
    }

    /// Whether a module of `kind` emits the item named `name`: a selectable function when the
    /// set names it, anything else always.
    pub fn wants(&self, kind: Kind, name: &str) -> bool {
        match name.parse::<Function>() {
            Ok(f) if kind.selectable().contains(&f) => {
                self.0.as_ref().is_none_or(|o| o.contains(&f))
            }
            _ => true,
        }
    }
}

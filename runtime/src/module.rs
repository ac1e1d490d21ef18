//! [`Dynamics`]: the one interface of every generated module, whatever its kind, so that code
//! over generated modules (firmware, test harnesses) is written once, as generic functions.
//!
//! `no_std`, no `alloc`: this file is all that generated code needs from this crate besides
//! `math`. A module implements the trait when it is generated with
//! `codegen::Config::implement` set (the path of this crate): it then holds a struct
//! `Module` (a unit struct, or `Module(pub Params)` with run-time parameters) and
//! `impl Dynamics<NX, DOF> for Module`, whose methods forward to the module's free functions.

/// The dynamics of one generated module, in its own coordinates.
///
/// `NX` is the number of position coordinates `x`, `DOF` the number of degrees of freedom:
/// of speeds `u`, of actuators (positions `q`, efforts `tau`). What they are depends on the
/// module's kind, as its own docs state:
///
/// | kind | `x` (`NX`) | `u`, `ud` (`DOF`) | `q`, `tau` (`DOF`) |
/// |---|---|---|---|
/// | tree | the joint positions `q` (`NX = DOF`) | joint rates `q̇`, accelerations `q̈` | the joints: `q = x`, efforts `τ` |
/// | parallel platform | the platform's pose: `[px, py, pz, qw, qx, qy, qz]` (`Pose`), a unit quaternion (`Orientation`), `[px, py]` (`PlanarPoint`), `[px, py, pz]` (`Translation`), `[px, py, φ]` (`PlanarPose`), `[pz, α, β]` (`HeaveTilt`: heave and two tilts, the parasitic `px`, `py`, `γ` from the legs, output by `platform_pose`) or `[px, py, pz, θ]` (`Schoenflies`: a 4-axis Delta's carrier and its tool's angle about z) | the platform's twist `[ω; v]`, `ω`, `[vx, vy]`, `v`, `[vx, vy, ω]`, `[ż, α̇, β̇]` (twist `S(x) u`) or `[v; ω]` (the carrier's velocity, the tool's rate about z), and its rate | the actuated joints' positions and efforts, in `ACTUATOR_NAMES` order |
/// | closed loops in joint coordinates | every spanning-tree joint's position (`JOINT_NAMES` order), closing the loops | the rates of the independent coordinates `x[INDEPENDENT[k]]`, and their rates | the independent (actuated) joints: `q = x[INDEPENDENT]`, their efforts |
///
/// Positions in rad or m, speeds in rad/s or m/s, efforts in N·m or N (SI throughout).
///
/// Every method is a call of the free function of the same name (with the module's `Params`
/// last when it has run-time parameters); where a tree has no such function the method is the
/// identity the table states (`inverse_kinematics`, `forward_kinematics`, `actuator_rates`), or
/// `mass_matrix` for `actuator_mass_matrix`. The errors are the module's own types, unchanged:
/// `Singular` (where and how a configuration failed) and `NoConvergence` (forward kinematics'
/// iterations and residual); a tree's forward kinematics cannot fail
/// (`NoConvergence = core::convert::Infallible`), and its only fallible function is
/// `forward_dynamics`.
///
/// The functions that some modules do not have are the provided methods returning `Option`:
/// `None` from a module without the function (another kind, no friction, or left out by the
/// spec's `[scene] functions`). Every kind has `gravity` and `coriolis` (and `friction` with
/// friction), in its own efforts, so that
/// `inverse_dynamics(x, u, ud) = actuator_mass_matrix(x) · q̈ + coriolis(x, u) + gravity(x)
/// (+ friction(x, u))` with `q̈ = actuator_rates(x, ud)`.
pub trait Dynamics<const NX: usize, const DOF: usize> {
    /// The scalar of the generated code (`f64`, or `f32`).
    type Scalar: Copy;
    /// The module's error of a singular configuration or a non-finite input.
    type Singular: Copy + core::fmt::Debug + PartialEq;
    /// The module's error of forward kinematics that did not converge.
    type NoConvergence: Copy + core::fmt::Debug + PartialEq;

    /// The spec's mechanism name.
    const NAME: &'static str;
    /// The spec's home configuration `x`: a guess for [`Dynamics::forward_kinematics`] near
    /// home (all zeros for a tree).
    const HOME: [Self::Scalar; NX];

    /// The actuated joints' positions `q(x)` (a tree: `x`).
    fn inverse_kinematics(
        &self,
        x: &[Self::Scalar; NX],
    ) -> Result<[Self::Scalar; DOF], Self::Singular>;

    /// The configuration `x` whose actuated joints are at `q`, on the branch of `guess` (pass
    /// the last configuration, or `HOME`); a tree: `q`.
    fn forward_kinematics(
        &self,
        q: &[Self::Scalar; DOF],
        guess: &[Self::Scalar; NX],
    ) -> Result<[Self::Scalar; NX], Self::NoConvergence>;

    /// The actuated joints' rates `q̇ = A u` (a tree, and closed loops: `u`).
    fn actuator_rates(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
    ) -> Result<[Self::Scalar; DOF], Self::Singular>;

    /// The actuator efforts `tau` that produce the motion `(x, u, ud)`, gravity included.
    fn inverse_dynamics(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
        ud: &[Self::Scalar; DOF],
    ) -> Result<[Self::Scalar; DOF], Self::Singular>;

    /// The generalized inertia `I(x)` of the speeds `u` (a tree's is infallible).
    fn mass_matrix(
        &self,
        x: &[Self::Scalar; NX],
    ) -> Result<[[Self::Scalar; DOF]; DOF], Self::Singular>;

    /// The inertia in actuator space `A⁻ᵀ I A⁻¹` (a tree, and closed loops: `mass_matrix`).
    fn actuator_mass_matrix(
        &self,
        x: &[Self::Scalar; NX],
    ) -> Result<[[Self::Scalar; DOF]; DOF], Self::Singular>;

    /// The speed rates `ud` that the actuator efforts `tau` produce at `(x, u)`.
    fn forward_dynamics(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
        tau: &[Self::Scalar; DOF],
    ) -> Result<[Self::Scalar; DOF], Self::Singular>;

    /// The names of the frames whose kinematics the module offers (its `FRAME_NAMES`, as the
    /// spec writes them; `[scene] frames`), in the order of the `frame` argument of
    /// [`Dynamics::frame_pose`], [`Dynamics::frame_jacobian`] and
    /// [`Dynamics::frame_jacobian_dot`]. Empty for a module without frames.
    const FRAME_NAMES: &'static [&'static str] = &[];

    /// The pose of frame `FRAME_NAMES[frame]` at `x`: the rotation base ← frame and the
    /// frame's origin in the base frame (its `F_pose`; a closed loop's `F_pose_at`, at the
    /// tree joint positions `x`). `None` when `frame` is out of range. A tree's and a closed
    /// loop's cannot fail (`Ok`); a platform's fails where its pose does.
    #[allow(clippy::type_complexity)]
    fn frame_pose(
        &self,
        frame: usize,
        x: &[Self::Scalar; NX],
    ) -> Option<Result<([[Self::Scalar; 3]; 3], [Self::Scalar; 3]), Self::Singular>> {
        let _ = (frame, x);
        None
    }

    /// The Jacobian of frame `FRAME_NAMES[frame]` at `x` (its `F_jacobian`): the map of the
    /// speeds `u` to the frame's twist `[ω; v]`, angular first, both in base-frame components,
    /// `v` the velocity of the frame's origin. `None` when `frame` is out of range, and for
    /// closed loops (which offer poses only).
    #[allow(clippy::type_complexity)]
    fn frame_jacobian(
        &self,
        frame: usize,
        x: &[Self::Scalar; NX],
    ) -> Option<Result<[[Self::Scalar; DOF]; 6], Self::Singular>> {
        let _ = (frame, x);
        None
    }

    /// `J̇ u` of frame `FRAME_NAMES[frame]` at `(x, u)` (a tree's `F_jacobian_dot_qd`, a
    /// platform's `F_jacobian_dot_u`), so that the frame's classical acceleration is
    /// `[ω̇; p̈] = J u̇ + J̇ u`. `None` as for [`Dynamics::frame_jacobian`].
    fn frame_jacobian_dot(
        &self,
        frame: usize,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
    ) -> Option<Result<[Self::Scalar; 6], Self::Singular>> {
        let _ = (frame, x, u);
        None
    }

    /// Closed loops: every joint's rate `ẋ = S u` (`joint_rates`). `None` elsewhere.
    fn joint_rates(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
    ) -> Option<Result<[Self::Scalar; NX], Self::Singular>> {
        let _ = (x, u);
        None
    }

    /// The velocity-dependent actuator efforts (`coriolis`): `C(q, q̇) q̇` of a tree, `A⁻ᵀ C u`
    /// of a platform, `C u` of closed loops; no gravity, no friction. `None` where the scene
    /// leaves it out. A tree's cannot fail (`Ok`).
    fn coriolis(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
    ) -> Option<Result<[Self::Scalar; DOF], Self::Singular>> {
        let _ = (x, u);
        None
    }

    /// The actuator efforts that hold the mechanism still against gravity (and a closed
    /// loop's springs) at `x` (`gravity`): `inverse_dynamics(x, 0, 0)`. `None` where the scene
    /// leaves it out. A tree's cannot fail (`Ok`).
    fn gravity(
        &self,
        x: &[Self::Scalar; NX],
    ) -> Option<Result<[Self::Scalar; DOF], Self::Singular>> {
        let _ = x;
        None
    }

    /// The actuator efforts of the joints' friction (viscous and regularized Coulomb; a
    /// closed loop's spring damping too) at `(x, u)` (`friction`). `None` where the mechanism
    /// has no friction or the scene leaves it out. A tree's cannot fail (`Ok`).
    fn friction(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
    ) -> Option<Result<[Self::Scalar; DOF], Self::Singular>> {
        let _ = (x, u);
        None
    }

    /// `(∂τ/∂x, ∂τ/∂u)` of `inverse_dynamics`, element `[i][j] = ∂τ_i/∂x_j`
    /// (`inverse_dynamics_derivatives`): a tree's `(∂τ/∂q, ∂τ/∂q̇)`, always `Ok`; a platform's
    /// and a closed loop's with the derivative in `x` along the tangent of its coordinates
    /// (column `j`: `x` moved as the speed `u_j` moves it). `None` where the module was
    /// generated without it.
    #[allow(clippy::type_complexity)]
    fn inverse_dynamics_derivatives(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
        ud: &[Self::Scalar; DOF],
    ) -> Option<Result<([[Self::Scalar; DOF]; DOF], [[Self::Scalar; DOF]; DOF]), Self::Singular>>
    {
        let _ = (x, u, ud);
        None
    }

    /// `(∂u̇/∂x, ∂u̇/∂u, ∂u̇/∂τ)` of `forward_dynamics`, with its pivots and errors
    /// (`forward_dynamics_derivatives`; a tree's `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)`), the derivative in `x`
    /// as in [`Dynamics::inverse_dynamics_derivatives`]. `None` where the module was generated
    /// without it.
    #[allow(clippy::type_complexity)]
    fn forward_dynamics_derivatives(
        &self,
        x: &[Self::Scalar; NX],
        u: &[Self::Scalar; DOF],
        tau: &[Self::Scalar; DOF],
    ) -> Option<
        Result<
            (
                [[Self::Scalar; DOF]; DOF],
                [[Self::Scalar; DOF]; DOF],
                [[Self::Scalar; DOF]; DOF],
            ),
            Self::Singular,
        >,
    > {
        let _ = (x, u, tau);
        None
    }
}

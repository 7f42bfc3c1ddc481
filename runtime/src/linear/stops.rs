//! What an equilibrium search or a linearisation reports beside its result: why Newton's
//! method stopped ([`NewtonStop`]), which part of the equations depends on `t`
//! ([`TimeDependentPart`]), and a time-dependent load set aside ([`TimeDependentForcing`]).

/// Why Newton's method on the equilibrium equations stopped short of a root.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum NewtonStop {
    /// `∂F/∂q` has a NaN or infinite entry at the iterate.
    #[error("the Jacobian ∂F/∂q is not finite")]
    NonFiniteJacobian,
    /// `∂F/∂q` is zero at the iterate: the forces do not depend on the configuration there
    /// (no restoring force), so nothing points to an equilibrium.
    #[error("the Jacobian ∂F/∂q is zero: the forces do not depend on q here")]
    ZeroJacobian,
    /// No step along the Newton direction, halved 30 times, reduces `max |F|`: a non-zero
    /// local minimum of `|F|`, or a singular `∂F/∂q` whose null space the residual leaves.
    #[error("no step reduces |F|: a non-zero minimum of |F| or a singular ∂F/∂q")]
    NoDecrease,
    /// 100 iterations without convergence.
    #[error("iteration limit")]
    IterationLimit,
}

/// A part of the linearised equations found to depend on `t` ([`ModalError::TimeDependent`](super::modal::ModalError::TimeDependent)).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum TimeDependentPart {
    /// The holonomic constraint of this name: `Φ`, its Jacobian `J` or its `γ` (a rheonomic
    /// constraint).
    Constraint {
        /// The constraint's name.
        name: String,
        /// Whether `J` changes with `t` (a rod spun at a given rate); `false` when only `Φ`,
        /// `Φ_t` or `γ` do, a prescribed motion with a constant Jacobian (base excitation,
        /// `x − a cos wt`), whose modes are those of the system relative to the moving base.
        jacobian_changes: bool,
    },
    /// The mass matrix `M(q*, t)`.
    MassMatrix,
    /// The damping coefficients `−∂F/∂q̇ (q*, 0, t)`.
    DampingMatrix,
    /// The stiffness coefficients `−∂F/∂q (q*, 0, t)` (parametric excitation).
    StiffnessMatrix,
}

impl std::fmt::Display for TimeDependentPart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Constraint {
                name,
                jacobian_changes: true,
            } => write!(f, "the constraint `{name}` (its Jacobian J)"),
            Self::Constraint { name, .. } => write!(
                f,
                "the constraint `{name}` (Φ and γ, with a constant Jacobian: a prescribed motion)"
            ),
            Self::MassMatrix => f.write_str("the mass matrix M"),
            Self::DampingMatrix => f.write_str("the damping matrix C = −∂F/∂q̇"),
            Self::StiffnessMatrix => f.write_str("the stiffness −∂F/∂q"),
        }
    }
}

/// A load that depends on `t` at the operating point and enters neither `M`, `C` nor `K`:
/// the linearisation is `M δq̈ + C δq̇ + K δq = F(q*, 0, t) − F(q*, 0, t₀)` about the equilibrium
/// `q*` under the load's value at `t₀` (deflected by it where that value is not 0), and the
/// modes are those of its left side, the load's variation set aside ([`time_dependence`](super::time_dependence::time_dependence)).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TimeDependentForcing {
    /// The time `t₀` (s) at which the load is frozen in the equilibrium `F(q*, 0, t₀) = 0`.
    pub t0: f64,
    /// The coordinate whose generalized force changes most.
    pub coordinate: String,
    /// `max |Fᵢ(q*, 0, t) − Fᵢ(q*, 0, t₀)|` over the sampled times (units of that
    /// generalized force): the size of the input set aside.
    pub largest_change: f64,
    /// The sampled time (s) where it was largest.
    pub t: f64,
}

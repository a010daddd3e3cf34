//! What a step does with the momentum of a model with holonomic constraints `g(q) = 0`.

/// What a step does with the momentum of a model with holonomic constraints `g(q) = 0`.
///
/// Both impose `g(q_{k+1}) = 0` through an impulse along `dg(q_k)` (SHAKE), so they produce the
/// same positions. `Shake` keeps `p_{k+1} = D₂L_d` (plus forces), whose velocity has a component
/// across the constraint of the order of the method's error. `Rattle` then removes it: it adds
/// the impulse `dg(q_{k+1})ᵀν` for which the velocity of `p_{k+1}` is tangent,
/// `dg(q_{k+1}) v_{k+1} = 0`, so that the state lies on the constraint's cotangent bundle and
/// `g = 0`, `dg v = 0` hold to round-off at every step. Measured on the Cartesian pendulum in
/// `tests/suite/constrained.rs`. The velocity a stepper reports ([`Stepper::v`](crate::Stepper::v))
/// is tangent under both, and so is the energy computed from it: the schemes differ in the
/// momentum they store, and only `Shake` has derivatives of its step map
/// ([`Stepper::step_linearised`](crate::Stepper::step_linearised)).
///
/// ```
/// use dirac_runtime::HolonomicScheme;
/// assert_eq!(HolonomicScheme::default(), HolonomicScheme::Shake);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HolonomicScheme {
    /// Keep the momentum the step's equations give.
    #[default]
    Shake,
    /// Project the momentum so that its velocity is tangent to the constraint.
    Rattle,
}

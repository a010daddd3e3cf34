//! Where on a step the constraint one-forms are evaluated: the discrete constraint point
//! `q_c = q_k + θ (q_{k+1} − q_k)` and the share of the constraint impulse on `p_k`.

/// Where on a step the constraint one-forms are evaluated.
///
/// Measured on the knife edge (`tests/suite/discrete_dirac.rs`): `Start` and `End` are first order, `Midpoint`
/// second order. For the same scene `Start` loses energy and `End` gains it, while `Midpoint`
/// keeps it bounded. Where the one-forms are constant (circuits, interconnections) all three
/// coincide.
///
/// ```
/// use dirac_runtime::ConstraintPoint;
/// assert_eq!(ConstraintPoint::default(), ConstraintPoint::Midpoint);
/// assert_eq!(ConstraintPoint::End.theta(), 1.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ConstraintPoint {
    /// `q_c = q_k`: the seed's (+) scheme.
    Start,
    /// `q_c = (q_k + q_{k+1}) / 2`.
    #[default]
    Midpoint,
    /// `q_c = q_{k+1}`: the (−) scheme.
    End,
}

impl ConstraintPoint {
    /// `θ` in `q_c = q_k + θ (q_{k+1} − q_k)`.
    pub fn theta(self) -> f64 {
        match self {
            ConstraintPoint::Start => 0.0,
            ConstraintPoint::Midpoint => 0.5,
            ConstraintPoint::End => 1.0,
        }
    }

    /// `σ`: the share of the constraint impulse on the equation of `p_k`; the rest goes to
    /// `p_{k+1}`.
    pub fn share(self) -> f64 {
        match self {
            ConstraintPoint::Midpoint => 0.5,
            ConstraintPoint::Start | ConstraintPoint::End => 1.0,
        }
    }
}

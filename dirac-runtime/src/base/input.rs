//! A handle on one input of a system, resolved by name once.

/// One input of a system, resolved by name once ([`Stepper::input`]) and then set without a
/// lookup ([`Stepper::set_input_value`]), as a control loop does at every step.
///
/// [`Stepper::input`]: crate::Stepper::input
/// [`Stepper::set_input_value`]: crate::Stepper::set_input_value
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
/// /// A unit mass pushed by the input u: L = v²/2, force u along x.
/// struct Pushed;
/// impl DiracSystem<1> for Pushed {
///     const FORCES: bool = true;
///     const INPUTS: usize = 1;
///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5
///     }
///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D]) -> SVector<D, 1> {
///         SVector::from([u[0]])
///     }
///     fn input_name(&self, _i: usize) -> String {
///         "u".into()
///     }
/// }
/// let mut stepper = Stepper::new(Pushed, Quadrature::midpoint(), 0.1)?;
/// stepper.start_from_velocity(vector![0.0], vector![0.0])?;
/// let u = stepper.input("u")?;
/// for _ in 0..10 {
///     stepper.set_input_value(u, 1.0)?;
///     stepper.step()?;
/// }
/// // A constant unit force for t = 1: x = t²/2 exactly under the midpoint rule.
/// assert!((stepper.q()[0] - 0.5).abs() < 1e-12);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Input {
    index: usize,
}

impl Input {
    pub(crate) fn new(index: usize) -> Self {
        Self { index }
    }

    /// The input's position in the system's `inputs(...)`.
    pub fn index(&self) -> usize {
        self.index
    }
}

//! # dirac
//!
//! Structure-preserving integrators generated at compile time. Annotate a struct of parameters
//! with [`#[dirac_system(...)]`](dirac_system), naming its coordinates, its Lagrangian and a
//! quadrature; build a [`Stepper`]; step it or run it for a [`Trajectory`].
//!
//! ```
//! use dirac::prelude::*;
//!
//! /// A pendulum of unit length and mass: q̈ = −sin q.
//! #[dirac_system(
//!     coordinates(theta),
//!     lagrangian = 0.5 * dot(theta).powi(2) + cos(theta),
//!     quadrature = galerkin(2),
//! )]
//! struct Pendulum;
//!
//! let mut stepper = Stepper::from_system(Pendulum, 0.05)?;
//! stepper.start_from_momentum(vector![1.0], vector![0.0])?;
//! let trajectory = stepper.run(100)?; // to T = 5
//! assert!((trajectory.q()[100][0] - -0.02395128485293).abs() < 1e-6);
//! # Ok::<(), DiracError>(())
//! ```
//!
//! The attribute's syntax is in `docs/syntax.md`, the quadratures and their measured orders in
//! `docs/mathematics.md`.

pub use dirac_macros::dirac_system;
pub use dirac_runtime::*;

/// A static vector `SVector<T, N>` from its entries, like nalgebra's `vector!` but needing no
/// direct dependency on nalgebra.
///
/// ```
/// let v: dirac::nalgebra::SVector<f64, 3> = dirac::vector![1.0, 2.0, 3.0];
/// assert_eq!(v[2], 3.0);
/// ```
#[macro_export]
macro_rules! vector {
    ($($entry:expr),* $(,)?) => {
        $crate::nalgebra::SVector::from([$($entry),*])
    };
}

/// Everything a model file needs: the attribute, the runtime types and `vector!`/`SVector`.
pub mod prelude {
    pub use crate::vector;
    pub use dirac_macros::dirac_system;
    pub use dirac_runtime::nalgebra::{Matrix3, SMatrix, SVector, Vector3};
    pub use dirac_runtime::{
        Anchor, Boundary, Composition, Configuration, ConfigurationSpace, ConstraintPoint,
        Crossing, DiracError, DiracSystem, Direction, DiscreteLagrangian, DualNum, Euclidean,
        Event, ExplicitSystem, Feedback, Field, FirstOrderScheme, HamiltonianSystem,
        HolonomicScheme, Input, Interconnected, Interconnection, Joint, Junction, ManifoldStepper,
        Modular, NewtonOptions, PlaneDensity, PlaneField, Positive, Product, Progress, Quadrature,
        Rates, Repeated, Retraction, Rule, Run, Sample, Scalar, SeparableDensity, Solution, Solver,
        Status, Stepper, TimeTransformed, Trajectory,
    };
}

/// The README's examples are compiled and run as doctests, so the front door stays true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// The attribute's documentation (written in `dirac-macros`, whose own doctests are off): its
/// examples run here. The file is outside this package, so they run from the repository only.
#[doc = include_str!("../dirac-macros/src/dirac_system.md")]
#[cfg(doctest)]
pub struct AttributeDoctests;

#[doc = include_str!("../docs/guide.md")]
#[cfg(doctest)]
pub struct GuideDoctests;

#[doc = include_str!("../docs/syntax.md")]
#[cfg(doctest)]
pub struct SyntaxDoctests;

#[doc = include_str!("../docs/mathematics.md")]
#[cfg(doctest)]
pub struct MathematicsDoctests;

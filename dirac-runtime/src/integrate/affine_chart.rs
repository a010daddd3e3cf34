//! A stepper on an affine chart `R_q(ξ) = q + Mξ` takes the Euclidean steps: a test of every
//! transpose a configuration space enters (pull-backs of forces and one-forms, the momentum
//! carried out of the chart).

use crate::base::scalar::Scalar;
use crate::integrate::stepper::Stepper;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::space::configuration_space::{
    ConfigurationSpace, Euclidean, chart_rate_by_tangent_map, covector_by_tangent_map, sealed,
};
use crate::space::manifold::Vectors;
use nalgebra::SVector;
use nalgebra::{Matrix2, vector};

/// `R_q(ξ) = q + Mξ` with a non-symmetric `M`: an affine chart, so the scheme is `Rⁿ`'s in
/// other coordinates, and every transpose (pull-backs of forces and one-forms, the momentum
/// carried out of the chart) shows if it is wrong.
#[derive(Debug, Clone, Copy)]
struct Sheared;

fn shear() -> Matrix2<f64> {
    Matrix2::new(1.0, 0.6, 0.0, 0.8)
}

impl sealed::Sealed for Sheared {}

impl ConfigurationSpace<2> for Sheared {
    type Manifold = Vectors;

    fn contains(&self, q: &SVector<f64, 2>) -> bool {
        q.iter().all(|x| x.is_finite())
    }

    fn retract<D: Scalar>(&self, q: &SVector<f64, 2>, xi: &SVector<D, 2>) -> SVector<D, 2> {
        let m = shear();
        SVector::from_fn(|i, _| xi[0] * m[(i, 0)] + xi[1] * m[(i, 1)] + q[i])
    }

    fn push_forward<D: Scalar>(
        &self,
        _q: &SVector<f64, 2>,
        _xi: &SVector<D, 2>,
        xi_dot: &SVector<D, 2>,
    ) -> SVector<D, 2> {
        let m = shear();
        SVector::from_fn(|i, _| xi_dot[0] * m[(i, 0)] + xi_dot[1] * m[(i, 1)])
    }

    fn local(&self, q: &SVector<f64, 2>, q1: &SVector<f64, 2>) -> Option<SVector<f64, 2>> {
        shear().try_inverse().map(|inverse| inverse * (q1 - q))
    }

    fn chart_rate(
        &self,
        q: &SVector<f64, 2>,
        xi: &SVector<f64, 2>,
        v: &SVector<f64, 2>,
    ) -> Option<SVector<f64, 2>> {
        chart_rate_by_tangent_map(self, q, xi, v)
    }

    fn push_covector(
        &self,
        q: &SVector<f64, 2>,
        xi: &SVector<f64, 2>,
        covector: &SVector<f64, 2>,
    ) -> Option<SVector<f64, 2>> {
        covector_by_tangent_map(self, q, xi, covector)
    }
}

/// A coupled Lagrangian with a position-dependent damping force and `FORMS` copies of the
/// one-form `cos q0 dq0 + sin q0 dq1` (0 or 1).
struct Model<const FORMS: usize>;

impl<const FORMS: usize> DiracSystem<2> for Model<FORMS> {
    const FORCES: bool = true;
    const ONE_FORMS: usize = FORMS;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        v[0] * v[0] * 0.5 + v[1] * v[1] * (q[0].cos() + 2.0) * 0.5 + v[0] * v[1] * 0.3
            - q[0].powi(2) * q[1].sin()
    }

    fn force<D: Scalar>(
        &self,
        q: &SVector<D, 2>,
        v: &SVector<D, 2>,
        _t: f64,
        _inputs: &[D],
    ) -> SVector<D, 2> {
        SVector::from([v[0] * (q[1] * -0.2), v[1] * -0.1 + q[0] * 0.05])
    }

    fn one_form<D: Scalar>(&self, q: &SVector<D, 2>, _a: usize) -> SVector<D, 2> {
        SVector::from([q[0].cos(), q[0].sin()])
    }
}

fn run<C: ConfigurationSpace<2, Manifold = Vectors>, const FORMS: usize>(
    space: C,
    quadrature: Quadrature,
) -> (SVector<f64, 2>, SVector<f64, 2>) {
    let mut stepper = Stepper::on_space(Model::<FORMS>, space, quadrature, 0.05).unwrap();
    stepper
        .start_from_velocity(vector![0.4, 0.7], vector![0.0, 0.0])
        .unwrap();
    stepper.run(60).unwrap();
    (stepper.q(), stepper.p())
}

#[test]
fn an_affine_chart_gives_the_euclidean_steps() {
    // Unconstrained with internal points, then with the one-form.
    let gauss = Quadrature::galerkin(2).unwrap();
    let pairs = [
        (
            run::<_, 0>(Euclidean, gauss.clone()),
            run::<_, 0>(Sheared, gauss),
        ),
        (
            run::<_, 1>(Euclidean, Quadrature::midpoint()),
            run::<_, 1>(Sheared, Quadrature::midpoint()),
        ),
    ];
    for ((q, p), (q_sheared, p_sheared)) in pairs {
        assert!((q - q_sheared).amax() < 1e-12, "{q} vs {q_sheared}");
        assert!((p - p_sheared).amax() < 1e-12, "{p} vs {p_sheared}");
        assert!(
            (q - vector![0.4, 0.7]).amax() > 1e-2,
            "the motion is not trivial"
        );
    }
}

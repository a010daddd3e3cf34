//! The step equations as a seam: a `Stepper` drives equations written outside the library with
//! the same Newton solve, trajectories and error guarantees as its own. Here the implicit
//! midpoint rule of the harmonic oscillator `H = (p² + ω² q²)/2`, in unknowns `x = [q1, p1]`:
//!
//! ```text
//! q1 − q0 − h (p0 + p1)/2 = 0,      p1 − p0 + h ω² (q0 + q1)/2 = 0.
//! ```
//!
//! Its step is the Cayley transform of the generator, a rotation of `(ω q, p)` by
//! `θ = 2 atan(hω/2)`: after `n` steps the state is known in closed form, and `H` is conserved.

use dirac::nalgebra::{DMatrix, DVector};
use dirac::newton::{Newton, NewtonFailure};
use dirac::prelude::*;
use dirac::{State, StepEquations};

#[derive(Debug, Clone)]
struct Oscillator {
    omega: f64,
}

#[derive(Debug, Clone)]
struct ImplicitMidpoint {
    oscillator: Oscillator,
    h: f64,
}

impl StepEquations<1> for ImplicitMidpoint {
    type System = Oscillator;
    type Manifold = dirac::Vectors;
    const NAME: &'static str = "the implicit midpoint rule";
    const VELOCITY: &'static str = "v = ∂H/∂p";

    fn system(&self) -> &Oscillator {
        &self.oscillator
    }

    fn h(&self) -> f64 {
        self.h
    }

    fn unknowns(&self) -> usize {
        2
    }

    fn multipliers(&self) -> usize {
        0
    }

    fn multiplier_names(&self) -> Vec<String> {
        Vec::new()
    }

    fn coordinate_name(&self, _i: usize) -> String {
        "x".into()
    }

    fn check_start(&self, state: &State<1>, _tolerance: f64) -> Result<(), DiracError> {
        if state.q()[0].is_finite() && state.p()[0].is_finite() {
            Ok(())
        } else {
            Err(DiracError::InconsistentInitialState("not finite".into()))
        }
    }

    fn predict(
        &mut self,
        state: &State<1>,
        _previous: Option<&DVector<f64>>,
        x: &mut DVector<f64>,
    ) {
        let w2 = self.oscillator.omega.powi(2);
        x[0] = state.q()[0] + self.h * state.p()[0];
        x[1] = state.p()[0] - self.h * w2 * state.q()[0];
    }

    fn assemble(
        &mut self,
        state: &State<1>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64 {
        let (q0, p0, h) = (state.q()[0], state.p()[0], self.h);
        let w2 = self.oscillator.omega.powi(2);
        residual[0] = x[0] - q0 - h * (p0 + x[1]) / 2.0;
        residual[1] = x[1] - p0 + h * w2 * (q0 + x[0]) / 2.0;
        if let Some(jacobian) = jacobian {
            jacobian[(0, 0)] = 1.0;
            jacobian[(0, 1)] = -h / 2.0;
            jacobian[(1, 0)] = h * w2 / 2.0;
            jacobian[(1, 1)] = 1.0;
        }
        q0.abs().max(p0.abs()).max(1.0)
    }

    fn advance(
        &self,
        state: &State<1>,
        x: &DVector<f64>,
        _step: u64,
    ) -> Result<State<1>, DiracError> {
        Ok(State::new(
            state.t(),
            vector![x[0]],
            vector![x[1]],
            vector![x[1]],
        ))
    }

    fn violation(&self, _from: &State<1>, _to: &State<1>, _x: &DVector<f64>) -> f64 {
        0.0
    }

    fn first_multiplier(&self) -> usize {
        2
    }

    fn momentum(
        &self,
        _q: &SVector<f64, 1>,
        v: &SVector<f64, 1>,
    ) -> Result<SVector<f64, 1>, DiracError> {
        Ok(*v)
    }

    fn unknown_name(&self, column: usize) -> String {
        ["q1", "p1"][column].into()
    }

    fn velocity(
        &self,
        _newton: &mut Newton,
        _t: f64,
        _q: &SVector<f64, 1>,
        p: &SVector<f64, 1>,
        _guess: &SVector<f64, 1>,
    ) -> Result<SVector<f64, 1>, NewtonFailure> {
        Ok(*p)
    }

    fn energy(&self, q: &SVector<f64, 1>, p: &SVector<f64, 1>, _v: &SVector<f64, 1>) -> f64 {
        0.5 * (p[0] * p[0] + self.oscillator.omega.powi(2) * q[0] * q[0])
    }
}

fn stepper(omega: f64, h: f64) -> Stepper<Oscillator, 1, ImplicitMidpoint> {
    let equations = ImplicitMidpoint {
        oscillator: Oscillator { omega },
        h,
    };
    Stepper::with_equations(equations).expect("valid equations")
}

#[test]
fn a_stepper_drives_equations_written_outside_the_library() {
    let (omega, h, n) = (2.0, 0.05, 1000);
    let mut stepper = stepper(omega, h);
    stepper
        .start_from_state(State::new(0.5, vector![1.0], vector![0.5], vector![0.5]))
        .expect("finite start");
    let trajectory = stepper.run(n).expect("linear steps converge");
    let theta = 2.0 * (h * omega / 2.0).atan();
    let (q0, p0) = (1.0, 0.5);
    for (k, (q, p)) in trajectory.q().iter().zip(trajectory.p()).enumerate() {
        let angle = k as f64 * theta;
        let q_exact = q0 * angle.cos() + p0 / omega * angle.sin();
        let p_exact = -omega * q0 * angle.sin() + p0 * angle.cos();
        assert!((q[0] - q_exact).abs() < 1e-12, "q at step {k}");
        assert!((p[0] - p_exact).abs() < 1e-12, "p at step {k}");
    }
    // The run starts at the state's own time, and H is conserved to round-off.
    assert!((stepper.t() - (0.5 + n as f64 * h)).abs() < 1e-12);
    assert!(trajectory.max_energy_error() < 1e-14);
    assert!(stepper.last_report().expect("stepped").iterations <= 3);
    // Equations that do not say what work their steps do get no energy balance, rather than
    // one made up: no work column, and an error that says why.
    assert!(matches!(stepper.work(), Err(DiracError::Unsupported(_))));
    assert!(trajectory.work().is_none());
    assert!(matches!(
        trajectory.energy_balance(),
        Err(DiracError::Unsupported(_))
    ));
}

#[test]
fn a_failed_custom_step_leaves_the_stepper_as_it_was() {
    let mut stepper = stepper(f64::NAN, 0.05);
    assert!(
        stepper
            .start_from_state(State::new(
                0.0,
                vector![f64::INFINITY],
                vector![0.0],
                vector![0.0]
            ))
            .is_err()
    );
    stepper
        .start_from_state(State::new(0.0, vector![1.0], vector![0.0], vector![0.0]))
        .expect("finite start");
    let error = stepper.step().expect_err("ω = NaN gives a NaN residual");
    assert!(matches!(error, DiracError::NonFinite { .. }), "{error}");
    assert!(
        error.to_string().contains("the implicit midpoint rule"),
        "{error}"
    );
    assert_eq!(
        (stepper.steps(), stepper.q()[0], stepper.t()),
        (0, 1.0, 0.0)
    );
}

/// A unit pendulum, `L = v²/2 + cos q`.
struct Pendulum;

impl DiracSystem<1> for Pendulum {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        v[0] * v[0] * 0.5 + q[0].cos()
    }
}

#[test]
fn a_lagrangian_stepper_continues_from_another_steppers_state() {
    let mut first = Stepper::new(Pendulum, Quadrature::galerkin(2).unwrap(), 0.1).unwrap();
    first
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    first.run(50).unwrap();
    let mut second = Stepper::new(Pendulum, Quadrature::galerkin(2).unwrap(), 0.1).unwrap();
    second
        .start_from_state(*first.state().expect("started"))
        .expect("a running stepper's state is a valid start");
    first.run(100).unwrap();
    second.run(100).unwrap();
    // Only the predictor of the first step differs: the same steps to solver tolerance.
    assert!((first.q() - second.q()).amax() < 1e-12);
    assert!((first.p() - second.p()).amax() < 1e-12);
    assert_eq!(first.t(), second.t());
}

#[test]
fn the_lagrangian_equations_validate_what_the_stepper_would() {
    use dirac::euler_lagrange::EulerLagrange;
    // One-forms with a Lobatto rule of degree 2, and a negative step, are refused by the
    // equations themselves, so Stepper::with_equations cannot bypass the checks.
    let lobatto = Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap();
    let discrete = DiscreteLagrangian::new(scenes::circuit::LC, lobatto, 0.01);
    assert!(matches!(
        EulerLagrange::new(discrete),
        Err(DiracError::InvalidQuadrature(_))
    ));
    let discrete = DiscreteLagrangian::new(Pendulum, Quadrature::midpoint(), -0.1);
    assert!(matches!(
        EulerLagrange::new(discrete),
        Err(DiracError::InvalidStep { .. })
    ));
}

/// A bead on the unit sphere whose velocity is held off one direction by a one-form: a model
/// with both kinds of constraint rows, and closed-form derivatives of `L`.
#[dirac_system(
    coordinates(x, y, z),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(z).powi(2)) - g * z,
    constraints(z * dx - x * dz),
    holonomic(x * x + y * y + z * z - 1.0),
)]
#[derive(Debug, Clone, Copy)]
struct HeldBead {
    g: f64,
}

/// Every row of a step's residual is written by the assembly, whatever the vector held before
/// (a degree-1 step with closed forms writes the Euler–Lagrange rows and leaves the rest to the
/// constraint rows): assembling into a vector of NaN gives what assembling into zeros gives.
#[test]
fn the_assembly_writes_every_row_of_the_residual() {
    use dirac::euler_lagrange::EulerLagrange;
    let bead = HeldBead { g: 9.81 };
    let q = vector![0.6, 0.0, -0.8];
    let v = vector![0.0, 1.0, 0.0];
    let state = State::new(0.0, q, v, v);
    // Closed forms: the midpoint rule takes the degree-1 path that leaves rows to the
    // constraints (`galerkin(2)` the general assembly).
    assert!(bead.lagrangian_hessian(&q, &v).is_some());
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let discrete = DiscreteLagrangian::new(bead, quadrature, 0.01);
        let mut equations = EulerLagrange::new(discrete).unwrap();
        equations.begin(&state);
        let n = equations.unknowns();
        let mut x = DVector::zeros(n);
        equations.predict(&state, None, &mut x);
        // Off the solution, with multipliers that are not zero.
        for (i, xi) in x.iter_mut().enumerate() {
            *xi += 1e-3 * (i + 1) as f64;
        }
        for with_jacobian in [false, true] {
            let mut assembled = |fill: f64| {
                let mut residual = DVector::from_element(n, fill);
                let mut jacobian = DMatrix::zeros(n, n);
                let scale = equations.assemble(
                    &state,
                    &x,
                    &mut residual,
                    with_jacobian.then_some(&mut jacobian),
                );
                (residual, jacobian, scale)
            };
            let (clean, stale) = (assembled(0.0), assembled(f64::NAN));
            assert!(clean.0.iter().all(|r| r.is_finite()) && clean.0.amax() > 0.0);
            assert_eq!(clean, stale, "{} rows, Jacobian: {with_jacobian}", n);
        }
    }
}

/// The knife edge with its one-form in closed form (its derivative's entries alone enter the
/// Jacobian).
#[dirac_system(
    coordinates(x, y, phi),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)) + 0.3 * dot(phi).powi(2) + 4.9 * x,
    constraints(sin(phi) * dx - cos(phi) * dy),
)]
#[derive(Debug, Clone, Copy)]
struct Blade;

/// A separable Lagrangian (`∂²L/∂q∂v = 0`, its potential curved): the step skips the mixed
/// blocks' products.
#[dirac_system(
    coordinates(x, y, z),
    lagrangian = 0.5 * (dot(x).powi(2) + 2.0 * dot(y).powi(2) + dot(z).powi(2)) + cos(x) - y * y * z,
)]
#[derive(Debug, Clone, Copy)]
struct Separable;

/// `∂²L/∂q∂v` with a single entry, off its diagonal (`∂²L/∂y∂ẋ`), and `∂²L/∂q²` diagonal: the
/// step combines the entries that do not vanish of a block and of its transpose.
#[dirac_system(
    coordinates(x, y, z),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(z).powi(2)) + y * dot(x)
        - cos(x) - y.powi(2) - z.powi(3),
)]
#[derive(Debug, Clone, Copy)]
struct Skew;

/// A model written by hand whose closed forms stop at `x > 0.5` (dual numbers take over there):
/// a step of the trapezoid rule from `x = 0.4` has them at its first node and not at its second.
#[derive(Debug, Clone, Copy)]
struct Partial;

impl DiracSystem<3> for Partial {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
        v.dot(v) * 0.5 + q[0].cos() - q[1] * q[1] * q[2]
    }

    fn lagrangian_gradient(
        &self,
        q: &SVector<f64, 3>,
        v: &SVector<f64, 3>,
    ) -> Option<dirac::LagrangianGradient<3>> {
        (q[0] <= 0.5).then(|| dirac::LagrangianGradient {
            value: self.lagrangian(q, v),
            q: SVector::from([-q[0].sin(), -2.0 * q[1] * q[2], -q[1] * q[1]]),
            v: *v,
        })
    }

    fn lagrangian_hessian(
        &self,
        q: &SVector<f64, 3>,
        v: &SVector<f64, 3>,
    ) -> Option<dirac::LagrangianHessian<3>> {
        let gradient = self.lagrangian_gradient(q, v)?;
        let qq = dirac::nalgebra::Matrix3::new(
            -q[0].cos(),
            0.0,
            0.0,
            0.0,
            -2.0 * q[2],
            -2.0 * q[1],
            0.0,
            -2.0 * q[1],
            0.0,
        );
        Some(dirac::LagrangianHessian {
            gradient,
            qq,
            qv: dirac::nalgebra::Matrix3::zeros(),
            vv: dirac::nalgebra::Matrix3::identity(),
        })
    }
}

/// The Jacobian the assembly adds is the derivative of its residual: against central
/// differences, off the solution with multipliers that are not zero, at each constraint point,
/// under the midpoint and trapezoid rules, for a one-form in closed form (with a Lagrangian whose
/// `∂²L/∂q²` and `∂²L/∂q∂v` vanish), for
/// one beside a holonomic constraint, for a separable Lagrangian, for one whose `∂²L/∂q∂v`
/// has a single entry off its diagonal, and for closed forms that stop within a step.
#[test]
fn the_jacobian_is_the_residuals_derivative() {
    use dirac::euler_lagrange::EulerLagrange;
    fn check<S: DiracSystem<3> + Copy>(system: S, q: SVector<f64, 3>, v: SVector<f64, 3>) {
        let state = State::new(0.0, q, v, v);
        // The midpoint rule (one node: the rows straight into the buffers where they can) and
        // the trapezoid rule (two nodes, zero weights among their seeds: out of line).
        let rules = [Quadrature::midpoint(), Quadrature::trapezoid()];
        let points = [
            ConstraintPoint::Start,
            ConstraintPoint::Midpoint,
            ConstraintPoint::End,
        ];
        for (rule, point) in rules
            .iter()
            .flat_map(|rule| points.iter().map(move |point| (rule, *point)))
        {
            let discrete = DiscreteLagrangian::new(system, rule.clone(), 0.05);
            let mut equations = EulerLagrange::new(discrete).unwrap();
            equations.set_constraint_point(point);
            equations.begin(&state);
            let n = equations.unknowns();
            let mut x = DVector::zeros(n);
            equations.predict(&state, None, &mut x);
            for (i, xi) in x.iter_mut().enumerate() {
                *xi += 0.05 * (i + 1) as f64;
            }
            let mut residual = DVector::zeros(n);
            let mut jacobian = DMatrix::zeros(n, n);
            equations.assemble(&state, &x, &mut residual, Some(&mut jacobian));
            // The residual is the same function with a Jacobian and without, bit for bit.
            let mut plain = DVector::zeros(n);
            equations.assemble(&state, &x, &mut plain, None);
            assert_eq!(residual, plain, "{} {point:?}", rule.name());
            let delta = 1e-6;
            let mut differenced = DMatrix::zeros(n, n);
            for j in 0..n {
                let (mut up, mut down) = (x.clone(), x.clone());
                up[j] += delta;
                down[j] -= delta;
                let (mut r_up, mut r_down) = (DVector::zeros(n), DVector::zeros(n));
                equations.assemble(&state, &up, &mut r_up, None);
                equations.assemble(&state, &down, &mut r_down, None);
                differenced.set_column(j, &((r_up - r_down) / (2.0 * delta)));
            }
            let error = (&jacobian - &differenced).amax();
            assert!(
                error <= 1e-6 * (1.0 + differenced.amax()),
                "{} {point:?}: {jacobian} against {differenced} (error {error:e})",
                rule.name()
            );
        }
    }
    check(
        Blade,
        vector![0.1, 0.2, 0.5],
        vector![0.5f64.cos(), 0.5f64.sin(), 1.0],
    );
    check(
        HeldBead { g: 9.81 },
        vector![0.6, 0.0, -0.8],
        vector![0.0, 1.0, 0.0],
    );
    check(Separable, vector![0.6, -0.3, 0.8], vector![0.2, 1.0, -0.4]);
    check(Skew, vector![0.6, -0.3, 0.8], vector![0.2, 1.0, -0.4]);
    check(Partial, vector![0.4, -0.3, 0.8], vector![3.0, 1.0, -0.4]);
    // The step skipped the Hessian's products it was told vanish: they did.
    let (blade, separable) = (
        Blade::LAGRANGIAN_HESSIAN_ZEROS,
        Separable::LAGRANGIAN_HESSIAN_ZEROS,
    );
    assert!((0..3).all(|i| (0..3).all(|j| blade.qq[i][j] && blade.qv[i][j])));
    assert!(blade.vanishes(0, 1) && !blade.vanishes(1, 1));
    assert!(!separable.qq[0][0] && separable.qq[0][1] && separable.qv == [[true; 3]; 3]);
    assert!(separable.vanishes(0, 1) && !separable.vanishes(1, 2));
    let skew = Skew::LAGRANGIAN_HESSIAN_ZEROS;
    let off_diagonal = |i: usize, j: usize| i != j;
    assert!((0..3).all(|i| (0..3).all(|j| skew.qq[i][j] == off_diagonal(i, j))));
    assert!((0..3).all(|i| (0..3).all(|j| skew.qv[i][j] == ((i, j) != (1, 0)))));
    assert!((0..3).all(|i| (0..3).all(|j| skew.vv[i][j] == off_diagonal(i, j))));
    assert!(!skew.vanishes(0, 1) && !skew.vanishes(1, 0) && skew.vanishes(0, 2));
}

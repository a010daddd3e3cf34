//! A rigid body whose spin about its third body axis turns a flywheel, built from two components
//! written once: the free body on `SO(3)` ([`FreeBody`]) and a flywheel ([`Flywheel`]), joined
//! by the junction `Ω₃ = θ̇` (a fixed covector of the body angular velocity: a shaft along the
//! body's third axis).
//!
//! The wheel's momentum `i θ̇` does not turn with the body (a rotor carried by the body would,
//! which makes a gyrostat: one model, not this interconnection). Euler's equations with the
//! shaft's force `λ e₃` on the body and `−λ` on the wheel give `J' Ω̇ = J Ω × Ω` with
//! `J' = J + i e₃e₃ᵀ`. With `I₁ = I₂` the force vanishes (`(I₃ + i) Ω̇₃ = 0`) and the body moves
//! as the free symmetric body, a closed form ([`rigid_body::symmetric`]); otherwise
//! [`rigid_body::with_wheel`] integrates it with Dop853.

use dirac::modular::Modular;
use dirac::nalgebra::DVector;
use dirac::prelude::*;

use super::Report;
use super::components::Flywheel;
use super::rigid_body::{self, ASYMMETRIC, FreeBody, HeavyTop};

/// The flywheel's inertia.
pub const WHEEL: f64 = 0.7;

/// The body and the wheel joined by the shaft, stepped by parts with the midpoint rule;
/// instances `body` (coordinates `R_x`, `R_y`, `R_z`) and `wheel` (`theta`), junction `shaft`.
pub fn by_parts(
    body: FreeBody,
    wheel: f64,
    space: Product<0, 1, 0>,
    h: f64,
) -> Result<Modular, DiracError> {
    let mut parts = Modular::new(Quadrature::midpoint(), h)?;
    parts.add_on_space("body", body, space)?;
    parts.add("wheel", Flywheel { i: wheel })?;
    parts.join(
        Junction::new("shaft")
            .flow("body.R_z", 1.0)
            .flow("wheel.theta", -1.0),
    )?;
    Ok(parts)
}

/// Starts `parts` ([`by_parts`]) at attitude `r0`, body angular velocity `omega0` and wheel
/// angle 0 (turning at `Ω₃`).
pub fn start(
    parts: &mut Modular,
    (r0, omega0): (Matrix3<f64>, Vector3<f64>),
) -> Result<(), DiracError> {
    let mut q: Vec<f64> = r0.transpose().iter().copied().collect();
    q.push(0.0);
    parts.start_from_velocity(&q, &[omega0[0], omega0[1], omega0[2], omega0[2]])
}

/// The body's attitude in `q` of [`by_parts`] (its first nine numbers, row by row).
pub fn attitude(q: &DVector<f64>) -> Matrix3<f64> {
    Matrix3::from_row_slice(&q.as_slice()[..9])
}

/// The same interconnection as one model on `R × SO(3)` (the wheel's angle, the attitude), the
/// shaft a one-form held at `Start`: the positions [`by_parts`] steps to (its impulses split
/// differently over the step's ends).
#[derive(Debug, Clone, Copy)]
pub struct BodyOnShaft {
    pub body: FreeBody,
    pub wheel: f64,
}

impl DiracSystem<4, Product<1, 1, 0>> for BodyOnShaft {
    const ONE_FORMS: usize = 1;

    fn lagrangian<D: Scalar>(&self, _q: &Configuration<D, 1, 1, 0>, v: &Rates<D, 1, 1, 0>) -> D {
        let (w, j) = (v.rotation[0], self.body.j);
        let body = (w[0] * w[0] * j[0] + w[1] * w[1] * j[1] + w[2] * w[2] * j[2]) * 0.5;
        body + v.vector[0] * v.vector[0] * (0.5 * self.wheel)
    }

    fn one_form<D: Scalar>(&self, _q: &Configuration<D, 1, 1, 0>, _a: usize) -> Rates<D, 1, 1, 0> {
        let (zero, one) = (D::from(0.0), D::from(1.0));
        Rates {
            vector: SVector::from([-one]),
            rotation: [Vector3::new(zero, zero, one)],
            direction: [],
        }
    }

    fn constraint_point(&self) -> ConstraintPoint {
        ConstraintPoint::Start
    }

    fn coordinate_name(&self, i: usize) -> String {
        ["theta", "R"][i].into()
    }
}

/// [`BodyOnShaft`] stepped with the midpoint rule (Cayley), started as [`start`] starts the
/// parts: attitude `r0`, body angular velocity `omega0`, the wheel at angle 0 turning at `Ω₃`.
pub fn one_model(
    body: FreeBody,
    wheel: f64,
    h: f64,
    (r0, omega0): (Matrix3<f64>, Vector3<f64>),
) -> Result<ManifoldStepper<BodyOnShaft, 4, Product<1, 1, 0>>, DiracError> {
    let model = BodyOnShaft { body, wheel };
    let mut one = Stepper::on_manifold(model, Product::cayley(), Quadrature::midpoint(), h)?;
    let q0 = Configuration {
        vector: SVector::from([0.0]),
        rotation: [r0],
        direction: [],
    };
    let v0 = Rates {
        vector: SVector::from([omega0[2]]),
        rotation: [omega0],
        direction: [],
    };
    one.start_from_velocity(q0, v0)?;
    Ok(one)
}

/// The body's attitude and `J'Ω` at `t_end` by Dop853 at `tolerance` (see the [module](self)).
pub fn reference(
    body: &FreeBody,
    wheel: f64,
    (r0, omega0): (Matrix3<f64>, Vector3<f64>),
    t_end: f64,
    tolerance: f64,
) -> Result<(Matrix3<f64>, Vector3<f64>), String> {
    let [a, b, c] = body.j;
    let free = HeavyTop {
        j: [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]],
        m: 0.0,
        g: 0.0,
        rho: [0.0; 3],
    };
    rigid_body::with_wheel(&free, wheel, &r0, &omega0, t_end, tolerance)
}

/// The tour's row: the asymmetric body and the wheel by parts (Cayley, midpoint, h = 0.01) to
/// T = 10 against the Dop853 reference; Tellegen's theorem on the shaft and the energy.
pub fn report() -> Result<Report, DiracError> {
    let (h, steps) = (0.01, 1000);
    let begin = rigid_body::free_start();
    let clock = std::time::Instant::now();
    let mut parts = by_parts(ASYMMETRIC, WHEEL, Product::cayley(), h)?;
    start(&mut parts, begin)?;
    let energy =
        |parts: &Modular| -> Result<f64, DiracError> { Ok(parts.energies()?.iter().sum()) };
    let e0 = energy(&parts)?;
    let (mut drift, mut tellegen): (f64, f64) = (0.0, 0.0);
    for _ in 0..steps {
        parts.step()?;
        drift = drift.max((energy(&parts)? - e0).abs());
        tellegen = tellegen.max(tellegen_in_ulps(&parts)?);
    }
    let wall = clock.elapsed();
    let t = steps as f64 * h;
    let (r, _) = reference(&ASYMMETRIC, WHEEL, begin, t, 1e-13)
        .map_err(|e| DiracError::Unsupported(format!("the reference: {e}")))?;
    let error = (attitude(&parts.q()) - r).amax();
    Ok(Report {
        scene: "rigid body + flywheel, by parts",
        quadrature: "midpoint".into(),
        h,
        steps,
        max_energy_error: Some(drift),
        wall,
        check: format!("|R − R_ref| = {error:.0e} at T = {t}; Tellegen {tellegen:.1} ε|e||θ|"),
    })
}

/// Tellegen's theorem on the shaft over the last step of [`by_parts`]: the net port work in
/// units of `ε |e| (|θ| + 1)`, the round-off of the wheel's stored angle that its step is read
/// from (the body's step is its chart increment, read off no stored number).
pub fn tellegen_in_ulps(parts: &Modular) -> Result<f64, DiracError> {
    let ports = parts.ports()?;
    let theta = parts.q()[9];
    let size = f64::EPSILON * ports.efforts[0].abs() * (theta.abs() + 1.0);
    Ok(ports.net_work().abs() / size.max(f64::MIN_POSITIVE))
}

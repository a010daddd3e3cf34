//! A DC motor driving a pendulum arm: two components (`components.rs`), the motor's electrical
//! and mechanical sides coupled inside it by a gyrator, joined to the arm by the shaft junction
//! `motor.dtheta − arm.dphi`, driven by a voltage `u`.
//!
//! With `y = (q, i, θ, ω)` the model is the ODE
//! `q' = i`, `l i' = u − r i − k ω`, `θ' = ω`, `(j + I) ω' = k i − m g d sin θ`, whose rest
//! state under a constant `u` is `i = u / r`, `sin θ = k u / (r m g d)`.
//!
//! The gyrator does no work on a step (the midpoint rule evaluates both of its forces at the
//! step's mean velocities: `−k Δθ Δq / h + k Δq Δθ / h = 0`), so the motor, whose Lagrangian
//! is quadratic, balances its energy exactly: `ΔE_motor = u Δq − r Δq² / h + W_shaft`. The
//! arm's energy follows its shaft work `−W_shaft` to the midpoint rule's order (its potential is
//! not quadratic).

use dirac::prelude::*;
use ode_solvers::System;

use super::components::{Arm, DcMotor};

/// The motor driving the arm.
pub type MotorArm = Interconnection<DcMotor, Arm, 2, 1, 3, 1>;

/// The scene's motor and arm.
pub const MOTOR: DcMotor = DcMotor {
    l: 0.1,
    r: 1.0,
    k: 0.5,
    j: 0.01,
};
pub const ARM: Arm = Arm {
    inertia: 0.1,
    mgd: 1.0,
};
/// The supply voltage.
pub const U: f64 = 1.0;

/// The motor and the arm joined at the shaft.
pub fn motor_arm() -> Result<MotorArm, DiracError> {
    Interconnection::new(
        ("motor", MOTOR),
        ("arm", ARM),
        [Junction::new("shaft")
            .flow("motor.theta", 1.0)
            .flow("arm.phi", -1.0)],
    )
}

/// The arm's angle at rest under the voltage `U`: `sin θ = k U / (r m g d)`.
pub fn rest_angle() -> f64 {
    (MOTOR.k * U / (MOTOR.r * ARM.mgd)).asin()
}

/// The same model as one ODE in `(q, i, θ, ω)`, for Dop853.
pub struct MotorArmOde;

impl System<f64, ode_solvers::SVector<f64, 4>> for MotorArmOde {
    fn system(
        &self,
        _t: f64,
        y: &ode_solvers::SVector<f64, 4>,
        dy: &mut ode_solvers::SVector<f64, 4>,
    ) {
        let (m, a) = (MOTOR, ARM);
        dy[0] = y[1];
        dy[1] = (U - m.r * y[1] - m.k * y[3]) / m.l;
        dy[2] = y[3];
        dy[3] = (m.k * y[1] - a.mgd * y[2].sin()) / (m.j + a.inertia);
    }
}

/// Per step, over `steps` steps of size `h` from rest with the arm hanging down: the largest
/// error of the motor's exact balance `ΔE_motor − (u Δq − r Δq²/h + W_shaft)` and of Tellegen's
/// `W_motor + W_arm` (both relative to the step's largest term), and the whole model's balance
/// defect `ΔE − (u Δq − r Δq²/h)` summed over the run (the arm's, O(h²) over a fixed time).
pub fn balance(h: f64, steps: usize) -> Result<(f64, f64, f64), DiracError> {
    let system = motor_arm()?;
    let mut stepper = Stepper::new(system.clone(), Quadrature::midpoint(), h)?;
    stepper.set_input("motor.u", U)?;
    stepper.start_from_velocity(SVector::zeros(), SVector::zeros())?;
    let (mut motor, mut tellegen, mut defect): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let mut e = system.energies(&stepper.q(), &stepper.v()?);
    for _ in 0..steps {
        let q = stepper.q();
        stepper.step()?;
        let ports = system.ports(&q, &stepper.q(), stepper.multipliers(), h)?;
        let next = system.energies(&stepper.q(), &stepper.v()?);
        let dq = stepper.q()[0] - q[0];
        let supplied = U * dq - MOTOR.r * dq * dq / h;
        let size = supplied
            .abs()
            .max(ports.scale)
            .max(e[0].abs())
            .max(f64::MIN_POSITIVE);
        motor = motor.max((next[0] - e[0] - supplied - ports.work[0]).abs() / size);
        tellegen = tellegen.max(ports.net_work().abs() / ports.scale.max(f64::MIN_POSITIVE));
        defect += next[0] + next[1] - e[0] - e[1] - supplied;
        e = next;
    }
    Ok((motor, tellegen, defect.abs()))
}

/// The state `(q, θ)` at `t_end` with step `h`, from rest with the arm hanging down.
pub fn at(h: f64, t_end: f64) -> Result<SVector<f64, 3>, DiracError> {
    let mut stepper = Stepper::new(motor_arm()?, Quadrature::midpoint(), h)?;
    stepper.set_input("motor.u", U)?;
    stepper.start_from_velocity(SVector::zeros(), SVector::zeros())?;
    for _ in 0..(t_end / h).round() as usize {
        stepper.step()?;
    }
    Ok(stepper.q())
}

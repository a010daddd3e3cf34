//! Two oscillators interconnected through a massless port y: the port is a coordinate without
//! kinetic energy, joined to x1 by the constant one-form dy − dx1.

use dirac::prelude::*;

use super::components::{MassSpring, Tethered};
use super::{Report, timed};

/// L = ½m1ẋ1² + ½m2ẋ2² − ½k1x1² − ½k2(x2 − y)², w = dy − dx1.
#[dirac_system(
    coordinates(x1, x2, y),
    lagrangian = 0.5 * m1 * dot(x1).powi(2) + 0.5 * m2 * dot(x2).powi(2)
        - 0.5 * k1 * x1.powi(2) - 0.5 * k2 * (x2 - y).powi(2),
    constraints(dy - dx1),
)]
#[derive(Debug, Clone, Copy)]
pub struct Port {
    pub m1: f64,
    pub m2: f64,
    pub k1: f64,
    pub k2: f64,
}

pub const SCENE: Port = Port {
    m1: 1.0,
    m2: 1.0,
    k1: 1.0,
    k2: 1.0,
};
/// x1(20), x2(20) from x1(0) = y(0) = 1, x2(0) = 0 at rest.
pub const X20: [f64; 2] = [0.6945591, 0.17574477];

pub fn q0() -> SVector<f64, 3> {
    vector![1.0, 0.0, 1.0]
}

/// (x1, x2) at T = 20 with step `h`, and the largest port violation |y − x1| on the way.
pub fn at_20(h: f64) -> Result<(SVector<f64, 2>, f64), DiracError> {
    let mut stepper = Stepper::new(SCENE, Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(q0(), SVector::zeros())?;
    let mut port: f64 = 0.0;
    for _ in 0..(20.0 / h).round() as usize {
        stepper.step()?;
        port = port.max((stepper.q()[2] - stepper.q()[0]).abs());
    }
    Ok((vector![stepper.q()[0], stepper.q()[1]], port))
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 20.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_velocity(q0(), SVector::zeros())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    trajectory.save_csv(format!(
        "output/port_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let q = stepper.q();
    Ok(Report {
        scene: "port",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "|x(20) − exact| = {:.2e}, |y − x1| ≤ {:.1e}",
            (q[0] - X20[0]).abs().max((q[1] - X20[1]).abs()),
            trajectory.max_constraint_violation()
        ),
    })
}

/// The port scene from two components: oscillator 1 (`left`, a mass on a spring to the ground)
/// and the tethered mass (`right`, mass 2 on a spring whose far end is the port), joined by the
/// port junction `dright.end − dleft.x`.
pub type FromComponents = Interconnection<MassSpring, Tethered, 1, 2, 3, 1>;

/// The scene `p` built from its two components; coordinates `left.x, right.x, right.end`
/// (today's `x1, x2, y`).
pub fn from_components(p: &Port) -> Result<FromComponents, DiracError> {
    Interconnection::new(
        ("left", MassSpring { m: p.m1, k: p.k1 }),
        ("right", Tethered { m: p.m2, k: p.k2 }),
        [Junction::new("port")
            .flow("right.end", 1.0)
            .flow("left.x", -1.0)],
    )
}

/// The tour's row: the port scene from its components against the monolithic one to T = 10,
/// and its ports read at every step.
pub fn components_report() -> Result<Report, DiracError> {
    let joined = from_components(&SCENE)?;
    let gap = super::ports::gap_to_whole(joined.clone(), SCENE, q0(), [0, 1, 2])?;
    super::ports::report("port (2 parts)", &joined, q0(), gap)
}

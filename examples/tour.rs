//! Runs every scene, prints one table (scene, quadrature, h, steps, max energy error, wall time,
//! check against the known answer) and writes it to `output/tour.csv`, beside one CSV trajectory
//! per run. Unconstrained scenes run with every tour quadrature, and an orbit of eccentricity
//! 0.9 at a fixed step and time-transformed; constrained ones with the
//! midpoint rule (the knife edge with each discrete constraint point); Lotka–Volterra (linear
//! in the velocities) and the rolling disk with the Gauss rules; and the trapezoid rule's
//! refusal of the ill-posed LC circuit is shown. Pictures: `output/convergence.png`,
//! `output/energy_error.png`, `output/knife_edge.png`, `output/lc_circuit.png`,
//! `output/cart_pole_lqr.png`, `output/long_horizon_energy.png`, `output/heavy_top.png`,
//! `output/heavy_top_invariants.png`, `output/rigid_chain.png`, `output/humanoid.png`,
//! `output/membrane.png`. Models
//! on rotations and unit vectors: the heavy top (both
//! retractions), the 3D pendulum against a quaternion reference, the spherical pendulum on `S²`
//! beside the Cartesian one, the rolling ball at each constraint point, a satellite's slew, and
//! a satellite with reaction wheels held by LQR on the step map's derivatives. Mechanisms of
//! bodies joined by joints: a four-bar linkage, a slider-crank and a tumbling humanoid. Fields:
//! the sine-Gordon kink–antikink collision on a line, a drum in two of its modes on a plane.
//!
//! `cargo run --release --example tour`

use dirac::{ConstraintPoint, DiracError, Product, Quadrature};
use scenes::{Report, circuit, knife_edge, rigid_body, rolling_ball};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    type Scene = fn(Quadrature) -> Result<Report, DiracError>;
    let scenes: [Scene; 6] = [
        scenes::oscillator::report,
        scenes::pendulum::report,
        scenes::double_pendulum::report,
        scenes::kepler::report,
        scenes::chain::report,
        scenes::hamiltonian::report,
    ];
    let mut reports = Vec::new();
    for scene in scenes {
        for quadrature in scenes::quadratures() {
            reports.push(scene(quadrature)?);
        }
    }
    type Constrained = fn(Quadrature) -> Result<Report, DiracError>;
    let constrained: [Constrained; 4] = [
        circuit::report,
        circuit::rlc_report,
        scenes::cartesian_pendulum::report,
        scenes::port::report,
    ];
    for scene in constrained {
        reports.push(scene(Quadrature::midpoint())?);
    }
    reports.extend(scenes::kepler::eccentric_reports()?);
    reports.push(circuit::driven_report()?);
    reports.push(circuit::subcircuits_report()?);
    reports.push(circuit::by_parts_report()?);
    reports.push(scenes::port::components_report()?);
    reports.push(scenes::ladder::report()?);
    reports.push(scenes::ladder::modular_report()?);
    // The newer model classes with the Gauss rules (the trapezoid is refused for a Lagrangian
    // linear in the velocities).
    type Newer = fn(Quadrature) -> Result<Report, DiracError>;
    let newer: [Newer; 2] = [scenes::lotka_volterra::report, scenes::rolling_disk::report];
    for scene in newer {
        for quadrature in scenes::quadratures()
            .into_iter()
            .filter(|q| *q != Quadrature::trapezoid())
        {
            reports.push(scene(quadrature)?);
        }
    }
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        reports.push(knife_edge::report_point(point)?);
    }
    // Rotations and unit vectors.
    for space in [Product::cayley(), Product::exp()] {
        reports.push(rigid_body::report(space)?);
    }
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2)?] {
        reports.push(rigid_body::pendulum_report(quadrature)?);
    }
    reports.extend(scenes::spherical_pendulum::reports()?);
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        reports.push(rolling_ball::report(point)?);
    }
    reports.push(scenes::shafted_body::report()?);
    reports.push(scenes::satellite::report()?);
    reports.push(scenes::reaction_wheels::report()?);
    // Mechanisms in maximal coordinates: bodies joined by joints, by parts.
    reports.extend(scenes::mechanism::reports()?);
    // A field: the sine-Gordon kink–antikink collision.
    reports.push(scenes::field::report()?);
    // A field on the plane: a drum in two of its modes.
    reports.push(scenes::membrane::report()?);
    scenes::print_table(&reports);
    scenes::save_table(&reports, "output/tour.csv")?;
    match circuit::lc_at_10(Quadrature::trapezoid(), 0.01) {
        Err(error) => {
            println!("\nLC circuit with the trapezoid rule is refused, as it must be:\n  {error}")
        }
        Ok(_) => println!("\nLC circuit with the trapezoid rule: unexpectedly accepted"),
    }
    println!("\nwrote output/tour.csv and one trajectory CSV per row to output/");
    for figure in scenes::figures::draw_all()? {
        println!("wrote {figure}");
    }
    Ok(())
}

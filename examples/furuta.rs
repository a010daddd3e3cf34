//! A Furuta pendulum balanced upright from a 0.2 rad tilt by discrete LQR on the step map's exact
//! derivatives, with the motor's torque saturated at 0.5 N m: the feedback runs inside one `Run`.
//! A motor limited to 0.2 N m cannot catch the same tilt.
//! `cargo run --release --example furuta`.

use scenes::furuta;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let h = 0.005;
    let k = furuta::linearisation_and_gain(h, 10.0)?.k;
    println!("LQR gain K = {k:.3}");
    let (samples, solution) = furuta::closed_loop(h, 0.2, furuta::TAU_MAX, 2000, 200)?;
    let saturated = samples
        .iter()
        .filter(|s| s.tau.abs() == furuta::TAU_MAX)
        .count();
    println!(
        "torque saturated at ±{} N m for {saturated} of {} steps",
        furuta::TAU_MAX,
        samples.len()
    );
    for (t, q) in solution.trajectory.t().iter().zip(solution.trajectory.q()) {
        println!("t = {t:4.1} s   φ = {:+.3e}   θ = {:+.3e}", q[0], q[1]);
    }
    // The motor's work against the pendulum's energy, booked by the library step by step (the
    // defect is the midpoint rule's energy error on this nonlinear model, O(h²)).
    println!("{}", solution.trajectory.energy_balance()?);
    let (weak, _) = furuta::closed_loop(h, 0.2, 0.2, 2000, 200)?;
    let fallen = weak.last().expect("samples");
    println!(
        "limited to 0.2 N m: at t = {:.1} s, θ = {:+.2} rad (the pendulum fell)",
        fallen.t, fallen.theta
    );
    Ok(())
}

//! A satellite on SO(3) driven by body torques, the feedback inside one run each time: slewed to
//! a target attitude by a proportional-derivative law, then detumbled from a tumble by a
//! saturated rate-damping law, with the energy balance printed by the library.
//! `cargo run --release --example satellite`.

use dirac::prelude::*;
use scenes::satellite;

fn main() -> Result<(), DiracError> {
    scenes::print_table(&[satellite::report()?]);

    let omega0 = Vector3::new(0.3, 1.0, -0.5);
    let solution = satellite::detumbled(omega0, 0.2, 0.01, 60.0, 1000)?;
    let trajectory = &solution.trajectory;
    println!(
        "\ndetumbling from |Ω| = {:.3} rad/s, torques limited to {} N m per axis:",
        omega0.norm(),
        satellite::DETUMBLE_TORQUE
    );
    for ((t, v), e) in trajectory
        .t()
        .iter()
        .zip(trajectory.v())
        .zip(trajectory.energy())
    {
        println!(
            "t = {t:4.0} s   |Ω| = {:.3e} rad/s   kinetic energy = {e:.6e} J",
            v.rotation[0].norm()
        );
    }
    println!("\n{}", trajectory.energy_balance()?);
    Ok(())
}

//! An RLC ladder of three sections built from components, charged from rest by a 1 V source,
//! its energy booked by the library component by component: the resistors take exactly what the
//! capacitors keep. `cargo run --release --example rlc_ladder`.

use scenes::rlc_ladder;

fn main() -> Result<(), dirac::DiracError> {
    let (l, r, c, voltage) = (1.0, 1.0, 1.0, 1.0);
    let (solution, ledger) =
        rlc_ladder::charged(rlc_ladder::ladder(l, r, c), voltage, 0.01, 60.0, 1000)?;
    for (t, q) in solution.trajectory.t().iter().zip(solution.trajectory.q()) {
        println!(
            "t = {t:4.1} s   capacitor charges {:.6} {:.6} {:.6}",
            q[3], q[6], q[9]
        );
    }
    println!("\n{}", solution.trajectory.energy_balance()?);
    println!("\n{ledger}");
    let dissipated: f64 = -ledger
        .components
        .iter()
        .map(|c| c.forces)
        .filter(|w| *w < 0.0)
        .sum::<f64>();
    println!(
        "the resistors took {dissipated:.9} J; charging 3 × {c} F to {voltage} V through them takes ½ V² Σc = {:.9} J",
        0.5 * voltage * voltage * 3.0 * c
    );
    Ok(())
}

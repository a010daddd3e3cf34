//! Discrete LQR on the step map's exact derivatives: an inverted pendulum on a cart, balanced
//! upright from a 0.3 rad tilt by feedback through the model's input, simulated by the
//! variational integrator. `cargo run --release --example lqr` writes `output/cart_pole_lqr.png`.

use scenes::cart_pole;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let h = 0.01;
    let cart_pole::Lqr { a, b, k } = cart_pole::linearisation_and_gain(h, 0.1)?;
    let radius = |m: &dirac::nalgebra::DMatrix<f64>| {
        m.complex_eigenvalues()
            .iter()
            .map(|e| e.norm())
            .fold(0.0, f64::max)
    };
    println!(
        "spectral radius of A: {:.4} (upright is unstable)",
        radius(&a)
    );
    println!("spectral radius of A − BK: {:.4}", radius(&(&a - &b * &k)));
    println!("LQR gain K = {:.3}", k);
    let samples = cart_pole::closed_loop(h, 0.3, 1000)?;
    let cart_pole::Sample { t, x, theta, u } = *samples.last().expect("samples");
    println!(
        "closed loop from θ = 0.3: at t = {t:.1} s, x = {x:.2e}, θ = {theta:.2e}, u = {u:.2e}"
    );
    std::fs::create_dir_all("output")?;
    println!("wrote {}", scenes::figures::cart_pole_lqr()?);
    Ok(())
}

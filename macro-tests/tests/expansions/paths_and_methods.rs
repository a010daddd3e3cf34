use dirac::prelude::*;

const C: f64 = 2.0;

/// Paths and user constants are constants wherever they stand; a method is the function of the
/// same name with the receiver first; powf takes an integer literal or a dual exponent.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * dot(x).powi(2)
        + g0 * g1 / (4.0 * std::f64::consts::PI) * ln(x * x + 1.0)
        + C * x.atan2(dot(y)) + m.atan2(x) + powf(dot(x), 2) + dot(x).powf(y) + pow(2.0, y)
        - std::f64::consts::PI / (2.0 * C) * y,
)]
struct Vortices {
    g0: f64,
    g1: f64,
    m: f64,
}

#[test]
fn compiles_and_runs() {
    let system = Vortices {
        g0: 1.0,
        g1: 3.0,
        m: 0.5,
    };
    let (x, y, vx, vy) = (0.5_f64, 0.25_f64, 1.5_f64, -0.5_f64);
    let expected = 0.5 * vx * vx
        + 3.0 / (4.0 * std::f64::consts::PI) * (x * x + 1.0).ln()
        + 2.0 * x.atan2(vy)
        + 0.5_f64.atan2(x)
        + vx * vx
        + vx.powf(y)
        + 2.0_f64.powf(y)
        - std::f64::consts::PI / 4.0 * y;
    let l: f64 = system.lagrangian(&vector![x, y], &vector![vx, vy]);
    assert!((l - expected).abs() < 1e-14, "L = {l}, expected {expected}");
}

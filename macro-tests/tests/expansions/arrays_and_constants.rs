use dirac::prelude::*;

/// Constants on the left of duals, parameter arrays, coordinate arrays and every function form.
#[dirac_system(
    coordinates(x, theta[2]),
    lagrangian = 0.5 * m[0] * dot(x).powi(2)
        + 0.5 * m[1] * (dot(theta[0]).powi(2) + dot(theta[1]) * dot(theta[1]))
        - (1.0 - cos(theta[0])) - 2.0 / (3.0 + x * x) + pow(2.0, theta[1]) * 0.0
        + atan2(1.0, 2.0) * 0.0 - sqrt(abs(x) + 1.0) + powf(x * x + 1.0, 1.5) * 0.0,
)]
struct Mixed {
    m: [f64; 2],
}

#[test]
fn compiles_and_runs() {
    let system = Mixed { m: [2.0, 3.0] };
    assert_eq!(system.coordinate_name(2), "theta[1]");
    assert_eq!(system.parameters()[1], ("m[1]".to_string(), 3.0));
    let (q, v) = (vector![0.0, 0.0, 0.0], vector![1.0, 1.0, 2.0]);
    // 0.5·2·1 + 0.5·3·(1 + 4) − 0 − 2/3 − 1.
    let l: f64 = system.lagrangian(&q, &v);
    assert!((l - (1.0 + 7.5 - 2.0 / 3.0 - 1.0)).abs() < 1e-14);
}

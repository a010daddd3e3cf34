//! Measurements shared by the integration tests.
#![allow(dead_code)]

pub mod monolithic_rlc;

/// Least-squares slope of ln(error) against ln(h): the measured order of convergence.
pub fn slope(hs: &[f64], errors: &[f64]) -> f64 {
    let x: Vec<f64> = hs.iter().map(|h| h.ln()).collect();
    let y: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

/// Measures the order of `errors` over the steps `hs`, prints it, and asserts it is `expected`
/// to ±0.3.
pub fn assert_order(what: &str, hs: &[f64], errors: &[f64], expected: f64) {
    let measured = slope(hs, errors);
    println!("{what}: {measured:.2} {errors:?}");
    assert!(
        (measured - expected).abs() < 0.3,
        "{what}: order {measured}, expected {expected}, {errors:?}"
    );
}

/// The largest energy error `|E − E_0|` in the first and in the last tenth of a run. A
/// symplectic method's error oscillates, so the two are alike; a drifting one grows.
pub fn energy_error_first_and_last_tenth(energy: &[f64]) -> (f64, f64) {
    let e0 = energy[0];
    let errors: Vec<f64> = energy.iter().map(|e| (e - e0).abs()).collect();
    let tenth = errors.len() / 10;
    let max = |s: &[f64]| s.iter().cloned().fold(0.0, f64::max);
    (max(&errors[..tenth]), max(&errors[errors.len() - tenth..]))
}

/// The header row of a trajectory's CSV.
pub fn csv_header<const N: usize>(trajectory: &dirac::Trajectory<N>) -> String {
    let mut csv = Vec::new();
    trajectory.write_csv(&mut csv).expect("CSV into memory");
    let text = String::from_utf8(csv).expect("UTF-8 CSV");
    text.lines().next().unwrap_or_default().to_string()
}

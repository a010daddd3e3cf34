mod scenes;
use dirac::prelude::*;
fn main() {
    let model = scenes::double_pendulum::DoublePendulum {
        m1: 1.0,
        m2: 1.0,
        l1: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mode = std::env::args().nth(1).unwrap_or_default();
    let n: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(20000);
    let mut s = Stepper::new(model, Quadrature::midpoint(), 0.01).unwrap();
    s.start_from_velocity(vector![half_pi, half_pi], SVector::zeros())
        .unwrap();
    let mut acc = 0.0;
    let t0 = std::time::Instant::now();
    for _ in 0..n {
        if mode == "lin" {
            let a = s.step_linearised().unwrap();
            acc += a.q_q[(0, 0)];
        } else {
            s.step().unwrap();
        }
    }
    println!("{acc} {} {:?}/step", s.q()[0], t0.elapsed() / n as u32);
}

#[path = "scenes/mod.rs"]
mod scenes;
use dirac::prelude::*;
use scenes::double_pendulum::*;
fn run(label: &str, m1: f64, quad: Quadrature, h: f64, steps: usize) {
    let model = DoublePendulum { m1, ..SCENE };
    let name = quad.name();
    let mut s = Stepper::new(model, quad, h)
        .unwrap()
        .with_newton_options(NewtonOptions {
            max_contraction: f64::INFINITY,
            ..Default::default()
        })
        .unwrap();
    s.start_from_velocity(q0(), v0()).unwrap();
    let e0 = s.energy().unwrap();
    let mut maxde: f64 = 0.0;
    let mut prev_e = e0;
    let mut maxc: f64 = 0.0;
    let mut hist = [0usize; 8];
    for k in 0..steps {
        let r = s.step();
        if r.is_err() {
            println!("{label} {name} h={h} step {k}: {:?}", r.err());
            break;
        }
        let e = s.energy().unwrap_or(f64::NAN);
        let c = s.last_report().unwrap().contraction;
        let bin = if c == 0.0 {
            0
        } else {
            ((c.log10() + 7.0).max(0.0) as usize).min(7)
        };
        hist[bin] += 1;
        let jump = (e - prev_e).abs();
        prev_e = e;
        if jump > 0.5 || c > 0.1 {
            println!(
                "{label} {name} {k} dE={:.3e} c={c:.3e} q={:?} it={}",
                e - e0,
                s.q().as_slice(),
                s.last_report().unwrap().iterations
            );
        }
        maxde = maxde.max((e - e0).abs());
        maxc = maxc.max(c);
    }
    println!(
        "{label} {name} h={h}: max dE {maxde:.3e} max contraction {maxc:.3e} hist(log10 bins from 1e-7) {hist:?}"
    );
}
fn main() {
    for q in [
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::gauss(2).unwrap(),
    ] {
        run("m1=0", 0.0, q, 0.01, 1000);
    }
}

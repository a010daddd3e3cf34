#[path = "scenes/mod.rs"]
#[allow(dead_code)]
mod scenes;
use dirac::prelude::*;
use scenes::double_pendulum;
fn main() {
    let mut s = double_pendulum::stepper(Quadrature::midpoint(), 0.01).unwrap();
    let mut acc = 0.0;
    for _ in 0..10 {
        let t = s.run(100_000).unwrap();
        acc += t.q()[1000][0];
    }
    println!("{acc}");
}

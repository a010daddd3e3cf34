#[path = "scenes/mod.rs"]
mod scenes;
use dirac::prelude::*;
use scenes::hand_written::{HandStepper, KnifeEdgeMidpoint};
use scenes::knife_edge;

fn main() {
    let which = std::env::args().nth(1).unwrap();
    let steps = 20000;
    if which == "gen" {
        let mut s = knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).expect("valid");
        for _ in 0..steps {
            std::hint::black_box(s.step()).unwrap();
        }
    } else {
        let v0 = SVector::from([0.0, 0.0, knife_edge::OMEGA]);
        let mut s = HandStepper::new(
            KnifeEdgeMidpoint(knife_edge::SCENE),
            0.01,
            SVector::zeros(),
            v0,
        );
        for _ in 0..steps {
            std::hint::black_box(s.step()).unwrap();
        }
    }
}

use dirac::prelude::*;

#[dirac_system(coordinates(q), lagrangian = 0.5 * dot(q).powi(2))]
struct Inductor;

#[dirac_system(coordinates(q), lagrangian = -0.5 * q.powi(2))]
struct Capacitor;

#[dirac_system(subsystems(l, c), junctions(series = l.dq - cap.dq))]
struct Loop {
    l: Inductor,
    c: Capacitor,
}

fn main() {}

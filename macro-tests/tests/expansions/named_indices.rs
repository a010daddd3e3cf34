//! Indices and lengths named by constants, in a plain and in a generic struct: within range they
//! compile (rustc checks them) and select the right coordinates.
use dirac::prelude::*;

const N: usize = 3;
const LAST: usize = N - 1;

#[dirac_system(
    coordinates(theta[N]),
    lagrangian = 0.5 * dot(theta[LAST]).powi(2) - theta[LAST - 1],
    constraints(dtheta[0] - dtheta[LAST]),
)]
struct Named;

#[dirac_system(
    coordinates(x[L]),
    lagrangian = 0.5 * dot(x[0]).powi(2) - 0.5 * x[L - 1].powi(2),
)]
struct Generic<const L: usize>;

#[test]
fn select_the_named_coordinates() {
    let (q, v) = (vector![1.0, 2.0, 3.0], vector![4.0, 5.0, 6.0]);
    let l: f64 = Named.lagrangian(&q, &v);
    assert_eq!(l, 0.5 * 36.0 - 2.0);
    let a: SVector<f64, 3> = Named.one_form(&q, 0);
    assert_eq!(a, vector![1.0, 0.0, -1.0]);
    let l: f64 = Generic::<3>.lagrangian(&q, &v);
    assert_eq!(l, 0.5 * 16.0 - 4.5);
}

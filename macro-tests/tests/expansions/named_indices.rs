//! Indices and lengths named by constants: in a plain struct, through `Self`, in a struct
//! generic in another constant, and in a struct declared inside a function. Within range they
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

/// The index names the struct's own constant (`Self`) and, in parentheses, a const parameter
/// that is not the length.
#[dirac_system(
    coordinates(x[3]),
    lagrangian = 0.5 * dot(x[Self::FIRST]).powi(2) - w[0] * x[(K - 1) / 2 + 1],
)]
struct Weighted<const K: usize> {
    w: [f64; K],
}

impl<const K: usize> Weighted<K> {
    const FIRST: usize = 0;
}

#[test]
fn select_the_named_coordinates() {
    let (q, v) = (vector![1.0, 2.0, 3.0], vector![4.0, 5.0, 6.0]);
    let l: f64 = Named.lagrangian(&q, &v);
    assert_eq!(l, 0.5 * 36.0 - 2.0);
    let a: SVector<f64, 3> = Named.one_form(&q, 0);
    assert_eq!(a, vector![1.0, 0.0, -1.0]);
    let l: f64 = Generic::<3>.lagrangian(&q, &v);
    assert_eq!(l, 0.5 * 16.0 - 4.5);
    // (K − 1)/2 + 1 = 2 for K = 3.
    let l: f64 = Weighted::<3> { w: [2.0; 3] }.lagrangian(&q, &v);
    assert_eq!(l, 0.5 * 16.0 - 2.0 * 3.0);
}

#[test]
fn a_struct_inside_a_function_reads_the_function_s_constants() {
    const M: usize = 2;
    #[dirac_system(coordinates(y[M]), lagrangian = 0.5 * dot(y[M - 1]).powi(2) - y[0])]
    struct Local;
    let l: f64 = Local.lagrangian(&vector![1.0, 2.0], &vector![3.0, 4.0]);
    assert_eq!(l, 0.5 * 16.0 - 1.0);
}

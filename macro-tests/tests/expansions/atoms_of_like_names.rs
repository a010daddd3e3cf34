//! Rotations and unit vectors whose names differ only by an index (`a_1` and `a[1]`, `n_0` and
//! `n[0]`) are different coordinates in the Lagrangian.
use dirac::prelude::*;

#[dirac_system(
    coordinates(a_1: SO3, a[2]: SO3, n_0: S2, n[1]: S2),
    lagrangian = 0.5 * dot(omega(a_1), omega(a_1)) + 2.0 * dot(omega(a[1]), omega(a[1]))
        + 3.0 * n_0[2] + 5.0 * n[0][2] + 7.0 * a_1[1][2] + 11.0 * a[1][1][2],
)]
struct Like;

#[test]
fn compiles_and_runs() {
    let turned = Retraction::Exp.map(&Vector3::new(0.3, 0.0, 0.0));
    let q = Configuration::<f64, 0, 3, 2>::new(
        SVector::zeros(),
        [turned, Matrix3::identity(), Matrix3::identity()],
        [Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 0.0, -1.0)],
    );
    let v = Rates::<f64, 0, 3, 2>::new(
        SVector::zeros(),
        [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::zeros(),
            Vector3::new(0.0, 3.0, 0.0),
        ],
        [Vector3::zeros(), Vector3::zeros()],
    );
    let expected = 0.5 * 1.0 + 2.0 * 9.0 + 3.0 * 1.0 - 5.0 * 1.0 + 7.0 * turned[(1, 2)];
    assert!((Like.lagrangian(&q, &v) - expected).abs() < 1e-14);
}

//! Fields on a rectangle of the plane (`PlaneField`): the membrane's discrete dispersion relation
//! held exactly with fixed, free and periodic edges, the order in space and time against the
//! drum's modes, the compositions' orders in time, the force as the gradient of the discrete
//! potential for a nonlinear anisotropic medium, the multisymplectic law node by node, a
//! hand-written five-point leapfrog followed to round-off, bounded energy, parallel steps,
//! refusals.

use std::f64::consts::{PI, TAU};

use crate::support::{assert_order, energy_error_first_and_last_tenth};
use dirac::nalgebra::SVector;
use dirac::{Boundary, Composition, DiracError, PlaneDensity, PlaneField, Scalar};
use scenes::membrane::{self, CoupledMembranes, DRUM, Membrane};

/// One-component values at the nodes of `field` of `f(x, y)`.
fn at<D: PlaneDensity<1>>(
    field: &PlaneField<D, 1>,
    f: impl Fn(f64, f64) -> f64,
) -> Vec<SVector<f64, 1>> {
    let points = field.points().into_iter();
    points.map(|[x, y]| SVector::from([f(x, y)])).collect()
}

/// The largest `|u − exact(x, y)|` over the nodes.
fn error<D: PlaneDensity<1>>(field: &PlaneField<D, 1>, exact: impl Fn(f64, f64) -> f64) -> f64 {
    let u = field.u().unwrap().iter();
    let gap = u
        .zip(field.points())
        .map(|(u, [x, y])| (u[0] - exact(x, y)).abs());
    gap.fold(0.0, f64::max)
}

/// The leapfrog's modes of the five-point membrane are exact solutions of the step, whatever
/// holds the edges: standing waves `sin·sin` on a drum fixed all round, `cos·sin` with two free
/// edges (whose half cells keep `cos` an eigenvector) and `cos·cos` free all round (the corners'
/// quarter cells too), a wave `cos(k_x x − ωt)` travelling round a periodic axis over a `cos` of
/// free edges. Each is followed to round-off over 2 000 steps at `sin(ωΔt/2) = (Δt/2) ω_h`,
/// where the continuum's `ω = |k|` is off by order one.
#[test]
fn the_membrane_keeps_its_discrete_dispersion_relation() {
    let (sides, cells, dt) = ([(0.0, 2.0), (0.0, 1.5)], [20, 12], 0.05);
    let (fixed, free, periodic) = (Boundary::Fixed, Boundary::Free, Boundary::Periodic);
    type Shape = fn(f64, f64, [f64; 2]) -> f64;
    let sin_sin: Shape = |x, y, k| (k[0] * x).sin() * (k[1] * y).sin();
    let cos_sin: Shape = |x, y, k| (k[0] * x).cos() * (k[1] * y).sin();
    let cos_cos: Shape = |x, y, k| (k[0] * x).cos() * (k[1] * y).cos();
    let cases: [([Boundary; 2], [f64; 2], Shape); 4] = [
        ([fixed, fixed], [PI, 2.0 * PI / 1.5], sin_sin),
        ([free, fixed], [1.5 * PI, 2.0 * PI / 1.5], cos_sin),
        ([free, free], [PI, PI / 1.5], cos_cos),
        ([periodic, free], [TAU, PI / 1.5], |x, y, k| {
            (k[0] * x).cos() * (k[1] * y).cos()
        }),
    ];
    for (boundary, k, shape) in cases {
        let mut drum = PlaneField::new(DRUM, sides, cells, boundary, dt).unwrap();
        let omega = membrane::discrete_frequency(k, drum.spacing(), dt);
        let travelling = boundary[0] == periodic;
        // Störmer–Verlet's momentum at t_n is (u^{n+1} − u^{n−1})/(2Δt).
        let rate = |x: f64, y: f64| match travelling {
            true => (k[0] * x).sin() * (k[1] * y).cos() * (omega * dt).sin() / dt,
            false => 0.0,
        };
        drum.start(&at(&drum, |x, y| shape(x, y, k)), &at(&drum, rate))
            .unwrap();
        drum.run(2_000).unwrap();
        let t = drum.t();
        let exact = |omega: f64| {
            move |x: f64, y: f64| match travelling {
                true => (k[0] * x - omega * t).cos() * (k[1] * y).cos(),
                false => shape(x, y, k) * (omega * t).cos(),
            }
        };
        let discrete = error(&drum, exact(omega));
        let continuum = error(&drum, exact(membrane::frequency(k)));
        println!("{boundary:?}: discrete relation {discrete:.2e}, continuum's {continuum:.2e}");
        assert!(discrete < 1e-11, "{boundary:?}: off by {discrete:e}");
        assert!(
            continuum > 0.1,
            "{boundary:?}: continuum as close, {continuum:e}"
        );
    }
}

/// In space and time together (Δt = Δx/2), the drum fixed all round converges at order 2 to its
/// mode `sin(πx) sin(2πy) cos(√5 π t)` of the continuum.
#[test]
fn the_drum_converges_at_order_two() {
    let t = 1.0;
    let omega = 5f64.sqrt() * PI;
    let exact = |x: f64, y: f64| (PI * x).sin() * (2.0 * PI * y).sin() * (omega * t).cos();
    let sizes = [12, 24, 48];
    let errors: Vec<f64> = sizes
        .iter()
        .map(|&n| {
            let dx = 1.0 / n as f64;
            let fixed = [Boundary::Fixed; 2];
            let square = [(0.0, 1.0); 2];
            let mut drum = PlaneField::new(DRUM, square, [n, n], fixed, 0.5 * dx).unwrap();
            let u0 = at(&drum, |x, y| exact(x, y) / (omega * t).cos());
            drum.start(&u0, &at(&drum, |_, _| 0.0)).unwrap();
            drum.run(2 * n as u64).unwrap();
            error(&drum, exact)
        })
        .collect();
    let hs: Vec<f64> = sizes.iter().map(|&n| 1.0 / n as f64).collect();
    assert_order("drum against the continuum", &hs, &errors, 2.0);
}

/// In time, each composition has its order against the travelling wave of the semi-discrete
/// membrane, `cos(2x + y − ω_h t)`, which the grid carries exactly.
#[test]
fn each_composition_has_its_order_in_time() {
    let (k, t) = ([2.0, 1.0], 1.0);
    let sides = [(0.0, TAU), (0.0, TAU)];
    let cells = [12, 8];
    let spacing = [TAU / 12.0, TAU / 8.0];
    let omega = membrane::semi_discrete_frequency(k, spacing);
    let cases = [
        (Composition::verlet(), [20, 40, 80]),
        (Composition::suzuki(), [8, 16, 32]),
        (Composition::kahan_li_8(), [5, 7, 10]),
    ];
    for (composition, steps) in cases {
        let order = composition.order() as f64;
        let name = composition.name();
        let errors: Vec<f64> = steps
            .iter()
            .map(|&n| {
                let dt = t / n as f64;
                let periodic = [Boundary::Periodic; 2];
                let mut wave = PlaneField::new(DRUM, sides, cells, periodic, dt)
                    .unwrap()
                    .with_composition(composition.clone());
                let u0 = at(&wave, |x, y| (k[0] * x + k[1] * y).cos());
                let ut0 = at(&wave, |x, y| omega * (k[0] * x + k[1] * y).sin());
                wave.start(&u0, &ut0).unwrap();
                wave.run(n).unwrap();
                error(&wave, |x, y| (k[0] * x + k[1] * y - omega * t).cos())
            })
            .collect();
        let hs: Vec<f64> = steps.iter().map(|&n| t / n as f64).collect();
        assert_order(name, &hs, &errors, order);
    }
}

/// A nonlinear, anisotropic medium of two components whose inertia and stiffness vary over the
/// plane, with slopes coupled across directions and components:
/// `U = ½ (1 + x) u_x² + ½ (2 + sin y) u_y² + 0.3 u_x u_y + ½ (w_x² + w_y²) + 0.2 u_x w_y
///   + 0.05 w_x⁴ + (1 − cos u) + 0.1 u² w²`.
#[derive(Clone)]
struct Medium;
impl PlaneDensity<2> for Medium {
    fn inertia(&self, [x, y]: [f64; 2]) -> SVector<f64, 2> {
        SVector::from([1.0 + x * x, 2.0 + y])
    }
    fn potential<S: Scalar>(
        &self,
        [x, y]: [f64; 2],
        u: &SVector<S, 2>,
        ux: &SVector<S, 2>,
        uy: &SVector<S, 2>,
    ) -> S {
        let stiff = ux[0] * ux[0] * (0.5 * (1.0 + x)) + uy[0] * uy[0] * (0.5 * (2.0 + y.sin()));
        let cross = ux[0] * uy[0] * 0.3 + ux[0] * uy[1] * 0.2;
        let second = (ux[1] * ux[1] + uy[1] * uy[1]) * 0.5 + ux[1].powi(4) * 0.05;
        let site = -u[0].cos() + 1.0 + u[0] * u[0] * u[1] * u[1] * 0.1;
        stiff + cross + second + site
    }
}

/// The medium's field and rates at `(x, y)`: smooth, not small, nothing special at the edges.
fn medium_start(x: f64, y: f64) -> (SVector<f64, 2>, SVector<f64, 2>) {
    let u = SVector::from([(1.3 * x + 0.4).sin() + 0.5 * y, (0.7 * y - x).cos()]);
    (u, SVector::from([0.2 * (x - y), 0.1 * x * y]))
}

/// The medium started from [`medium_start`], on `[0, 1.2] × [0.5, 1.3]` in 6 × 4 cells.
fn medium(boundary: [Boundary; 2], dt: f64) -> PlaneField<Medium, 2> {
    medium_on_cells(boundary, [6, 4], 1, dt)
}

/// The medium started from [`medium_start`], on `[0, 1.2] × [0.5, 1.3]` in `cells` of `degree`.
fn medium_on_cells(
    boundary: [Boundary; 2],
    cells: [usize; 2],
    degree: usize,
    dt: f64,
) -> PlaneField<Medium, 2> {
    let sides = [(0.0, 1.2), (0.5, 1.3)];
    let mut field = PlaneField::new(Medium, sides, cells, boundary, dt)
        .unwrap()
        .with_degree(degree)
        .unwrap();
    let (u, mut ut): (Vec<_>, Vec<_>) = field
        .points()
        .into_iter()
        .map(|[x, y]| medium_start(x, y))
        .unzip();
    // Nodes on a fixed edge do not move.
    for (rate, moves) in ut.iter_mut().zip(moving(&field)) {
        if !moves {
            *rate = SVector::zeros();
        }
    }
    field.start(&u, &ut).unwrap();
    field
}

/// Which nodes move: those not on a fixed edge.
fn moving<D: PlaneDensity<C>, const C: usize>(field: &PlaneField<D, C>) -> Vec<bool> {
    let ([nx, ny], [bx, by]) = (field.nodes(), field.boundary());
    let on_fixed = |i: usize, n: usize, b: Boundary| b == Boundary::Fixed && (i == 0 || i == n - 1);
    (0..nx * ny)
        .map(|k| !(on_fixed(k % nx, nx, bx) || on_fixed(k / nx, ny, by)))
        .collect()
}

/// The force the step kicks with is `−∂Φ/∂u` of the potential that `energy` sums corner by
/// corner (central differences of the energy, node by node and component by component), and it
/// is zero on a fixed edge: for the nonlinear anisotropic medium, with free, periodic and fixed
/// edges. A corner read at the wrong node, a slope of the wrong sign or a send to the wrong
/// neighbour is off by order one.
#[test]
fn the_force_is_the_gradient_of_the_discrete_potential() {
    let (free, fixed, periodic) = (Boundary::Free, Boundary::Fixed, Boundary::Periodic);
    for boundary in [[free, periodic], [fixed, free], [periodic, fixed]] {
        assert_force_is_minus_gradient(&medium(boundary, 0.01), &format!("{boundary:?}"));
    }
}

/// `field`'s force against central differences of its energy, node by node and component by
/// component: within 1e-7 of forces of order one where the node moves, exactly zero where it
/// does not.
fn assert_force_is_minus_gradient(field: &PlaneField<Medium, 2>, what: &str) {
    let (u, ut) = (field.u().unwrap().to_vec(), field.velocities().unwrap());
    let force = field.force().unwrap().to_vec();
    let h = 1e-6;
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    for (k, moves) in moving(field).iter().enumerate() {
        for c in 0..2 {
            let energy_at = |shift: f64| {
                let mut probe = field.clone();
                let mut v = u.clone();
                v[k][c] += shift;
                probe.start(&v, &ut).unwrap();
                probe.energy().unwrap()
            };
            let gradient = (energy_at(h) - energy_at(-h)) / (2.0 * h);
            match moves {
                true => worst = worst.max((force[k][c] + gradient).abs()),
                false => assert_eq!(force[k][c], 0.0, "{what}: node {k} on a fixed edge"),
            }
            scale = scale.max(gradient.abs());
        }
    }
    println!("{what}: force against −∂Φ/∂u, {worst:.1e} of {scale:.1e}");
    assert!(
        scale > 0.1 && worst < 1e-7 * scale,
        "{what}: {worst:e} of {scale:e}"
    );
}

/// The discrete multisymplectic conservation law, node by node and step by step. For a linear
/// density any two solutions `U`, `W` are first variations of each other, and the five-point
/// leapfrog keeps
/// `(κ^{n+½} − κ^{n−½})/Δt = (φ_{i+½,j} − φ_{i−½,j})/Δx + (ψ_{i,j+½} − ψ_{i,j−½})/Δy` at every
/// node, with `κ^{n+½} = (U^{n+1}·W^n − W^{n+1}·U^n)/Δt`,
/// `φ_{i+½,j} = (U_{i+1,j}·W_{i,j} − W_{i+1,j}·U_{i,j})/Δx` and `ψ` alike along `y` (the springs'
/// terms cancel between the two components). Two coupled membranes on a periodic grid of
/// unequal spacings from unrelated rough data, 200 steps.
#[test]
fn the_multisymplectic_law_holds_node_by_node() {
    let (cells, dt) = ([10, 8], 0.05);
    let sides = [(0.0, TAU), (0.0, 3.0)];
    let spacing = [TAU / 10.0, 3.0 / 8.0];
    // A fixed sequence of pseudo-random numbers in [−1, 1).
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let mut histories = Vec::new();
    for _ in 0..2 {
        let periodic = [Boundary::Periodic; 2];
        let mut pair =
            PlaneField::new(CoupledMembranes { k: 2.0 }, sides, cells, periodic, dt).unwrap();
        let n = pair.points().len();
        let mut values = || -> Vec<SVector<f64, 2>> {
            (0..n)
                .map(|_| SVector::from([random(), random()]))
                .collect()
        };
        let (u0, ut0) = (values(), values());
        pair.start(&u0, &ut0).unwrap();
        let mut history = vec![pair.u().unwrap().to_vec()];
        for _ in 0..200 {
            pair.step().unwrap();
            history.push(pair.u().unwrap().to_vec());
        }
        histories.push(history);
    }
    let (u, w) = (&histories[0], &histories[1]);
    let [nx, ny] = cells;
    let node = |i: usize, j: usize| (j % ny) * nx + i % nx;
    let kappa = |m: usize, k: usize| (u[m + 1][k].dot(&w[m][k]) - w[m + 1][k].dot(&u[m][k])) / dt;
    let flux = |m: usize, from: usize, to: usize, h: f64| {
        (u[m][to].dot(&w[m][from]) - w[m][to].dot(&u[m][from])) / h
    };
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    for m in 1..u.len() - 1 {
        for j in 0..ny {
            for i in 0..nx {
                let k = node(i, j);
                let (left, right) = (node(i + nx - 1, j), node(i + 1, j));
                let (below, above) = (node(i, j + ny - 1), node(i, j + 1));
                let [dx, dy] = spacing;
                let time = (kappa(m, k) - kappa(m - 1, k)) / dt;
                let along_x = (flux(m, k, right, dx) - flux(m, left, k, dx)) / dx;
                let along_y = (flux(m, k, above, dy) - flux(m, below, k, dy)) / dy;
                worst = worst.max((time - along_x - along_y).abs());
                scale = scale.max(time.abs() + along_x.abs() + along_y.abs());
            }
        }
    }
    println!("multisymplectic law: largest defect {worst:.2e} against terms of {scale:.2e}");
    assert!(
        scale > 1.0 && worst < 1e-13 * scale,
        "{worst:e} of {scale:e}"
    );
}

/// A periodic membrane of 130 × 70 nodes follows a hand-written five-point leapfrog
/// (`scenes::membrane::leapfrog_membrane`) to round-off over 100 steps, the wrap-around on both
/// axes included.
#[test]
fn a_membrane_equals_a_hand_written_five_point_leapfrog() {
    let (cells, dt) = ([130, 70], 0.02);
    let sides = [(0.0, 6.5), (0.0, 4.2)];
    let spacing = [0.05, 0.06];
    let periodic = [Boundary::Periodic; 2];
    let mut drum = PlaneField::new(DRUM, sides, cells, periodic, dt).unwrap();
    let shape = |x: f64, y: f64| {
        (TAU * x / 6.5).sin() * (TAU * 2.0 * y / 4.2).cos() + (x * y).sin().powi(3) * 0.1
    };
    let u0 = at(&drum, shape);
    drum.start(&u0, &at(&drum, |x, _| (TAU * x / 6.5).cos()))
        .unwrap();
    let mut u: Vec<f64> = u0.iter().map(|u| u[0]).collect();
    let mut p: Vec<f64> = drum.velocities().unwrap().iter().map(|v| v[0]).collect();
    let mut force = vec![0.0; u.len()];
    membrane::laplacian(&u, &mut force, cells[0], spacing);
    drum.run(100).unwrap();
    for _ in 0..100 {
        membrane::leapfrog_membrane([&mut u, &mut p, &mut force], cells[0], spacing, dt);
    }
    let worst = (drum.u().unwrap().iter().zip(&u))
        .map(|(a, b)| (a[0] - b).abs())
        .fold(0.0, f64::max);
    let scale = u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    println!("against the hand-written leapfrog: {worst:.1e} of {scale:.1e}");
    assert!(scale > 0.5 && worst < 1e-12 * scale, "{worst:e}");
}

/// The nonlinear medium with free and periodic edges over 4 000 steps: the energy error
/// oscillates within the same band at the end as in the first tenth, a band well above
/// round-off (the step keeps a modified energy, not the energy itself).
#[test]
fn the_energy_error_stays_bounded() {
    let mut field = medium([Boundary::Free, Boundary::Periodic], 0.02);
    let mut energy = vec![field.energy().unwrap()];
    for _ in 0..400 {
        field.run(10).unwrap();
        energy.push(field.energy().unwrap());
    }
    let (first, last) = energy_error_first_and_last_tenth(&energy);
    println!("energy error: first tenth {first:.2e}, last tenth {last:.2e}");
    assert!(first > 1e-9, "the band is round-off: {first:e}");
    assert!(last < 1.5 * first, "drift: {first:e} then {last:e}");
}

/// Split across threads, the steps are the same bit for bit: 201 × 181 nodes with free and fixed
/// edges, and 200 × 200 periodic nodes (the first band reading the last row below it, the last
/// the first row above it); two bands of rows each. Cells of degree 3 alike: 193 × 193 nodes with
/// free and fixed edges (three bands, the last holding the top row of nodes alone) and 192 × 192
/// periodic nodes (the first band gathering the last row of cells, above it across the edge). A
/// run may be split across threads midway.
#[test]
fn parallel_and_sequential_membranes_step_alike() {
    let (free_fixed, periodic) = ([Boundary::Free, Boundary::Fixed], [Boundary::Periodic; 2]);
    let cases = [
        (free_fixed, [200, 180], 1, 0.003),
        (periodic, [200, 200], 1, 0.003),
        (free_fixed, [64, 64], 3, 0.0005),
        (periodic, [64, 64], 3, 0.0005),
    ];
    for (edges, cells, degree, dt) in cases {
        // On one thread, on several, and on one then several from the third step on.
        let runs = [(false, false), (true, true), (false, true)].map(|(first, then)| {
            let sides = [(0.0, 1.6), (0.0, 1.2)];
            let mut drum = PlaneField::new(DRUM, sides, cells, edges, dt)
                .unwrap()
                .with_degree(degree)
                .unwrap()
                .with_parallel(first);
            let u0 = at(&drum, |x, y| {
                (TAU * x / 1.6).cos() * (PI * y / 1.2).sin() + (x * y * (1.2 - y)).sin()
            });
            drum.start(&u0, &at(&drum, |_, _| 0.0)).unwrap();
            drum.run(2).unwrap();
            let mut drum = drum.with_parallel(then);
            drum.run(3).unwrap();
            drum
        });
        for run in &runs[1..] {
            assert_eq!(
                runs[0].u().unwrap(),
                run.u().unwrap(),
                "{edges:?}, {degree}"
            );
            assert_eq!(runs[0].momenta().unwrap(), run.momenta().unwrap());
            assert_eq!(runs[0].force().unwrap(), run.force().unwrap());
            assert_eq!(runs[0].t(), run.t());
        }
    }
}

/// Each node weighs `w_x w_y ρ(x, y)`: the whole cell inside, half of it on a free edge, a
/// quarter at a free corner, nothing on a fixed edge. The momenta of the medium's start (whose
/// inertia varies over the plane) are those weights times the rates, component by component.
#[test]
fn each_node_weighs_its_share_of_the_cells() {
    let (free, fixed) = (Boundary::Free, Boundary::Fixed);
    let field = medium([free, fixed], 0.01);
    let ([nx, ny], [dx, dy]) = (field.nodes(), field.spacing());
    let momenta = field.momenta().unwrap();
    let mut worst = 0.0_f64;
    for (k, (p, [x, y])) in momenta.iter().zip(field.points()).enumerate() {
        let (i, j) = (k % nx, k / nx);
        let wx = if i == 0 || i == nx - 1 { 0.5 * dx } else { dx };
        let wy = if j == 0 || j == ny - 1 { 0.0 } else { dy };
        let expected = medium_start(x, y).1.component_mul(&Medium.inertia([x, y])) * (wx * wy);
        worst = worst.max((p - expected).amax());
    }
    assert!(worst < 1e-15, "{worst:e}");
    // A free corner: a quarter cell.
    let corners = medium([free, free], 0.01);
    let p = corners.momenta().unwrap()[0];
    let rate = medium_start(0.0, 0.5)
        .1
        .component_mul(&Medium.inertia([0.0, 0.5]));
    assert!((p - rate * (0.25 * dx * dy)).amax() < 1e-15, "{p:?}");
}

/// `U = ½ (u_x² + u_y²) + 2√u`: finite for `u ≥ 0`, not below.
struct Root;
impl PlaneDensity<1> for Root {
    fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 1> {
        SVector::from([1.0])
    }
    fn potential<S: Scalar>(
        &self,
        _at: [f64; 2],
        u: &SVector<S, 1>,
        ux: &SVector<S, 1>,
        uy: &SVector<S, 1>,
    ) -> S {
        (ux[0] * ux[0] + uy[0] * uy[0]) * 0.5 + u[0].sqrt() * 2.0
    }
}

/// What a plane field refuses, and a failed step that changes nothing.
#[test]
fn what_a_plane_field_refuses() {
    let (fixed, periodic) = ([Boundary::Fixed; 2], [Boundary::Periodic; 2]);
    let unit = [(0.0, 1.0); 2];
    let new = |sides: [(f64, f64); 2], cells: [usize; 2], edges: [Boundary; 2], dt: f64| {
        PlaneField::new(DRUM, sides, cells, edges, dt).err()
    };
    assert!(matches!(
        new(unit, [4, 4], fixed, 0.0),
        Some(DiracError::InvalidStep { .. })
    ));
    assert!(matches!(
        new(unit, [4, 4], fixed, f64::NAN),
        Some(DiracError::InvalidStep { .. })
    ));
    assert!(matches!(
        new(unit, [4, 1], fixed, 0.1),
        Some(DiracError::Dimension(_))
    ));
    assert!(matches!(
        new(unit, [2, 4], periodic, 0.1),
        Some(DiracError::Dimension(_))
    ));
    let flat = [(0.0, 1.0), (1.0, 1.0)];
    assert!(matches!(
        new(flat, [4, 4], fixed, 0.1),
        Some(DiracError::InvalidRun(_))
    ));
    let endless = [(0.0, f64::INFINITY), (0.0, 1.0)];
    assert!(matches!(
        new(endless, [4, 4], fixed, 0.1),
        Some(DiracError::InvalidRun(_))
    ));
    let massless = Membrane {
        rho: 0.0,
        kappa: 1.0,
    };
    let refused = PlaneField::new(massless, unit, [4, 4], fixed, 0.1);
    assert!(matches!(refused, Err(DiracError::NonFinite { .. })));

    let mut drum = PlaneField::new(DRUM, unit, [4, 3], fixed, 0.01).unwrap();
    assert_eq!(drum.step(), Err(DiracError::NotStarted));
    assert_eq!(drum.u().err(), Some(DiracError::NotStarted));
    let n = drum.points().len();
    let (zeros, short) = (vec![SVector::zeros(); n], vec![SVector::zeros(); n - 1]);
    assert!(matches!(
        drum.start(&short, &zeros),
        Err(DiracError::Dimension(_))
    ));
    assert!(matches!(
        drum.start(&zeros, &short),
        Err(DiracError::Dimension(_))
    ));
    let mut bad = zeros.clone();
    bad[7][0] = f64::INFINITY;
    assert!(matches!(
        drum.start(&bad, &zeros),
        Err(DiracError::NonFinite { .. })
    ));
    // Node 2 is on the lower edge, which is fixed.
    let mut moving_edge = zeros.clone();
    moving_edge[2][0] = 1.0;
    assert!(matches!(
        drum.start(&zeros, &moving_edge),
        Err(DiracError::InconsistentInitialState(_))
    ));
    assert_eq!(drum.u().err(), Some(DiracError::NotStarted));
    // Cells of degree 0 or past the last, and more nodes than can be counted.
    for degree in [0, dirac::field::MOST_DEGREE + 1] {
        let refused = PlaneField::new(DRUM, unit, [4, 4], fixed, 0.1)
            .and_then(|field| field.with_degree(degree));
        assert!(
            matches!(refused, Err(DiracError::Unsupported(_))),
            "{degree}"
        );
    }
    let huge = PlaneField::new(DRUM, unit, [usize::MAX / 4, 4], periodic, 0.1);
    assert!(
        matches!(&huge, Err(DiracError::Dimension(why)) if why.contains("memory")),
        "{huge:?}"
    );
    let uncountable = PlaneField::new(DRUM, unit, [usize::MAX / 2, 3], periodic, 0.1);
    assert!(
        matches!(&uncountable, Err(DiracError::Dimension(why)) if why.contains("counted")),
        "{uncountable:?}"
    );

    // The field falls below zero, where `U = … + 2√u` is not defined: the step is refused and the
    // state is that of the step before.
    let free = [Boundary::Free; 2];
    let mut root = PlaneField::new(Root, unit, [3, 3], free, 0.3).unwrap();
    root.start(&at(&root, |_, _| 0.05), &at(&root, |_, _| -0.1))
        .unwrap();
    let state = |f: &PlaneField<Root, 1>| {
        let (u, p) = (f.u().unwrap().to_vec(), f.momenta().unwrap().to_vec());
        (u, p, f.t(), f.energy().unwrap())
    };
    let before = state(&root);
    let failed = root.step();
    assert!(
        matches!(failed, Err(DiracError::NonFinite { .. })),
        "{failed:?}"
    );
    assert_eq!(before, state(&root));
}

/// Cells of degree `r` (the tensor-product Gauss–Lobatto rule): the drum fixed all round against
/// its mode `sin(πx) sin(2πy) cos(√5 π t)`, the largest error at the nodes over `0 < t ≤ 0.5`
/// (Kahan–Li 8 in time at `Δt = Δx/(4r²)`, whose own error is far below), falls at order 2 for
/// the box cell and `r + 2` for degrees 2 to 4, as on a line (measured 2.00, 4.12, 4.95 on 4, 8
/// and 16 cells, 5.82 on 4, 6 and 8 cells of degree 4).
#[test]
fn cells_of_higher_degree_converge_at_order_r_plus_two() {
    let omega = 5f64.sqrt() * PI;
    let shape = |x: f64, y: f64| (PI * x).sin() * (2.0 * PI * y).sin();
    for degree in 1..=4usize {
        let sizes: [usize; 3] = if degree < 4 { [4, 8, 16] } else { [4, 6, 8] };
        let errors: Vec<f64> = sizes
            .iter()
            .map(|&n| {
                let r = degree as f64;
                let steps = (0.5 * 4.0 * r * r * n as f64).ceil() as u64;
                let dt = 0.5 / steps as f64;
                let fixed = [Boundary::Fixed; 2];
                let mut drum = PlaneField::new(DRUM, [(0.0, 1.0); 2], [n, n], fixed, dt)
                    .unwrap()
                    .with_degree(degree)
                    .unwrap()
                    .with_composition(Composition::kahan_li_8());
                assert_eq!(drum.nodes(), [n * degree + 1; 2]);
                drum.start(&at(&drum, shape), &at(&drum, |_, _| 0.0))
                    .unwrap();
                (1..=steps)
                    .map(|step| {
                        drum.step().unwrap();
                        let t = step as f64 * dt;
                        error(&drum, |x, y| shape(x, y) * (omega * t).cos())
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let hs: Vec<f64> = sizes.iter().map(|&n| 1.0 / n as f64).collect();
        let expected = if degree == 1 {
            2.0
        } else {
            degree as f64 + 2.0
        };
        assert_order(&format!("degree {degree}"), &hs, &errors, expected);
    }
}

/// The sine-Gordon field on the plane, `U = ½ (u_x² + u_y²) + 1 − cos u`.
struct PlaneSineGordon;
impl PlaneDensity<1> for PlaneSineGordon {
    fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 1> {
        SVector::from([1.0])
    }
    fn potential<S: Scalar>(
        &self,
        _at: [f64; 2],
        u: &SVector<S, 1>,
        ux: &SVector<S, 1>,
        uy: &SVector<S, 1>,
    ) -> S {
        (ux[0] * ux[0] + uy[0] * uy[0]) * 0.5 - u[0].cos() + 1.0
    }
}

/// A field that varies along one axis only steps on cells of degree `r` as the line's cells of
/// that degree step it (whose own test follows a hand-written spectral-element leapfrog): the
/// sine-Gordon pulse along `x` (free ends) over a periodic `y`, along `y` (fixed ends) over free
/// edges in `x`, and along `x` again with periodic ends (the last cell's last points are the
/// first nodes) over free edges in `y`, 150 steps of cells of degrees 2 and 3. The masses (`w_x w_y`, shared where
/// cells meet), the slopes through `D` and the cells' shares are all in the comparison.
#[test]
fn cells_of_higher_degree_step_a_field_of_one_axis_as_the_line_does() {
    use dirac::Field;
    let (length, cells, dt) = (8.0, 10, 0.01);
    let pulse = |s: f64| 2.0 / (s - 3.0).cosh() + 0.3 * (0.7 * s).sin();
    let rate = |s: f64| 0.5 * (0.4 * s).cos();
    for degree in [2usize, 3] {
        let cases = [
            (0usize, Boundary::Free, Boundary::Periodic),
            (1, Boundary::Fixed, Boundary::Free),
            (0, Boundary::Periodic, Boundary::Free),
        ];
        for (along, ends, across) in cases {
            let mut line = Field::new(scenes::field::SineGordon, (0.0, length), cells, ends, dt)
                .unwrap()
                .with_degree(degree)
                .unwrap();
            let x = line.positions();
            let (u0, ut0): (Vec<_>, Vec<_>) = x
                .iter()
                .map(|&s| match ends {
                    // Fixed ends at rest.
                    Boundary::Fixed if s == 0.0 || s == length => (0.0, 0.0),
                    _ => (pulse(s), rate(s)),
                })
                .map(|(u, ut)| (SVector::from([u]), SVector::from([ut])))
                .unzip();
            line.start(&u0, &ut0).unwrap();
            line.run(150).unwrap();
            let (mut sides, mut edges, mut counts) = ([(0.0, 1.5); 2], [across; 2], [3usize; 2]);
            (sides[along], edges[along], counts[along]) = ((0.0, length), ends, cells);
            let mut plane = PlaneField::new(PlaneSineGordon, sides, counts, edges, dt)
                .unwrap()
                .with_degree(degree)
                .unwrap();
            let axes = plane.axes();
            assert_eq!(axes[along], x, "degree {degree}: the line's points");
            let index = |p: [f64; 2]| x.iter().position(|&s| s == p[along]).unwrap();
            let points = plane.points();
            let u: Vec<_> = points.iter().map(|&p| u0[index(p)]).collect();
            let ut: Vec<_> = points.iter().map(|&p| ut0[index(p)]).collect();
            plane.start(&u, &ut).unwrap();
            plane.run(150).unwrap();
            let (line_u, plane_u) = (line.u().unwrap(), plane.u().unwrap());
            let worst = points
                .iter()
                .zip(plane_u)
                .map(|(&p, u)| (u - line_u[index(p)]).amax())
                .fold(0.0, f64::max);
            println!("degree {degree}, {ends:?} along axis {along}: {worst:.1e} from the line");
            assert!(
                worst < 1e-12,
                "degree {degree}, {ends:?}, axis {along}: {worst:e}"
            );
            assert!(
                line_u.iter().any(|u| u[0].abs() > 0.5),
                "a pulse that moved"
            );
        }
    }
}

/// On cells of degree 2 and 3 the force is `−∂Φ/∂u` of the potential `energy` sums over the
/// cells' points (central differences, node by node and component by component), zero on a
/// fixed edge: the nonlinear anisotropic medium, whose cross terms `u_x u_y` read both slopes,
/// with free, periodic and fixed edges.
#[test]
fn on_cells_of_higher_degree_the_force_is_the_gradient_of_the_potential() {
    let (free, fixed, periodic) = (Boundary::Free, Boundary::Fixed, Boundary::Periodic);
    for (degree, boundary) in [
        (2, [free, periodic]),
        (3, [fixed, free]),
        (2, [periodic, fixed]),
    ] {
        let field = medium_on_cells(boundary, [3, 3], degree, 0.001);
        assert_force_is_minus_gradient(&field, &format!("degree {degree}, {boundary:?}"));
    }
}

/// On cells of degree 3, periodic both ways, the membrane's potential does not change when the
/// field is shifted by a constant, so the total momentum `Σ p` is kept to round-off (7.54 kept
/// to 1.1e-14 over 2 000 steps from a rough start), and the energy error stays in a band without drift.
#[test]
fn on_cells_of_higher_degree_momentum_is_kept_and_energy_bounded() {
    let sides = [(0.0, TAU), (0.0, 3.0)];
    let periodic = [Boundary::Periodic; 2];
    let mut field = PlaneField::new(DRUM, sides, [5, 4], periodic, 0.01)
        .unwrap()
        .with_degree(3)
        .unwrap();
    let u0 = at(&field, |x, y| {
        (x + 0.3).sin() * (TAU * y / 3.0).cos() + 0.2 * (2.0 * x).cos()
    });
    let ut0 = at(&field, |x, y| 0.4 + 0.3 * (x - y).sin());
    field.start(&u0, &ut0).unwrap();
    let total = |field: &PlaneField<Membrane, 1>| -> f64 {
        field.momenta().unwrap().iter().map(|p| p[0]).sum()
    };
    let p0 = total(&field);
    let mut energy = vec![field.energy().unwrap()];
    let mut drift = 0.0_f64;
    for _ in 0..200 {
        field.run(10).unwrap();
        energy.push(field.energy().unwrap());
        drift = drift.max((total(&field) - p0).abs());
    }
    let (first, last) = energy_error_first_and_last_tenth(&energy);
    println!(
        "momentum {p0:.3} kept to {drift:.1e}; energy: first tenth {first:.2e}, last {last:.2e}"
    );
    assert!(p0.abs() > 1.0 && drift < 1e-13, "{drift:e} of {p0}");
    assert!(first > 1e-9, "the band is round-off: {first:e}");
    assert!(last < 1.5 * first, "drift: {first:e} then {last:e}");
}

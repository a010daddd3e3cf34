//! Recording a run allocates nothing per sample: the allocations of `run(n)` on the double
//! pendulum do not grow with `n` (counted by a global allocator that counts the allocations made
//! on the test's own thread: the test harness's thread may allocate while the test runs).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use dirac::prelude::*;
use scenes::double_pendulum;

/// The system allocator, counting the allocations of each thread.
struct Counting;

thread_local! {
    /// Allocations made on this thread (a `const` thread-local: reading it never allocates).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Bytes allocated less bytes freed on this thread.
    static HELD: Cell<isize> = const { Cell::new(0) };
}

fn count_one(bytes: isize) {
    ALLOCATIONS.with(|count| count.set(count.get() + 1));
    HELD.with(|held| held.set(held.get() + bytes));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one(layout.size() as isize);
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        HELD.with(|held| held.set(held.get() - layout.size() as isize));
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one(new_size as isize - layout.size() as isize);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// What `make` returns and the bytes it still holds on the heap (allocated on this thread and
/// not freed when `make` returns).
fn held<T>(make: impl FnOnce() -> T) -> (T, isize) {
    let before = HELD.with(Cell::get);
    let made = make();
    (made, HELD.with(Cell::get) - before)
}

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

#[test]
fn recording_allocates_nothing_per_sample() {
    let count = |n: u64| {
        let mut stepper = double_pendulum::stepper(Quadrature::midpoint(), 0.01).unwrap();
        stepper.step().unwrap();
        allocations(|| {
            let trajectory = stepper.run(n).unwrap();
            assert_eq!(trajectory.len() as u64, n + 1);
        })
    };
    let (short, long) = (count(10), count(10_000));
    println!("run(10): {short} allocations, run(10 000): {long}");
    assert_eq!(short, long, "allocations grow with the number of samples");
    // Samples at given times come from the dense output, which allocates nothing either.
    let saved = |n: usize| {
        let mut stepper = double_pendulum::stepper(Quadrature::midpoint(), 0.01).unwrap();
        stepper.step().unwrap();
        let times: Vec<f64> = (1..=n).map(|i| 0.01 + 0.005 * i as f64 + 0.0013).collect();
        let t_end = times[n - 1] + 0.01;
        let run = Run::until(t_end).saveat(times);
        allocations(|| {
            let solution = stepper.solve(run).unwrap();
            assert_eq!(solution.trajectory.len(), n);
        })
    };
    let (short, long) = (saved(10), saved(10_000));
    println!("saveat 10 times: {short} allocations, 10 000 times: {long}");
    assert_eq!(
        short, long,
        "allocations grow with the number of saved times"
    );
    // The bare steps allocate nothing at all.
    let mut stepper = double_pendulum::stepper(Quadrature::galerkin(2).unwrap(), 0.01).unwrap();
    stepper.step().unwrap();
    assert_eq!(
        allocations(|| {
            for _ in 0..1000 {
                stepper.step().unwrap();
            }
        }),
        0
    );
}

/// Steps of constrained models and Galerkin rules allocate nothing either: one-forms held at the
/// midpoint and at the Gauss nodes, SHAKE, a Galerkin step with internal points (solved by
/// Newton's method and by fixed-point iteration), and the LC
/// circuit's hidden constraint checked at each midpoint step's end. (A projection that moves
/// `q`, as under Galerkin rules, which hold the hidden constraint at their nodes only, and
/// hidden constraints not fixed along the motion still allocate.)
#[test]
fn constrained_and_galerkin_steps_allocate_nothing() {
    fn after_a_step<S: DiracSystem<N>, const N: usize>(
        name: &str,
        mut stepper: Stepper<S, N>,
    ) -> (String, usize) {
        stepper.step().unwrap();
        let count = allocations(|| {
            for _ in 0..100 {
                stepper.step().unwrap();
            }
        });
        // A run by fixed-point iteration iterated every step (none handed to Newton's method).
        assert_eq!(stepper.handed_over(), (0, None), "{name}");
        (name.to_string(), count)
    }
    let knife = |quadrature: Quadrature| {
        let mut stepper = Stepper::new(scenes::knife_edge::SCENE, quadrature, 0.01).unwrap();
        stepper
            .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, 1.0])
            .unwrap();
        stepper
    };
    let mut pendulum = Stepper::new(
        scenes::cartesian_pendulum::SCENE,
        Quadrature::midpoint(),
        0.01,
    )
    .unwrap();
    pendulum
        .start_from_velocity(scenes::cartesian_pendulum::q0(1.0), SVector::zeros())
        .unwrap();
    let mut kepler = Stepper::new(
        scenes::kepler::SCENE,
        Quadrature::galerkin(3).unwrap(),
        0.01,
    )
    .unwrap();
    kepler
        .start_from_momentum(scenes::kepler::q0(), scenes::kepler::p0())
        .unwrap();
    // The same Galerkin step solved by fixed-point iteration (its tables set up at the first
    // step).
    let mut iterated = Stepper::new(
        scenes::kepler::SCENE,
        Quadrature::galerkin(4).unwrap(),
        0.01,
    )
    .unwrap()
    .with_fixed_point()
    .unwrap();
    iterated
        .start_from_momentum(scenes::kepler::q0(), scenes::kepler::p0())
        .unwrap();
    // A model that is not separable, iterated on its rows with their acceleration.
    let rows = scenes::double_pendulum::stepper(Quadrature::galerkin(4).unwrap(), 0.01)
        .unwrap()
        .with_fixed_point()
        .unwrap();
    let mut lc = Stepper::new(scenes::circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    lc.start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .unwrap();
    let counts = [
        after_a_step("LC circuit, midpoint", lc),
        after_a_step("knife edge, midpoint", knife(Quadrature::midpoint())),
        after_a_step(
            "knife edge, galerkin(2)",
            knife(Quadrature::galerkin(2).unwrap()),
        ),
        after_a_step("Cartesian pendulum, SHAKE", pendulum),
        after_a_step("Kepler, galerkin(3)", kepler),
        after_a_step("Kepler, galerkin(4), fixed point", iterated),
        after_a_step("double pendulum, galerkin(4), fixed point", rows),
    ];
    for (name, count) in counts {
        assert_eq!(count, 0, "{name}: {count} allocations in 100 steps");
    }
}

/// The step of a field allocates nothing: its passes write into buffers the start made (a
/// sine-Gordon field of 1 000 cells with free ends, by Kahan–Li 8).
#[test]
fn field_steps_allocate_nothing() {
    use dirac::{Boundary, Field};
    let mut kink = Field::new(
        scenes::field::SineGordon,
        (-20.0, 20.0),
        1_000,
        Boundary::Free,
        0.01,
    )
    .unwrap()
    .with_composition(Composition::kahan_li_8());
    let x = kink.positions();
    let at = |pick: fn((f64, f64)) -> f64| -> Vec<SVector<f64, 1>> {
        let value = |x: f64| pick(scenes::field::kink(0.5, 0.0, x));
        x.iter().map(|&x| SVector::from([value(x)])).collect()
    };
    kink.start(&at(|k| k.0), &at(|k| k.1)).unwrap();
    kink.step().unwrap();
    let count = allocations(|| kink.run(100).unwrap());
    assert_eq!(count, 0, "{count} allocations in 100 steps of a field");
    assert!(kink.u().unwrap().iter().any(|u| u[0] > 3.0));
}

/// A step of a field on the plane allocates nothing either (a membrane of 60 × 40 cells with
/// free and fixed edges, by Suzuki's composition).
#[test]
fn plane_field_steps_allocate_nothing() {
    use dirac::{Boundary, PlaneField};
    let edges = [Boundary::Free, Boundary::Fixed];
    let sides = [(0.0, 1.5), (0.0, 1.0)];
    let mut drum = PlaneField::new(scenes::membrane::DRUM, sides, [60, 40], edges, 0.005)
        .unwrap()
        .with_composition(Composition::suzuki());
    let u0: Vec<SVector<f64, 1>> = (drum.points().into_iter())
        .map(|[x, y]| SVector::from([x.cos() * (std::f64::consts::PI * y).sin()]))
        .collect();
    drum.start(&u0, &vec![SVector::zeros(); u0.len()]).unwrap();
    drum.step().unwrap();
    let count = allocations(|| drum.run(20).unwrap());
    assert_eq!(count, 0, "{count} allocations in 20 steps of a plane field");
    assert_eq!(drum.steps(), 21);
    // Cells of degree 3: their scratch is on the stack.
    let mut cells = PlaneField::new(scenes::membrane::DRUM, sides, [6, 4], edges, 0.002)
        .unwrap()
        .with_degree(3)
        .unwrap();
    let u0: Vec<SVector<f64, 1>> = (cells.points().into_iter())
        .map(|[x, y]| SVector::from([x.cos() * (std::f64::consts::PI * y).sin()]))
        .collect();
    cells.start(&u0, &vec![SVector::zeros(); u0.len()]).unwrap();
    cells.step().unwrap();
    let count = allocations(|| cells.run(20).unwrap());
    assert_eq!(
        count, 0,
        "{count} allocations in 20 steps of cells of degree 3"
    );
}

/// A field's memory is linear in its nodes: a started field of four times the nodes holds the
/// same bytes a node, on the line (1-D sine-Gordon, 10⁴ and 4·10⁴ cells) and on the plane (the
/// membrane, 100² and 200² periodic nodes, which holds `7 C` numbers a node, the state and the
/// step being taken and the mass, and three rows of the force's shares per band of rows).
#[test]
fn a_fields_memory_is_linear_in_its_nodes() {
    use dirac::{Boundary, Field, PlaneField};
    let line = |cells: usize| {
        let zeros = vec![SVector::<f64, 1>::zeros(); cells];
        let u0: Vec<SVector<f64, 1>> = (0..cells)
            .map(|j| SVector::from([(j as f64).sin()]))
            .collect();
        let (field, bytes) = held(|| {
            let periodic = Boundary::Periodic;
            let mut field = Field::new(
                scenes::field::SineGordon,
                (0.0, cells as f64),
                cells,
                periodic,
                0.1,
            )
            .unwrap();
            field.start(&u0, &zeros).unwrap();
            field
        });
        assert_eq!(field.u().unwrap().len(), cells);
        bytes as f64 / cells as f64
    };
    let plane = |side: usize| {
        let nodes = side * side;
        let zeros = vec![SVector::<f64, 1>::zeros(); nodes];
        let u0: Vec<SVector<f64, 1>> = (0..nodes)
            .map(|k| SVector::from([(k as f64).sin()]))
            .collect();
        let (field, bytes) = held(|| {
            let (periodic, sides) = ([Boundary::Periodic; 2], [(0.0, side as f64); 2]);
            let mut drum =
                PlaneField::new(scenes::membrane::DRUM, sides, [side, side], periodic, 0.1)
                    .unwrap();
            drum.start(&u0, &zeros).unwrap();
            drum
        });
        assert_eq!(field.u().unwrap().len(), nodes);
        bytes as f64 / nodes as f64
    };
    let (small, large) = (line(10_000), line(40_000));
    println!("line: {small:.2} and {large:.2} bytes a node");
    assert!(
        (large / small - 1.0).abs() < 0.01,
        "{small} then {large} bytes a node"
    );
    let (small, large) = (plane(100), plane(200));
    println!("plane: {small:.2} and {large:.2} bytes a node");
    assert!(
        (large / small - 1.0).abs() < 0.05,
        "{small} then {large} bytes a node"
    );
    assert!(
        (56.0..60.0).contains(&small),
        "{small} bytes a node, not 7 f64 and the rows"
    );
}

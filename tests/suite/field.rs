//! Fields with a separable Lagrangian density (`Field`): the wave equation's discrete dispersion
//! relation held exactly, the orders in time against the semi-discrete plane wave, in space and
//! time against the sine-Gordon kink and breather, the standing waves of fixed and free
//! strings and a string with masses at its ends, two coupled components against their modes,
//! the multisymplectic law node by node, bounded energy, parallel steps, binary snapshots,
//! refusals.

use std::f64::consts::{PI, TAU};

use crate::support::{assert_order, energy_error_first_and_last_tenth, slope};
use dirac::nalgebra::SVector;
use dirac::{Boundary, Composition, DiracError, Field, Scalar, SeparableDensity};
use scenes::field::{self, CoupledStrings, SineGordon, Wave};

const WAVE: Wave = Wave {
    rho: 1.0,
    kappa: 1.0,
};

/// One-component values at the nodes `x` of `f`.
fn at(x: &[f64], f: impl Fn(f64) -> f64) -> Vec<SVector<f64, 1>> {
    x.iter().map(|&x| SVector::from([f(x)])).collect()
}

/// `string` started from `shape` at rest and run `steps` steps, with its largest distance from
/// the standing wave `shape(x) cos(ωt)`.
fn standing_wave<D: SeparableDensity<1>>(
    mut string: Field<D, 1>,
    shape: impl Fn(f64) -> f64,
    omega: f64,
    steps: u64,
) -> (Field<D, 1>, f64) {
    let x = string.positions();
    string
        .start(&at(&x, &shape), &vec![SVector::zeros(); x.len()])
        .unwrap();
    string.run(steps).unwrap();
    let t = string.t();
    let off = error(&string, |x| SVector::from([shape(x) * (omega * t).cos()]));
    (string, off)
}

/// The largest `|u_j − exact(x_j)|`.
fn error<const C: usize>(
    field: &Field<impl SeparableDensity<C>, C>,
    exact: impl Fn(f64) -> SVector<f64, C>,
) -> f64 {
    let u = field.u().unwrap();
    let x = field.positions();
    u.iter()
        .zip(&x)
        .map(|(u, &x)| (u - exact(x)).amax())
        .fold(0.0, f64::max)
}

/// The leapfrog's plane wave `cos(k x_j − ω t_n)`, `sin(ω Δt/2)/Δt = sin(k Δx/2)/Δx`, is an exact
/// solution of the step: started from its own momenta it is followed to round-off over 2 000
/// steps, where the continuum's frequency `ω = k` would be off by order one.
#[test]
fn the_wave_equation_keeps_its_discrete_dispersion_relation() {
    let (cells, k) = (64, 5.0);
    let dx = TAU / cells as f64;
    let dt = 0.8 * dx;
    let omega = field::discrete_frequency(k, dx, dt);
    let mut wave = Field::new(WAVE, (0.0, TAU), cells, Boundary::Periodic, dt).unwrap();
    let x = wave.positions();
    // Störmer–Verlet's momentum at t_n is (u^{n+1} − u^{n−1})/(2Δt).
    let rate = (omega * dt).sin() / dt;
    wave.start(
        &at(&x, |x| (k * x).cos()),
        &at(&x, |x| rate * (k * x).sin()),
    )
    .unwrap();
    wave.run(2_000).unwrap();
    let t = wave.t();
    let discrete = error(&wave, |x| SVector::from([(k * x - omega * t).cos()]));
    let continuum = error(&wave, |x| SVector::from([(k * x - k * t).cos()]));
    println!("discrete relation {discrete:.2e}, continuum's {continuum:.2e}");
    assert!(
        discrete < 1e-11,
        "off the discrete plane wave by {discrete:e}"
    );
    assert!(
        continuum > 0.1,
        "the continuum's wave is as close: {continuum:e}"
    );
}

/// In time, each composition has its order against the plane wave of the semi-discrete wave
/// equation, `cos(k x_j − ω t)` with `ω = 2 sin(kΔx/2)/Δx`, which the grid carries exactly.
#[test]
fn each_composition_has_its_order_in_time() {
    let (cells, k, t) = (16, 2.0, 1.0);
    let dx = TAU / cells as f64;
    let omega = field::semi_discrete_frequency(k, dx);
    let cases = [
        (Composition::verlet(), [20, 40, 80]),
        (Composition::triple_jump(), [8, 16, 32]),
        (Composition::kahan_li_6(), [8, 16, 32]),
        (Composition::kahan_li_8(), [5, 7, 10]),
    ];
    for (composition, steps) in cases {
        let order = composition.order() as f64;
        let name = composition.name();
        let errors: Vec<f64> = steps
            .iter()
            .map(|&n| {
                let dt = t / n as f64;
                let mut wave = Field::new(WAVE, (0.0, TAU), cells, Boundary::Periodic, dt)
                    .unwrap()
                    .with_composition(composition.clone());
                let x = wave.positions();
                let u0 = at(&x, |x| (k * x).cos());
                wave.start(&u0, &at(&x, |x| omega * (k * x).sin())).unwrap();
                wave.run(n).unwrap();
                error(&wave, |x| SVector::from([(k * x - omega * t).cos()]))
            })
            .collect();
        let hs: Vec<f64> = steps.iter().map(|&n| t / n as f64).collect();
        assert_order(name, &hs, &errors, order);
    }
}

/// In space and time together (Δt = Δx/2), the sine-Gordon kink moving at half the speed of
/// light converges at order 2 to the closed form `4 arctan exp(γ(x − vt))`, and the field's
/// energy at order 2 to the kink's `8γ`.
#[test]
fn the_sine_gordon_kink_converges_at_order_two() {
    let (v, t) = (0.5, 4.0);
    let mut errors = Vec::new();
    let mut energy_errors = Vec::new();
    let mut hs = Vec::new();
    for cells in [100, 200, 400] {
        let dx = 40.0 / cells as f64;
        let steps = (t / (0.5 * dx)).round() as u64;
        let dt = t / steps as f64;
        let mut kink = Field::new(SineGordon, (-20.0, 20.0), cells, Boundary::Fixed, dt).unwrap();
        let x = kink.positions();
        let u0 = at(&x, |x| field::kink(v, 0.0, x).0);
        let mut ut0 = at(&x, |x| field::kink(v, 0.0, x).1);
        // The ends are held: the kink's tails there move by e^{−γ 20} ≈ 1e-10.
        let last = ut0.len() - 1;
        (ut0[0], ut0[last]) = (SVector::zeros(), SVector::zeros());
        kink.start(&u0, &ut0).unwrap();
        kink.run(steps).unwrap();
        errors.push(error(&kink, |x| SVector::from([field::kink(v, t, x).0])));
        energy_errors.push((kink.energy().unwrap() - field::kink_energy(v)).abs());
        hs.push(dx);
    }
    assert_order("sine-Gordon kink", &hs, &errors, 2.0);
    assert_order("sine-Gordon kink's energy", &hs, &energy_errors, 2.0);
    // Measured 3.3e-3 at Δx = 0.1.
    assert!(errors[2] < 4e-3, "{errors:?}");
}

/// The sine-Gordon breather of frequency ω = 0.5 (fixed ends, Δt = Δx/2) over a period of its
/// oscillation, 4π: order 2 in space and time together against the closed form, and the
/// energy converging to `16 √(1 − ω²)` faster still.
#[test]
fn the_sine_gordon_breather_converges_at_order_two() {
    let (omega, t) = (0.5, 4.0 * std::f64::consts::PI);
    let (mut errors, mut energy_errors, mut hs) = (Vec::new(), Vec::new(), Vec::new());
    for cells in [200, 400, 800] {
        let dx = 40.0 / cells as f64;
        let steps = (t / (0.5 * dx)).round() as u64;
        let dt = t / steps as f64;
        let mut breather =
            Field::new(SineGordon, (-20.0, 20.0), cells, Boundary::Fixed, dt).unwrap();
        let x = breather.positions();
        let u0 = at(&x, |x| field::breather(omega, 0.0, x).0);
        let mut ut0 = at(&x, |x| field::breather(omega, 0.0, x).1);
        // The ends are held: the breather's tails there are below 1e-6.
        let last = ut0.len() - 1;
        (ut0[0], ut0[last]) = (SVector::zeros(), SVector::zeros());
        breather.start(&u0, &ut0).unwrap();
        breather.run(steps).unwrap();
        errors.push(error(&breather, |x| {
            SVector::from([field::breather(omega, t, x).0])
        }));
        energy_errors.push((breather.energy().unwrap() - field::breather_energy(omega)).abs());
        hs.push(dx);
    }
    assert_order("sine-Gordon breather", &hs, &errors, 2.0);
    // Measured 2.6e-2 at Δx = 0.05 (the error is the breather's phase, after a period).
    assert!(errors[2] < 3e-2, "{errors:?}");
    // At t = 4π the breather is all velocity (u = 0): the trapezoidal sum of ½u_t² converges
    // faster than any power for a smooth decaying profile, and the scheme's energy error is
    // small there. Measured: 2.1e-3, 3.1e-5, 3.5e-7 (slope 6.3).
    let energy_order = slope(&hs, &energy_errors);
    println!("sine-Gordon breather's energy: {energy_order:.2} {energy_errors:?}");
    assert!(
        energy_order > 4.0 && energy_errors[2] < 1e-6,
        "{energy_errors:?}"
    );
}

/// A field's snapshots written to the compact binary file read back bit for bit, in the size
/// the layout gives; a file cut short, another file, or another number of components is
/// refused, and a snapshot of another length is not written.
#[test]
fn snapshots_read_back_bit_for_bit() {
    use dirac::snapshots::{SnapshotWriter, Snapshots};
    let mut strings = Field::new(
        CoupledStrings { k: 2.0 },
        (0.0, TAU),
        50,
        Boundary::Periodic,
        0.05,
    )
    .unwrap();
    let x = strings.positions();
    let u0: Vec<SVector<f64, 2>> = x
        .iter()
        .map(|&x| SVector::from([x.sin(), 0.3 * (2.0 * x).cos()]))
        .collect();
    strings
        .start(&u0, &vec![SVector::zeros(); x.len()])
        .unwrap();
    let mut writer = SnapshotWriter::<_, 2>::new(Vec::new(), &x).unwrap();
    let mut expected = Vec::new();
    for _ in 0..3 {
        writer.record(&strings).unwrap();
        expected.push((strings.t(), strings.u().unwrap().to_vec()));
        strings.run(7).unwrap();
    }
    assert!(matches!(
        writer.write(1.0, &u0[1..]),
        Err(DiracError::Dimension(_))
    ));
    let bytes = writer.finish().unwrap();
    assert_eq!(bytes.len(), 24 + 8 * x.len() + 3 * 8 * (1 + 2 * x.len()));
    let read = Snapshots::<2>::read(&bytes[..]).unwrap();
    assert_eq!(read.positions, x);
    for (k, (t, u)) in expected.iter().enumerate() {
        assert_eq!((read.t[k], &read.u[k]), (*t, u));
    }
    assert!(matches!(
        Snapshots::<2>::read(&bytes[..bytes.len() - 1]),
        Err(DiracError::Io(m)) if m.contains("inside a snapshot")
    ));
    assert!(matches!(
        Snapshots::<1>::read(&bytes[..]),
        Err(DiracError::Dimension(_))
    ));
    assert!(matches!(
        Snapshots::<2>::read(&b"t,u\n0,1\n"[..]),
        Err(DiracError::Io(_))
    ));
}

/// The kink–antikink collision of Perring and Skyrme (free ends, Δt = 0.4 Δx), through the
/// moment the two pass each other: order 2 against the closed form, and in the energy against
/// the pair's `2 · 8γ` at every snapshot.
#[test]
fn the_kink_antikink_collision_converges_at_order_two() {
    let cells = [200, 400, 800];
    let runs: Vec<_> = cells
        .iter()
        .map(|&n| field::collision_run(n, 4.0, 4).unwrap())
        .collect();
    let errors: Vec<f64> = runs.iter().map(|r| r.error).collect();
    let hs: Vec<f64> = cells.iter().map(|&n| 40.0 / n as f64).collect();
    assert_order("kink–antikink collision", &hs, &errors, 2.0);
    // The energy at every snapshot, the collision's included, against the pair's 16γ.
    let pair = 2.0 * field::kink_energy(0.5);
    let energy_errors: Vec<f64> = runs
        .iter()
        .map(|r| {
            r.energy
                .iter()
                .map(|e| (e - pair).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    assert_order("the collision's energy", &hs, &energy_errors, 2.0);
}

/// A periodic sine-Gordon field of 10 000 cells, whose step's passes take three blocks, follows a
/// hand-written leapfrog of the same scheme (`scenes::field::leapfrog_sine_gordon`) to round-off
/// over 200 steps, the blocks' edges included.
#[test]
fn a_field_of_several_blocks_equals_a_hand_written_leapfrog() {
    let (cells, dx, dt) = (10_000, 0.05, 0.02);
    let length = cells as f64 * dx;
    let mode = |m: f64, x: f64| TAU * m * x / length;
    let mut sine_gordon =
        Field::new(SineGordon, (0.0, length), cells, Boundary::Periodic, dt).unwrap();
    let x = sine_gordon.positions();
    let u0: Vec<f64> = x
        .iter()
        .map(|&x| mode(29.0, x).sin() + 0.5 * mode(300.0, x).cos())
        .collect();
    let ut0: Vec<f64> = x.iter().map(|&x| 0.3 * mode(7.0, x).cos()).collect();
    let lift = |values: &[f64]| {
        values
            .iter()
            .map(|&v| SVector::from([v]))
            .collect::<Vec<_>>()
    };
    sine_gordon.start(&lift(&u0), &lift(&ut0)).unwrap();
    sine_gordon.run(200).unwrap();
    let (mut u, mut rate, mut force) = (u0, ut0, vec![0.0; cells]);
    field::sine_gordon_force(&u, &mut force, dx);
    for _ in 0..200 {
        field::leapfrog_sine_gordon(&mut u, &mut rate, &mut force, dx, dt);
    }
    let field_u = sine_gordon.u().unwrap();
    let field_rate = sine_gordon.velocities().unwrap();
    let apart = (0..cells)
        .map(|j| {
            (field_u[j][0] - u[j])
                .abs()
                .max((field_rate[j][0] - rate[j]).abs())
        })
        .fold(0.0, f64::max);
    assert!(apart < 1e-11, "apart by {apart:e}");
    assert!(u.iter().any(|u| u.abs() > 1.0), "the field did not move");
}

/// A string whose tension grows along it, `κ(x) = 1 + x`, fixed at both ends: the discrete
/// equilibrium (the flux `½ (κ(x_j) + κ(x_{j+1})) (u_{j+1} − u_j)/Δx` the same in every cell)
/// stays at rest to round-off, while the equilibrium of a cell's tension read at its left end
/// alone does not: the step reads the density at both ends of each cell.
#[test]
fn a_density_that_varies_along_the_string_keeps_its_equilibrium() {
    let cells = 50;
    let dx = 1.0 / cells as f64;
    let tension = |x: f64| 1.0 + x;
    let equilibrium = |cell_tension: &dyn Fn(usize) -> f64| {
        let mut u = vec![SVector::from([0.0])];
        for i in 0..cells {
            let next = u[i][0] + dx / cell_tension(i);
            u.push(SVector::from([next]));
        }
        u
    };
    let at_rest = |u0: &[SVector<f64, 1>]| {
        let mut string = Field::new(Graded, (0.0, 1.0), cells, Boundary::Fixed, 0.005).unwrap();
        string
            .start(u0, &vec![SVector::zeros(); cells + 1])
            .unwrap();
        string.run(500).unwrap();
        let moved = error(&string, |x| u0[(x / dx).round() as usize]);
        let momentum = string
            .momenta()
            .unwrap()
            .iter()
            .map(|p| p.amax())
            .fold(0.0, f64::max);
        moved.max(momentum)
    };
    let both_ends = equilibrium(&|i| 0.5 * (tension(i as f64 * dx) + tension((i + 1) as f64 * dx)));
    let left_end = equilibrium(&|i| tension(i as f64 * dx));
    let (kept, left) = (at_rest(&both_ends), at_rest(&left_end));
    println!("at rest: {kept:.1e}; the left end's equilibrium moves by {left:.1e}");
    assert!(kept < 1e-13, "the equilibrium moved by {kept:e}");
    assert!(
        left > 1e-5,
        "the left end's equilibrium moved only by {left:e}"
    );
}

/// `ℒ = ½ u_t² − ½ (1 + x) u_x²`: a string whose tension grows along it.
struct Graded;
impl SeparableDensity<1> for Graded {
    fn inertia(&self, _x: f64) -> SVector<f64, 1> {
        SVector::from([1.0])
    }
    fn potential<S: Scalar>(&self, x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
        ux[0] * ux[0] * (0.5 * (1.0 + x))
    }
}

/// A string whose inertia varies along it, `ρ(x) = 1 + x²`, with free ends: moving as a whole
/// at unit speed its energy is half the trapezoidal sum of `ρ` (each node weighs `ρ(x_j) Δx`, an
/// end half that); plucked, its total momentum `Σ p_j` stays what it was to round-off, as the
/// potential `½ u_x²` does not change when the whole string moves.
#[test]
fn a_varying_inertia_weighs_each_node_and_keeps_the_momentum() {
    let (cells, length) = (40, 2.0);
    let dx = length / cells as f64;
    let rho = |x: f64| 1.0 + x * x;
    let mut string = Field::new(Heavy, (0.0, length), cells, Boundary::Free, 0.01).unwrap();
    let x = string.positions();
    string
        .start(&vec![SVector::zeros(); x.len()], &at(&x, |_| 1.0))
        .unwrap();
    let interior: f64 = x[1..cells].iter().map(|&x| rho(x)).sum();
    let trapezoid = dx * (0.5 * rho(0.0) + interior + 0.5 * rho(length));
    let energy = string.energy().unwrap();
    assert!(
        (energy - 0.5 * trapezoid).abs() < 1e-13,
        "{energy} against {}",
        0.5 * trapezoid
    );
    string
        .start(&at(&x, |x| (3.0 * x).sin()), &at(&x, |x| x.cos()))
        .unwrap();
    let total =
        |string: &Field<Heavy, 1>| string.momenta().unwrap().iter().map(|p| p[0]).sum::<f64>();
    let before = total(&string);
    string.run(1_000).unwrap();
    let after = total(&string);
    assert!(
        (after - before).abs() < 1e-13,
        "momentum {before} then {after}"
    );
    assert!(before.abs() > 0.1);
}

/// `ℒ = ½ (1 + x²) u_t² − ½ u_x²`: a string heavier towards one end.
struct Heavy;
impl SeparableDensity<1> for Heavy {
    fn inertia(&self, x: f64) -> SVector<f64, 1> {
        SVector::from([1.0 + x * x])
    }
    fn potential<S: Scalar>(&self, _x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
        ux[0] * ux[0] * 0.5
    }
}

/// A string fixed at both ends (`sin(πx) cos(πt)`) and a bar free at both ends
/// (`cos(πx) cos(πt)`, the ends carrying half a cell): both converge at order 2 in space and
/// time, and the fixed ends do not move.
#[test]
fn fixed_and_free_ends_converge_at_order_two() {
    let t = 0.7;
    type Shape = fn(f64) -> f64;
    let cases: [(Boundary, Shape); 2] = [
        (Boundary::Fixed, |x| (PI * x).sin()),
        (Boundary::Free, |x| (PI * x).cos()),
    ];
    for (boundary, shape) in cases {
        let mut errors = Vec::new();
        let mut hs = Vec::new();
        for cells in [20, 40, 80] {
            let dx = 1.0 / cells as f64;
            let steps = (t / (0.5 * dx)).round() as u64;
            let string = Field::new(WAVE, (0.0, 1.0), cells, boundary, t / steps as f64).unwrap();
            let (string, off) = standing_wave(string, shape, PI, steps);
            errors.push(off);
            hs.push(dx);
            let (u, x) = (string.u().unwrap(), string.positions());
            if boundary == Boundary::Fixed {
                assert_eq!((u[0][0], u[cells][0]), (shape(x[0]), shape(x[cells])));
            }
        }
        assert_order(&format!("{boundary:?} ends"), &hs, &errors, 2.0);
    }
}

/// Two strings joined by springs, the first plucked into a cosine: the sum `u + w` is a wave
/// of the semi-discrete frequency `ω_a`, the difference a Klein–Gordon mode of
/// `ω_b = √(ω_a² + 2k)`; Kahan–Li 8 follows both to 1e-10.
#[test]
fn two_components_follow_their_modes() {
    let (cells, k, spring, t) = (32, 3.0, 2.0, 2.0);
    let dx = TAU / cells as f64;
    let omega_a = field::semi_discrete_frequency(k, dx);
    let omega_b = (omega_a * omega_a + 2.0 * spring).sqrt();
    let strings = CoupledStrings { k: spring };
    let mut pair = Field::new(strings, (0.0, TAU), cells, Boundary::Periodic, 0.01)
        .unwrap()
        .with_composition(Composition::kahan_li_8());
    let x = pair.positions();
    let u0: Vec<_> = x
        .iter()
        .map(|&x| SVector::from([(k * x).cos(), 0.0]))
        .collect();
    pair.start(&u0, &vec![SVector::zeros(); x.len()]).unwrap();
    pair.run(200).unwrap();
    let exact = |x: f64| {
        let (sum, difference) = ((omega_a * t).cos(), (omega_b * t).cos());
        SVector::from([sum + difference, sum - difference]) * (0.5 * (k * x).cos())
    };
    let error = error(&pair, exact);
    assert!(error < 1e-10, "off the modes by {error:e}");
}

/// A string (ρ = 1, tension 1, length 1) with a point mass `M = 0.5` joined to each free end
/// (`M u_tt = ±u_x` there): its first mode `cos kx − Mk sin kx` with `tan k = 2Mk/(M²k² − 1)`,
/// oscillating as `cos kt`. Order 2 in space and time together (Δt = Δx/2), and masses at ends
/// that are not free are refused.
#[test]
fn a_string_with_masses_at_its_ends_keeps_its_mode() {
    let m = 0.5;
    let root = |k: f64| (m * m * k * k - 1.0) * k.sin() - 2.0 * m * k * k.cos();
    let (mut low, mut high) = (1.0, 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if root(mid) < 0.0 {
            low = mid;
        } else {
            high = mid;
        }
    }
    let k = 0.5 * (low + high);
    let shape = |x: f64| (k * x).cos() - m * k * (k * x).sin();
    let t = 3.0;
    let (mut errors, mut hs) = (Vec::new(), Vec::new());
    for cells in [50, 100, 200] {
        let dx = 1.0 / cells as f64;
        let steps = (t / (0.5 * dx)).round() as u64;
        let string = Field::new(WAVE, (0.0, 1.0), cells, Boundary::Free, t / steps as f64)
            .unwrap()
            .with_end_masses(m, m)
            .unwrap();
        errors.push(standing_wave(string, shape, k, steps).1);
        hs.push(dx);
    }
    assert_order("string with end masses", &hs, &errors, 2.0);
    // Without the masses the same shape is no mode: the run leaves it by far more.
    let bare = Field::new(WAVE, (0.0, 1.0), 200, Boundary::Free, 0.0025).unwrap();
    let off = standing_wave(bare, shape, k, 1200).1;
    assert!(off > 1e3 * errors[2], "{off} {errors:?}");
    for boundary in [Boundary::Fixed, Boundary::Periodic] {
        let refused = Field::new(WAVE, (0.0, 1.0), 10, boundary, 0.01)
            .unwrap()
            .with_end_masses(1.0, 1.0);
        assert!(matches!(refused, Err(DiracError::Unsupported(_))));
    }
    for bad in [-1.0, f64::NAN] {
        let refused = Field::new(WAVE, (0.0, 1.0), 10, Boundary::Free, 0.01)
            .unwrap()
            .with_end_masses(bad, 0.0);
        assert!(matches!(refused, Err(DiracError::NonFinite { .. })));
    }
}

/// The discrete multisymplectic conservation law, node by node and step by step. For a linear
/// density any two solutions `U`, `W` are first variations of each other, and the trapezoidal
/// cells (the leapfrog `u^{n+1} − 2u^n + u^{n−1} = Δt² (Δ²u/Δx² − k(u − w), …)`) keep
/// `(κ_j^{n+½} − κ_j^{n−½})/Δt = (φ_{j+½}^n − φ_{j−½}^n)/Δx` with
/// `κ_j^{n+½} = Σ_c (U_j^{n+1} W_j^n − W_j^{n+1} U_j^n)/Δt` and
/// `φ_{j+½}^n = Σ_c (U_{j+1}^n W_j^n − W_{j+1}^n U_j^n)/Δx` (the coupling springs' terms cancel
/// between the two components). Two coupled strings on a periodic grid from unrelated rough
/// data, 300 steps: the law holds at every node to round-off of its terms.
#[test]
fn the_multisymplectic_law_holds_cell_by_cell() {
    let (cells, dt) = (40, 0.05);
    let dx = TAU / cells as f64;
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
        let mut pair = Field::new(
            CoupledStrings { k: 2.0 },
            (0.0, TAU),
            cells,
            Boundary::Periodic,
            dt,
        )
        .unwrap();
        let n = pair.nodes();
        let u0: Vec<SVector<f64, 2>> = (0..n)
            .map(|_| SVector::from([random(), random()]))
            .collect();
        let ut0: Vec<SVector<f64, 2>> = (0..n)
            .map(|_| SVector::from([random(), random()]))
            .collect();
        pair.start(&u0, &ut0).unwrap();
        let mut history = vec![pair.u().unwrap().to_vec()];
        for _ in 0..300 {
            pair.step().unwrap();
            history.push(pair.u().unwrap().to_vec());
        }
        histories.push(history);
    }
    let (u, w) = (&histories[0], &histories[1]);
    let n = u[0].len();
    let kappa = |m: usize, j: usize| (u[m + 1][j].dot(&w[m][j]) - w[m + 1][j].dot(&u[m][j])) / dt;
    let phi = |m: usize, j: usize| {
        let next = (j + 1) % n;
        (u[m][next].dot(&w[m][j]) - w[m][next].dot(&u[m][j])) / dx
    };
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    for m in 1..u.len() - 1 {
        for j in 0..n {
            let before = (j + n - 1) % n;
            let time = (kappa(m, j) - kappa(m - 1, j)) / dt;
            let space = (phi(m, j) - phi(m, before)) / dx;
            worst = worst.max((time - space).abs());
            scale = scale.max(kappa(m, j).abs() / dt + phi(m, j).abs() / dx);
        }
    }
    println!("multisymplectic law: largest defect {worst:.2e} against terms of {scale:.2e}");
    assert!(
        // Measured 3.4e-13 against 6.2e2.
        scale > 1.0 && worst < 1e-14 * scale,
        "{worst:e} of {scale:e}"
    );
}

/// A sine-Gordon breather-like pulse on a periodic grid over 20 000 steps: the energy error
/// oscillates within the same band at the end as in the first tenth, a band well above
/// round-off (the step keeps a modified energy; it does not keep the energy itself).
#[test]
fn the_energy_error_stays_bounded() {
    let mut pulse = Field::new(SineGordon, (-16.0, 16.0), 64, Boundary::Periodic, 0.1).unwrap();
    let x = pulse.positions();
    let ut0 = at(&x, |x| 2.0 / x.cosh());
    pulse.start(&vec![SVector::zeros(); x.len()], &ut0).unwrap();
    let mut energy = vec![pulse.energy().unwrap()];
    for _ in 0..2_000 {
        pulse.run(10).unwrap();
        energy.push(pulse.energy().unwrap());
    }
    let (first, last) = energy_error_first_and_last_tenth(&energy);
    println!("energy error: first tenth {first:.2e}, last tenth {last:.2e}");
    assert!(first > 1e-8, "the band is round-off: {first:e}");
    assert!(last < 1.5 * first, "drift: {first:e} then {last:e}");
}

/// Split across threads (20 000 cells, above the grain), the steps are the same bit for bit.
#[test]
fn parallel_and_sequential_fields_step_alike() {
    let runs = [false, true].map(|parallel| {
        let mut kinks = Field::new(SineGordon, (-100.0, 100.0), 20_000, Boundary::Free, 0.004)
            .unwrap()
            .with_parallel(parallel);
        let x = kinks.positions();
        let u0 = at(&x, |x| field::kink(0.5, 0.0, x.sin() * 10.0).0);
        let ut0 = at(&x, |x| field::kink(0.5, 0.0, x.sin() * 10.0).1);
        kinks.start(&u0, &ut0).unwrap();
        kinks.run(5).unwrap();
        kinks
    });
    assert_eq!(runs[0].u().unwrap(), runs[1].u().unwrap());
    assert_eq!(runs[0].momenta().unwrap(), runs[1].momenta().unwrap());
    assert_eq!(runs[0].t(), runs[1].t());
}

/// `U = 2√u`: finite for `u ≥ 0`, not below.
struct Root;
impl SeparableDensity<1> for Root {
    fn inertia(&self, _x: f64) -> SVector<f64, 1> {
        SVector::from([1.0])
    }
    fn potential<S: Scalar>(&self, _x: f64, u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
        ux[0] * ux[0] * 0.5 + u[0].sqrt() * 2.0
    }
}

/// An inertia that is zero at the middle of the interval.
struct Massless;
impl SeparableDensity<1> for Massless {
    fn inertia(&self, x: f64) -> SVector<f64, 1> {
        SVector::from([x.abs()])
    }
    fn potential<S: Scalar>(&self, _x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
        ux[0] * ux[0]
    }
}

/// What a field refuses, and a failed step that changes nothing.
#[test]
fn what_a_field_refuses() {
    let periodic = Boundary::Periodic;
    let refused = Field::new(WAVE, (0.0, 1.0), 10, periodic, 0.0);
    assert!(matches!(refused, Err(DiracError::InvalidStep { .. })));
    let refused = Field::new(WAVE, (0.0, 1.0), 10, periodic, f64::NAN);
    assert!(matches!(refused, Err(DiracError::InvalidStep { .. })));
    assert!(matches!(
        Field::new(WAVE, (0.0, 1.0), 2, periodic, 0.1),
        Err(DiracError::Dimension(_))
    ));
    assert!(matches!(
        Field::new(WAVE, (0.0, 1.0), 1, Boundary::Fixed, 0.1),
        Err(DiracError::Dimension(_))
    ));
    assert!(matches!(
        Field::new(WAVE, (1.0, 1.0), 10, periodic, 0.1),
        Err(DiracError::InvalidRun(_))
    ));
    assert!(matches!(
        Field::new(WAVE, (0.0, f64::INFINITY), 10, periodic, 0.1),
        Err(DiracError::InvalidRun(_))
    ));
    assert!(matches!(
        Field::new(Massless, (-1.0, 1.0), 10, Boundary::Free, 0.1),
        Err(DiracError::NonFinite { .. })
    ));

    let mut string = Field::new(WAVE, (0.0, 1.0), 10, Boundary::Fixed, 0.01).unwrap();
    assert_eq!(string.step(), Err(DiracError::NotStarted));
    assert_eq!(string.u().err(), Some(DiracError::NotStarted));
    let x = string.positions();
    let zeros = vec![SVector::zeros(); x.len()];
    let short = vec![SVector::zeros(); x.len() - 1];
    assert!(matches!(
        string.start(&short, &zeros),
        Err(DiracError::Dimension(_))
    ));
    assert!(matches!(
        string.start(&zeros, &short),
        Err(DiracError::Dimension(_))
    ));
    let mut bad = zeros.clone();
    bad[3][0] = f64::NAN;
    assert!(matches!(
        string.start(&bad, &zeros),
        Err(DiracError::NonFinite { .. })
    ));
    let mut moving_end = zeros.clone();
    moving_end[0][0] = 1.0;
    assert!(matches!(
        string.start(&zeros, &moving_end),
        Err(DiracError::InconsistentInitialState(_))
    ));
    assert_eq!(string.u().err(), Some(DiracError::NotStarted));

    // The field falls below zero, where U = 2√u is not defined: the step is refused and the
    // state is that of the step before.
    let mut root = Field::new(Root, (0.0, 1.0), 10, Boundary::Free, 0.3).unwrap();
    let x = root.positions();
    root.start(&at(&x, |_| 0.05), &at(&x, |_| -0.1)).unwrap();
    let before = (
        root.u().unwrap().to_vec(),
        root.momenta().unwrap().to_vec(),
        root.t(),
        root.energy().unwrap(),
    );
    let failed = root.step();
    assert!(
        matches!(failed, Err(DiracError::NonFinite { .. })),
        "{failed:?}"
    );
    let after = (
        root.u().unwrap().to_vec(),
        root.momenta().unwrap().to_vec(),
        root.t(),
        root.energy().unwrap(),
    );
    assert_eq!(before, after);
}

/// The method of lines that the field's work–precision study runs (`scenes::field_lines`:
/// Dop853 and Dopri5 on `u_tt = u_xx − sin u` discretised in space) integrates the field's own
/// semi-discrete equations, free ends included: the two energies agree at the start, and the
/// field's steps converge to Dop853's solution at 1e-12 on the same grid, Störmer–Verlet at
/// order 2 and Suzuki at order 4 (two different equations would leave a difference that does
/// not shrink). A kink crossing `[−5, 5]` moves the free ends (by about 0.04), so their
/// equations are in the comparison.
#[test]
fn the_method_of_lines_integrates_the_fields_semi_discrete_equations() {
    use scenes::field_lines::{SineGordonLines, distance, field_run, integrate};
    use scenes::peers::Peer;
    let lines = SineGordonLines::new((-5.0, 5.0), 40).unwrap();
    let y0 = lines.kink(0.5, -2.0);
    let field = lines.field(&Composition::verlet(), 0.1, &y0).unwrap();
    let (e_field, e_lines) = (field.energy().unwrap(), lines.energy(&y0));
    assert!(
        (e_field - e_lines).abs() <= 1e-14 * e_lines,
        "{e_field} against {e_lines}"
    );
    let horizon = 4.0;
    let reference = integrate(&lines, Peer::Dop853, &y0, horizon, 1e-12).unwrap();
    let n = lines.nodes();
    let ends = [reference.end[0] - y0[0], reference.end[n - 1] - y0[n - 1]];
    assert!(
        ends.iter().all(|d| d.abs() > 1e-2),
        "the ends barely move: {ends:?}"
    );
    let steps = [0.05, 0.025, 0.0125];
    for (composition, order) in [(Composition::verlet(), 2.0), (Composition::suzuki(), 4.0)] {
        let errors: Vec<f64> = steps
            .iter()
            .map(|&dt| {
                let run = field_run(&lines, &composition, dt, &y0, horizon).unwrap();
                distance(&run.end, &reference.end)
            })
            .collect();
        assert_order(composition.name(), &steps, &errors, order);
    }
}

/// The string's standing wave `sin(3πx) cos(3πt)` (fixed ends) over `0 < t ≤ 0.5` on cells of
/// degree 1 to 5 (Kahan–Li 8 in time at `Δt = Δx/(3r²)`, whose own error is far below): the
/// largest error over the run falls on 8, 16 and 32 cells at order `2` for degree 1 and `r + 2`
/// for degrees 2 to 5 (measured 1.98, 4.03, 5.01, 6.00, 6.86), and each degree is at least ten
/// times closer than the one below on 32 cells. The error at one time is no measure of the
/// order: the start excites the cells' high branches, whose oscillations it samples at an
/// arbitrary phase (at `t = 0.5` alone the slopes run from 3.2 to 7.5). Free ends are held as
/// well: the bar's mode `cos 3πx` on 16 cells of degree 3.
#[test]
fn lobatto_cells_converge_faster_with_their_degree() {
    let k = 3.0 * PI;
    let cells = [8usize, 16, 32];
    let mut finest = f64::INFINITY;
    for degree in 1..=5usize {
        let errors: Vec<f64> = cells
            .iter()
            .map(|&n| {
                let r = degree as f64;
                let steps = (0.5 * 3.0 * r * r * n as f64).ceil() as u64;
                let dt = 0.5 / steps as f64;
                let mut string = Field::new(WAVE, (0.0, 1.0), n, Boundary::Fixed, dt)
                    .unwrap()
                    .with_degree(degree)
                    .unwrap()
                    .with_composition(Composition::kahan_li_8());
                let x = string.positions();
                string
                    .start(&at(&x, |x| (k * x).sin()), &at(&x, |_| 0.0))
                    .unwrap();
                (1..=steps)
                    .map(|step| {
                        string.run(1).unwrap();
                        let t = step as f64 * dt;
                        error(&string, |x| SVector::from([(k * x).sin() * (k * t).cos()]))
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let hs: Vec<f64> = cells.iter().map(|&n| 1.0 / n as f64).collect();
        let expected = if degree == 1 {
            2.0
        } else {
            degree as f64 + 2.0
        };
        assert_order(&format!("degree {degree}"), &hs, &errors, expected);
        assert!(errors[2] < 0.1 * finest, "degree {degree}: {errors:?}");
        finest = errors[2];
    }
    // Free ends, degree 3, 16 cells: the bar's mode `cos 3πx cos 3πt` as closely.
    let steps = (0.5 * 27.0 * 16.0_f64).ceil() as u64;
    let mut bar = Field::new(WAVE, (0.0, 1.0), 16, Boundary::Free, 0.5 / steps as f64)
        .unwrap()
        .with_degree(3)
        .unwrap()
        .with_composition(Composition::kahan_li_8());
    let x = bar.positions();
    bar.start(&at(&x, |x| (k * x).cos()), &at(&x, |_| 0.0))
        .unwrap();
    bar.run(steps).unwrap();
    let free = error(&bar, |x| SVector::from([(k * x).cos() * (0.5 * k).cos()]));
    println!("free ends, degree 3, 16 cells: {free:.2e}");
    assert!(free < 1e-5, "{free:e}");
}

/// The spectral-element leapfrog of the sine-Gordon field written out by hand: on each cell of
/// degree `r` the stiffness `K_mn = Σ_q w_q D_qm D_qn / Δx`, the lumped masses `w_m Δx` (summed
/// where cells meet), and `m ü = −K u − m sin u`; periodic, Störmer–Verlet.
fn spectral_leapfrog(
    u: &mut [f64],
    v: &mut [f64],
    cells: usize,
    r: usize,
    dx: f64,
    dt: f64,
    steps: usize,
) {
    use dirac::Quadrature;
    let rule = Quadrature::galerkin_with_rule(r, dirac::Rule::GaussLobatto(r + 1)).unwrap();
    let (c, w) = (rule.nodes().to_vec(), rule.weights().to_vec());
    let d = |q: usize, m: usize| -> f64 {
        // ℓ'_m(c_q) from the product rule.
        (0..=r)
            .filter(|&l| l != m)
            .map(|l| {
                let others: f64 = (0..=r)
                    .filter(|&i| i != m && i != l)
                    .map(|i| (c[q] - c[i]) / (c[m] - c[i]))
                    .product();
                others / (c[m] - c[l])
            })
            .sum()
    };
    let n = u.len();
    let mut mass = vec![0.0; n];
    for e in 0..cells {
        for m in 0..=r {
            mass[(e * r + m) % n] += w[m] * dx;
        }
    }
    let accel = |u: &[f64]| -> Vec<f64> {
        let mut f = vec![0.0; n];
        for e in 0..cells {
            for m in 0..=r {
                for l in 0..=r {
                    let stiffness: f64 =
                        (0..=r).map(|q| w[q] * d(q, m) * d(q, l)).sum::<f64>() / dx;
                    f[(e * r + m) % n] -= stiffness * u[(e * r + l) % n];
                }
            }
        }
        (0..n).map(|j| f[j] / mass[j] - u[j].sin()).collect()
    };
    let mut a = accel(u);
    for _ in 0..steps {
        for j in 0..n {
            v[j] += 0.5 * dt * a[j];
            u[j] += dt * v[j];
        }
        a = accel(u);
        for j in 0..n {
            v[j] += 0.5 * dt * a[j];
        }
    }
}

/// Cells of degree 3 step the sine-Gordon field as the spectral-element leapfrog written out by
/// hand (`spectral_leapfrog`): a periodic pulse over 200 steps, to round-off; the cells' points
/// sit at `a + (e + c_m) Δx`, and the field's total mass is `ρ L`.
#[test]
fn lobatto_cells_are_the_spectral_element_leapfrog() {
    let (cells, r, dt) = (12, 3, 0.02);
    let length = 12.0;
    let dx = length / cells as f64;
    let mut field = Field::new(SineGordon, (0.0, length), cells, Boundary::Periodic, dt)
        .unwrap()
        .with_degree(r)
        .unwrap();
    assert_eq!((field.nodes(), field.degree()), (cells * r, r));
    let x = field.positions();
    let (c3, c1) = (
        0.5 + 0.5 * (1.0_f64 / 5.0).sqrt(),
        0.5 - 0.5 * (1.0_f64 / 5.0).sqrt(),
    );
    assert!((x[4] - (dx + c1 * dx)).abs() < 1e-14 && (x[5] - (dx + c3 * dx)).abs() < 1e-14);
    let shape = |x: f64| 2.0 / (x - 6.0).cosh() + 0.3 * (TAU * x / length).sin();
    let mut u: Vec<f64> = x.iter().map(|&x| shape(x)).collect();
    let mut v: Vec<f64> = x.iter().map(|&x| (TAU * x / length).cos()).collect();
    field
        .start(&at(&x, shape), &at(&x, |x| (TAU * x / length).cos()))
        .unwrap();
    field.run(200).unwrap();
    spectral_leapfrog(&mut u, &mut v, cells, r, dx, dt, 200);
    let worst = (field.u().unwrap().iter().zip(&u))
        .map(|(a, b)| (a[0] - b).abs())
        .fold(0.0, f64::max);
    println!("degree 3 against the hand-written spectral leapfrog: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
    // 1 400 cells, 4 200 nodes: the force's second block starts at node 4 096, point 1 of cell
    // 1 365.
    let (many, length) = (1_400, 1_400.0);
    let mut long = Field::new(SineGordon, (0.0, length), many, Boundary::Periodic, dt)
        .unwrap()
        .with_degree(r)
        .unwrap();
    let nodes = long.positions();
    let bumps = |x: f64| (x * 0.37).sin() + 0.5 * (x * 1.3).cos();
    long.start(&at(&nodes, bumps), &at(&nodes, |x| (x * 0.11).cos()))
        .unwrap();
    long.run(5).unwrap();
    let mut u: Vec<f64> = nodes.iter().map(|&x| bumps(x)).collect();
    let mut v: Vec<f64> = nodes.iter().map(|&x| (x * 0.11).cos()).collect();
    spectral_leapfrog(&mut u, &mut v, many, r, 1.0, dt, 5);
    let worst = (long.u().unwrap().iter().zip(&u))
        .map(|(a, b)| (a[0] - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-13, "across blocks: {worst:e}");
    // Moving as a whole at unit speed, the field's energy is ½ ρ L.
    let mut whole = Field::new(SineGordon, (0.0, length), cells, Boundary::Periodic, dt)
        .unwrap()
        .with_degree(r)
        .unwrap();
    whole.start(&at(&x, |_| 0.0), &at(&x, |_| 1.0)).unwrap();
    assert!((whole.energy().unwrap() - 0.5 * length).abs() < 1e-12);
}

/// Cells of degree 4 with free ends: a sine-Gordon pulse over 4 000 steps keeps its energy
/// error in a band, split across threads the steps are the same bit for bit, masses at the ends
/// join the ends' points whatever the order of the calls, and degrees 0 and past the last are
/// refused, as are more cells than can be counted or held.
#[test]
fn lobatto_cells_keep_energy_and_refuse_what_they_cannot_be() {
    let pulse = || {
        let mut pulse = Field::new(SineGordon, (-16.0, 16.0), 16, Boundary::Free, 0.02)
            .unwrap()
            .with_degree(4)
            .unwrap();
        let x = pulse.positions();
        pulse
            .start(&at(&x, |_| 0.0), &at(&x, |x| 2.0 / x.cosh()))
            .unwrap();
        pulse
    };
    let mut field = pulse();
    let mut energy = vec![field.energy().unwrap()];
    for _ in 0..400 {
        field.run(10).unwrap();
        energy.push(field.energy().unwrap());
    }
    let (first, last) = energy_error_first_and_last_tenth(&energy);
    println!("degree 4 energy error: first tenth {first:.2e}, last tenth {last:.2e}");
    assert!(
        first > 1e-9 && last < 1.5 * first,
        "{first:e} then {last:e}"
    );

    let runs = [false, true].map(|parallel| {
        let mut kinks = Field::new(SineGordon, (-100.0, 100.0), 6_000, Boundary::Free, 0.002)
            .unwrap()
            .with_degree(3)
            .unwrap()
            .with_parallel(parallel);
        let x = kinks.positions();
        kinks
            .start(
                &at(&x, |x| field::kink(0.5, 0.0, x).0),
                &at(&x, |x| field::kink(0.5, 0.0, x).1),
            )
            .unwrap();
        kinks.run(5).unwrap();
        kinks
    });
    assert_eq!(runs[0].u().unwrap(), runs[1].u().unwrap());

    let heavy = |first_masses: bool| {
        let field = Field::new(WAVE, (0.0, 1.0), 4, Boundary::Free, 0.001).unwrap();
        let mut field = match first_masses {
            true => field
                .with_end_masses(2.0, 3.0)
                .unwrap()
                .with_degree(3)
                .unwrap(),
            false => field
                .with_degree(3)
                .unwrap()
                .with_end_masses(2.0, 3.0)
                .unwrap(),
        };
        let n = field.nodes();
        field
            .start(&vec![SVector::zeros(); n], &vec![SVector::from([1.0]); n])
            .unwrap();
        let p = field.momenta().unwrap();
        // The end points' masses: their share of a cell of degree 3, Δx/12, and the mass.
        let ends = [p[0][0] - 0.25 / 12.0, p[n - 1][0] - 0.25 / 12.0];
        assert!(
            (ends[0] - 2.0).abs() < 1e-15 && (ends[1] - 3.0).abs() < 1e-15,
            "{ends:?}"
        );
        field.energy().unwrap()
    };
    // ½ (1 + 2 + 3) · 1²: the string and its two masses.
    assert!((heavy(true) - 3.0).abs() < 1e-14 && (heavy(false) - 3.0).abs() < 1e-14);
    let string = || Field::new(WAVE, (0.0, 1.0), 4, Boundary::Fixed, 0.001).unwrap();
    assert!(matches!(
        string().with_degree(0),
        Err(DiracError::Unsupported(_))
    ));
    let past = dirac::field::MOST_DEGREE + 1;
    assert!(matches!(
        string().with_degree(past),
        Err(DiracError::Unsupported(_))
    ));
    // More nodes than can be counted, or held.
    for (cells, what) in [(usize::MAX, "counted"), (usize::MAX / 2, "memory")] {
        let huge = Field::new(WAVE, (0.0, 1.0), cells, Boundary::Fixed, 0.001);
        assert!(
            matches!(&huge, Err(DiracError::Dimension(why)) if why.contains(what)),
            "{huge:?}"
        );
    }
}

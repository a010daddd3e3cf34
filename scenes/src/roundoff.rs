//! Brouwer's law on Kepler's problem (e = 0.5): where the method's own energy error is far below
//! round-off, what is left of the energy error in a long run is round-off, and with compensated
//! sums it should grow like a random walk, `√t`, not like `t`.
//!
//! The energy error of one run is one walk; the law is a statement about their spread. An
//! ensemble of runs whose starts differ only by a rotation of the orbit (the same energy and
//! the same exact motion, turned; different roundings) gives the root mean square of `E − E_0`
//! at checkpoints spaced evenly in `log t`, and a least-squares line through
//! `(log t, log rms)` its exponent.

use dirac::nalgebra::Matrix2;
use dirac::prelude::*;
use dirac::{StepEquations, Vectors};
use rayon::prelude::*;

use super::{hamiltonian, kepler};

/// Kepler's start turned by `angle` about the origin: the same orbit, rotated.
pub fn turned_start(angle: f64) -> (SVector<f64, 2>, SVector<f64, 2>) {
    let turn = Matrix2::new(angle.cos(), -angle.sin(), angle.sin(), angle.cos());
    (turn * kepler::q0(), turn * kepler::p0())
}

/// Step counts spaced evenly in `log n`, `per_decade` to a decade, from `first` to `last`.
pub fn checkpoints(first: u64, last: u64, per_decade: u32) -> Vec<u64> {
    let (a, b) = ((first as f64).log10(), (last as f64).log10());
    let count = ((b - a) * f64::from(per_decade)).round() as u32;
    let mut steps: Vec<u64> = (0..=count)
        .map(|k| 10f64.powf(a + (b - a) * f64::from(k) / f64::from(count.max(1))))
        .map(|n| n.round() as u64)
        .collect();
    steps.dedup();
    steps
}

/// A method whose round-off the ensembles measure on Kepler's problem.
#[derive(Clone, Debug)]
pub enum Method {
    /// An explicit composition of Störmer–Verlet steps.
    Explicit(Composition),
    /// The implicit step of a quadrature on the Lagrangian route, solved by Newton's method.
    Lagrangian(Quadrature),
    /// The same step solved by fixed-point iteration ([`Stepper::with_fixed_point`]).
    FixedPoint(Quadrature),
    /// The implicit step of a quadrature on the discrete Hamiltonian route (Kepler's `H(q, p)`).
    Hamiltonian(Quadrature),
}

impl Method {
    /// The method's name, as the ensembles report it.
    pub fn name(&self) -> String {
        match self {
            Method::Explicit(composition) => format!("explicit {}", composition.name()),
            Method::Lagrangian(quadrature) => format!("implicit Gauss {}", quadrature.name()),
            Method::FixedPoint(quadrature) => {
                format!("implicit Gauss {}, fixed point", quadrature.name())
            }
            Method::Hamiltonian(quadrature) => {
                format!("implicit Gauss {}, Hamiltonian route", quadrature.name())
            }
        }
    }
}

/// The root mean square of `E(t_n) − E(0)` at the step counts `at` over `runs` runs of
/// `method` with step `h` from turned starts (angles spread over the circle), run in parallel:
/// `(t_n, rms)` pairs.
///
/// The runs are long (10⁵ to 10⁸ steps), so they are compiled here, once, at the scenes'
/// optimisation level: the tests that call this are built unoptimised.
pub fn rms_energy_error(
    method: &Method,
    h: f64,
    runs: usize,
    at: &[u64],
) -> Result<Vec<(f64, f64)>, DiracError> {
    match method {
        Method::Explicit(composition) => ensemble(
            || Stepper::explicit(kepler::SCENE, composition.clone(), h),
            runs,
            at,
        ),
        Method::Lagrangian(quadrature) => ensemble(
            || Stepper::new(kepler::SCENE, quadrature.clone(), h),
            runs,
            at,
        ),
        Method::FixedPoint(quadrature) => ensemble(
            || Stepper::new(kepler::SCENE, quadrature.clone(), h)?.with_fixed_point(),
            runs,
            at,
        ),
        Method::Hamiltonian(quadrature) => ensemble(
            || Stepper::hamiltonian(hamiltonian::Kepler { mu: 1.0 }, quadrature.clone(), h),
            runs,
            at,
        ),
    }
}

/// `rms_energy_error` of the steppers `stepper` builds, each started from its turned start.
fn ensemble<E, F>(stepper: F, runs: usize, at: &[u64]) -> Result<Vec<(f64, f64)>, DiracError>
where
    E: StepEquations<2, Manifold = Vectors> + Send,
    F: Fn() -> Result<Stepper<E::System, 2, E>, DiracError> + Sync,
{
    let walks: Vec<Vec<f64>> = (0..runs)
        .into_par_iter()
        .map(|run| {
            // Turns of an irrational fraction of the circle: no two starts alike.
            let angle = std::f64::consts::TAU * (run as f64 * 0.618_033_988_749_895).fract();
            let (q0, p0) = turned_start(angle);
            let mut stepper = stepper()?;
            stepper.start_from_momentum(q0, p0)?;
            let e0 = stepper.energy()?;
            let mut errors = Vec::with_capacity(at.len());
            for &n in at {
                while stepper.steps() < n {
                    stepper.step()?;
                }
                errors.push(stepper.energy()? - e0);
            }
            Ok(errors)
        })
        .collect::<Result<_, DiracError>>()?;
    let h = stepper()?.h();
    Ok(at
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let mean_square = walks.iter().map(|w| w[k] * w[k]).sum::<f64>() / runs as f64;
            (n as f64 * h, mean_square.sqrt())
        })
        .collect())
}

/// The slope of the least-squares line through `(log t, log e)`: the exponent `α` of `e ∝ t^α`.
pub fn exponent(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, e)| *e > 0.0)
        .map(|&(t, e)| (t.ln(), e.ln()))
        .collect();
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

//! The integrators users would otherwise pick, on a scene's first-order form (`first_order.rs`),
//! measured as dirac's `Study` measures its own runs: the error at the horizon against a
//! reference, the largest energy error over every accepted step, and the wall time per unit of
//! simulated time of a run that watches nothing (the fastest of `repetitions`).
//!
//! Two differences in the timing count against the peers: ode_solvers' runs store every accepted
//! step (sparse output: the only way its `solout` sees each step's state), and BDF's include
//! building the problem and the solver; dirac's exclude building and starting the stepper.
//!
//! Peers: `Dop853` and `Dopri5` (explicit Runge–Kutta of orders 8 and 5, ode_solvers) and `Bdf`
//! (variable-order BDF with a dense LU, diffsol; its Jacobian-vector products by dual numbers),
//! each with `rtol = atol = tolerance`.
//!
//! BDF is built only with this crate's `bdf` feature (`--features scenes/bdf` from the
//! workspace root): diffsol's linear algebra (faer) would otherwise be a third of the tests'
//! build. Without it, [`Peer::Bdf`] is refused with an `Err` that says so, and
//! [`Peer::is_built`] tells the study to leave it out.

use std::cell::RefCell;
use std::time::Instant;

use dirac::Sample;
use ode_solvers::System;

use super::first_order::FirstOrder;

/// An integrator of the study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Peer {
    Dop853,
    Dopri5,
    Bdf,
}

impl Peer {
    pub fn name(self) -> &'static str {
        match self {
            Peer::Dop853 => "Dop853",
            Peer::Dopri5 => "Dopri5",
            Peer::Bdf => "BDF",
        }
    }

    /// Whether this build has the peer: BDF needs the `bdf` feature.
    pub fn is_built(self) -> bool {
        self != Peer::Bdf || cfg!(feature = "bdf")
    }
}

/// One run of a peer.
#[derive(Debug, Clone)]
pub struct PeerRun {
    pub peer: Peer,
    pub tolerance: f64,
    /// Accepted steps.
    pub steps: u64,
    /// `max(|q(T) − q_ref(T)|, |p(T) − p_ref(T)|)` (∞-norms), as dirac's `Measurement::error`.
    pub error: f64,
    /// `max_k |E_k − E_0|` over every accepted step.
    pub energy_error: f64,
    /// The largest constraint violation of an accepted step.
    pub violation: f64,
    pub seconds_per_unit_time: f64,
}

/// What a monitored run tracks at every accepted step.
#[derive(Debug, Clone, Copy)]
struct Monitor {
    energy0: f64,
    energy_error: f64,
    violation: f64,
}

impl Monitor {
    fn see<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(&mut self, ode: &F, y: &[f64; Y]) {
        self.energy_error = self.energy_error.max((ode.energy(y) - self.energy0).abs());
        self.violation = self.violation.max(ode.violation(y));
    }
}

/// A form as ode_solvers' `System`, watching every accepted step when `monitor` is given.
struct Explicit<'a, F, const Y: usize, const N: usize> {
    ode: &'a F,
    monitor: Option<&'a RefCell<Monitor>>,
}

fn array<const Y: usize>(y: &ode_solvers::SVector<f64, Y>) -> [f64; Y] {
    std::array::from_fn(|i| y[i])
}

impl<F: FirstOrder<Y, N>, const Y: usize, const N: usize> System<f64, ode_solvers::SVector<f64, Y>>
    for Explicit<'_, F, Y, N>
{
    fn system(
        &self,
        _t: f64,
        y: &ode_solvers::SVector<f64, Y>,
        dy: &mut ode_solvers::SVector<f64, Y>,
    ) {
        let f = self.ode.rhs(&array(y));
        for (d, f) in dy.iter_mut().zip(f) {
            *d = f;
        }
    }

    fn solout(
        &mut self,
        _t: f64,
        y: &ode_solvers::SVector<f64, Y>,
        _dy: &ode_solvers::SVector<f64, Y>,
    ) -> bool {
        if let Some(monitor) = self.monitor {
            monitor.borrow_mut().see(self.ode, &array(y));
        }
        false
    }
}

/// No step limit: a long horizon at a tight tolerance takes millions of steps.
pub(crate) const MAX_STEPS: u32 = u32::MAX;

/// ode_solvers' `Dop853` or `Dopri5` (`peer`) on `system` from `y0` over `[0, horizon]` at
/// relative and absolute `tolerance`: `Ok((end state, accepted steps))`, or `Err` with why. Each
/// with the crate's default controller (safety, beta, fac_min, fac_max), no step limit, `h_max`
/// the whole span, and sparse output: every accepted step is stored, and `solout` sees it (with
/// dense output it would see the last interpolated point instead; and its interpolant at a few
/// points off the steps ended 1e-3 away from the solution of a field's stiff semi-discrete
/// equations). A macro because the solvers are generic over the state's dimension with bounds
/// of ode_solvers' own nalgebra.
macro_rules! adaptive {
    (@run $solver:ident, $beta:expr, $fac_min:expr, $fac_max:expr,
     $system:expr, $y0:expr, $horizon:expr, $tolerance:expr) => {{
        let mut solver = ode_solvers::$solver::from_param(
            $system,
            0.0,
            $horizon,
            0.0,
            $y0,
            $tolerance,
            $tolerance,
            0.9,
            $beta,
            $fac_min,
            $fac_max,
            $horizon,
            0.0,
            $crate::peers::MAX_STEPS,
            1000,
            ode_solvers::OutputType::Sparse,
        );
        match solver.integrate() {
            Ok(stats) => solver
                .y_out()
                .last()
                .cloned()
                .map(|end| (end, stats.accepted_steps as u64))
                .ok_or_else(|| format!("{}: no output", stringify!($solver))),
            Err(e) => Err(format!("{}: {e}", stringify!($solver))),
        }
    }};
    ($peer:expr, $system:expr, $y0:expr, $horizon:expr, $tolerance:expr) => {
        match $peer {
            $crate::peers::Peer::Dop853 => {
                adaptive!(@run Dop853, 0.0, 0.333, 6.0, $system, $y0, $horizon, $tolerance)
            }
            $crate::peers::Peer::Dopri5 => {
                adaptive!(@run Dopri5, 0.04, 0.2, 10.0, $system, $y0, $horizon, $tolerance)
            }
            $crate::peers::Peer::Bdf => Err::<_, String>(
                "BDF is not an explicit Runge–Kutta method: it is run apart".to_string(),
            ),
        }
    };
}
pub(crate) use adaptive;

/// Runs `peer` on `ode` from its initial state to `horizon`: the end state and the accepted
/// steps.
fn integrate<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(
    peer: Peer,
    ode: &F,
    horizon: f64,
    tolerance: f64,
    monitor: Option<&RefCell<Monitor>>,
) -> Result<([f64; Y], u64), String> {
    if peer != Peer::Bdf && F::DIFFERENTIAL != Y {
        return Err(format!("{} takes no algebraic rows", peer.name()));
    }
    let y0 = ode_solvers::SVector::<f64, Y>::from(ode.initial());
    let system = Explicit { ode, monitor };
    let (y_out, steps) = match peer {
        Peer::Bdf => return bdf(ode, horizon, tolerance, monitor),
        peer => adaptive!(peer, system, y0, horizon, tolerance)?,
    };
    Ok((array(&y_out), steps))
}

/// The end state of Dop853 on `system` from `y0` over `[0, t_end]` at relative and absolute
/// tolerance `tolerance` (sparse output, the crate's default controller, no step limit): the
/// references of scenes whose ODE is written directly (rigid bodies, the sphere).
pub fn dop853_end<S: System<f64, ode_solvers::SVector<f64, Y>>, const Y: usize>(
    system: S,
    y0: ode_solvers::SVector<f64, Y>,
    t_end: f64,
    tolerance: f64,
) -> Result<ode_solvers::SVector<f64, Y>, String> {
    adaptive!(Peer::Dop853, system, y0, t_end, tolerance).map(|(end, _)| end)
}

/// Without the `bdf` feature: a refusal that names it.
#[cfg(not(feature = "bdf"))]
fn bdf<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(
    _ode: &F,
    _horizon: f64,
    _tolerance: f64,
    _monitor: Option<&RefCell<Monitor>>,
) -> Result<([f64; Y], u64), String> {
    Err(
        "BDF is not built: enable the `bdf` feature of dirac-scenes (`--features scenes/bdf`)"
            .into(),
    )
}

/// diffsol's BDF on `ode`, its algebraic rows given a zero row of the mass matrix. It stops at
/// the stop time to within diffsol's 100 ε (|t| + |h|), and that state is taken as the end.
/// The index-1 forms hold a constraint only in its differentiated form, so it may drift.
#[cfg(feature = "bdf")]
fn bdf<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(
    ode: &F,
    horizon: f64,
    tolerance: f64,
    monitor: Option<&RefCell<Monitor>>,
) -> Result<([f64; Y], u64), String> {
    use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason};
    use dirac::num_dual::Dual64;
    let failed = |e: diffsol::error::DiffsolError| format!("BDF: {e}");
    let initial = ode.initial();
    let problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .rtol(tolerance)
        .atol([tolerance])
        .rhs_implicit(
            |x: &[f64], _p: &[f64], _t: f64, y: &mut [f64]| {
                let f = ode.rhs::<f64>(&std::array::from_fn(|i| x[i]));
                y.copy_from_slice(&f);
            },
            |x: &[f64], _p: &[f64], _t: f64, v: &[f64], y: &mut [f64]| {
                let seeded: [Dual64; Y] = std::array::from_fn(|i| Dual64::new(x[i], v[i]));
                for (y, f) in y.iter_mut().zip(ode.rhs(&seeded)) {
                    *y = f.eps;
                }
            },
        )
        .mass(|v: &[f64], _p: &[f64], _t: f64, beta: f64, y: &mut [f64]| {
            for i in 0..Y {
                let mv = if i < F::DIFFERENTIAL { v[i] } else { 0.0 };
                y[i] = mv + beta * y[i];
            }
        })
        .init(
            move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&initial),
            Y,
        )
        .build()
        .map_err(failed)?;
    let mut solver = problem.bdf::<NalgebraLU<f64>>().map_err(failed)?;
    solver.set_stop_time(horizon).map_err(failed)?;
    loop {
        let reason = solver.step().map_err(failed)?;
        if let Some(monitor) = monitor {
            let y = solver.state().y;
            monitor
                .borrow_mut()
                .see(ode, &std::array::from_fn(|i| y[i]));
        }
        if let OdeSolverStopReason::TstopReached = reason {
            break;
        }
    }
    let y = solver.state().y;
    let steps = solver.get_statistics().number_of_steps as u64;
    Ok((std::array::from_fn(|i| y[i]), steps))
}

/// The state at `horizon` by Dop853 at `tolerance`, as a dirac `Sample`.
pub fn solution<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(
    ode: &F,
    horizon: f64,
    tolerance: f64,
) -> Result<Sample<N>, String> {
    let (y, _) = integrate(Peer::Dop853, ode, horizon, tolerance, None)?;
    Ok(ode.sample(horizon, &y))
}

/// The reference at `horizon` and its error estimate: the closed form where the scene has one
/// (estimate 0), else Dop853 at `rtol = atol = 1e-13` with its difference from the run at 1e-12.
pub fn reference<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(
    ode: &F,
    horizon: f64,
) -> Result<(Sample<N>, f64), String> {
    if let Some(exact) = ode.exact(horizon) {
        return Ok((ode.sample(horizon, &exact), 0.0));
    }
    let fine = solution(ode, horizon, 1e-13)?;
    let coarse = solution(ode, horizon, 1e-12)?;
    Ok((fine, distance(&fine, &coarse)))
}

/// `max(|Δq|, |Δp|)` (∞-norms), the study's error.
pub fn distance<const N: usize>(a: &Sample<N>, b: &Sample<N>) -> f64 {
    (a.q - b.q).amax().max((a.p - b.p).amax())
}

/// Measures `peer` on `ode` to `horizon` at `tolerance` against `reference`.
pub fn measure<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(
    peer: Peer,
    ode: &F,
    horizon: f64,
    tolerance: f64,
    reference: &Sample<N>,
    repetitions: usize,
) -> Result<PeerRun, String> {
    let initial = ode.initial();
    let monitor = RefCell::new(Monitor {
        energy0: ode.energy(&initial),
        energy_error: 0.0,
        violation: ode.violation(&initial),
    });
    let (end, steps) = integrate(peer, ode, horizon, tolerance, Some(&monitor))?;
    let error = distance(&ode.sample(horizon, &end), reference);
    let mut fastest = f64::INFINITY;
    for _ in 0..repetitions.max(1) {
        let clock = Instant::now();
        integrate(peer, ode, horizon, tolerance, None)?;
        fastest = fastest.min(clock.elapsed().as_secs_f64());
    }
    let Monitor {
        energy_error,
        violation,
        ..
    } = monitor.into_inner();
    Ok(PeerRun {
        peer,
        tolerance,
        steps,
        error,
        energy_error,
        violation,
        seconds_per_unit_time: fastest / horizon,
    })
}

//! The seven scenes of the speed/accuracy study, each as a dirac model and as the first-order
//! form its peers integrate (and, for the circuit and the knife edge, the index-1 DAE that BDF
//! takes), with the steps dirac's quadratures are measured at. dirac starts from the form's
//! initial state, so both sides solve the same problem.

use dirac::plot::{Series, line_chart};
use dirac::work_precision::Study;
use dirac::{DiracSystem, Quadrature};

use super::chain;
use super::circuit;
use super::double_pendulum::DoublePendulum;
use super::first_order::{
    ChainOde, DoublePendulumOde, FirstOrder, KeplerOde, KnifeEdgeDae, KnifeEdgeOde, LcDae, LcOde,
    PendulumOde,
};
use super::kepler;
use super::knife_edge;
use super::peers::{self, Peer};
use super::pendulum;

/// One scene: the dirac model, its first-order form for the explicit peers, an optional DAE form
/// for BDF, and dirac's steps.
pub struct Scene<S, F, G, const Y: usize, const Z: usize, const N: usize> {
    pub name: &'static str,
    pub system: S,
    pub ode: F,
    pub dae: Option<G>,
    /// The quadratures and steps at a short horizon (T = 10).
    pub quadratures: Vec<Quadrature>,
    pub steps: Vec<f64>,
    /// The quadratures and steps at a long horizon (T = 10⁴), where a step costs 10³ times more.
    pub long: (Vec<Quadrature>, Vec<f64>),
    /// The fictive steps of the time-transformed compositions (`dt/ds = −1/V(q)`), for a
    /// potential negative along the motion; none for the other scenes.
    pub fictive_steps: Vec<f64>,
}

/// Something done with every scene (the study, a test).
pub trait Visitor {
    fn visit<S, F, G, const Y: usize, const Z: usize, const N: usize>(
        &mut self,
        scene: Scene<S, F, G, Y, Z, N>,
    ) -> Result<(), String>
    where
        S: DiracSystem<N> + Clone,
        F: FirstOrder<Y, N>,
        G: FirstOrder<Z, N>;
}

/// The double pendulum of the study: m = l = 1, g = 9.81, both links horizontal at rest.
pub const DOUBLE_PENDULUM: DoublePendulum = DoublePendulum {
    m1: 1.0,
    m2: 1.0,
    l1: 1.0,
    l2: 1.0,
    g: 9.81,
};

/// The pendulum of the tour (q̈ = −sin q) released from q = 1.
pub fn pendulum() -> Scene<pendulum::Pendulum, PendulumOde, PendulumOde, 2, 2, 1> {
    Scene {
        name: "pendulum",
        system: pendulum::SCENE,
        ode: PendulumOde {
            pendulum: pendulum::SCENE,
            theta0: 1.0,
        },
        dae: None,
        // Separable: the Gauss steps by fixed-point iteration cost a gradient per node and
        // iteration, so the grid reaches to degree 8 (order 16) and steps of 1.
        quadratures: gauss_to_eight(),
        steps: vec![1.0, 0.5, 0.2, 0.1, 0.05, 0.025],
        long: (gauss_to_eight(), vec![1.0, 0.5, 0.2, 0.1, 0.05, 0.025]),
        fictive_steps: Vec::new(),
    }
}

/// Visits the seven scenes in order.
pub fn visit_all(visitor: &mut impl Visitor) -> Result<(), String> {
    let half_pi = std::f64::consts::FRAC_PI_2;
    visitor.visit(pendulum())?;
    visitor.visit(Scene::<_, _, DoublePendulumOde, 4, 4, 2> {
        name: "double pendulum",
        system: DOUBLE_PENDULUM,
        ode: DoublePendulumOde {
            pendulum: DOUBLE_PENDULUM,
            theta0: [half_pi, half_pi],
        },
        dae: None,
        quadratures: (1..=6)
            .filter_map(|s| Quadrature::galerkin(s).ok())
            .collect(),
        steps: vec![0.05, 0.02, 0.01, 0.005],
        long: (every_quadrature(), vec![0.02, 0.01, 0.005]),
        fictive_steps: Vec::new(),
    })?;
    for (name, e, steps) in [
        ("Kepler e = 0.5", 0.5, vec![0.04, 0.02, 0.01, 0.005]),
        ("Kepler e = 0.9", 0.9, vec![0.01, 0.005, 0.0025]),
    ] {
        visitor.visit(Scene::<_, _, KeplerOde, 4, 4, 2> {
            name,
            system: kepler::SCENE,
            ode: KeplerOde {
                kepler: kepler::SCENE,
                e,
            },
            dae: None,
            quadratures: every_quadrature(),
            long: (every_quadrature(), steps.clone()),
            steps,
            // A revolution is 2π of the fictive time: 16 to 128 steps a revolution.
            fictive_steps: vec![0.4, 0.2, 0.1, 0.05],
        })?;
    }
    visitor.visit(Scene::<_, _, ChainOde<8>, 16, 16, 8> {
        name: "chain (8 links)",
        system: chain::SCENE8,
        ode: ChainOde::<8> {
            chain: chain::SCENE8,
            theta0: chain::initial::<8>().into(),
        },
        dae: None,
        quadratures: every_quadrature(),
        steps: vec![0.02, 0.01, 0.005],
        // 200 µs per galerkin(3) step: 10⁶ steps at T = 10⁴ take minutes.
        long: (
            vec![
                Quadrature::galerkin(2).unwrap(),
                Quadrature::galerkin(3).unwrap(),
            ],
            vec![0.02],
        ),
        fictive_steps: Vec::new(),
    })?;
    let lc = LcOde {
        circuit: circuit::LC,
        q0: circuit::q0().into(),
    };
    visitor.visit(Scene::<_, _, _, 5, 5, 4> {
        name: "LC circuit",
        system: circuit::LC,
        ode: lc,
        dae: Some(LcDae(lc)),
        quadratures: every_quadrature(),
        // Linear: by their step maps the Gauss–Galerkin steps cost a product of a matrix and
        // the state whatever their degree, so the study reaches to degree 5 and long steps.
        steps: vec![0.4, 0.2, 0.1, 0.05],
        long: (
            (1..=5)
                .filter_map(|s| Quadrature::galerkin(s).ok())
                .collect(),
            vec![0.4, 0.2, 0.1, 0.05],
        ),
        fictive_steps: Vec::new(),
    })?;
    let knife = KnifeEdgeOde {
        knife: knife_edge::SCENE,
        omega: knife_edge::OMEGA,
    };
    visitor.visit(Scene::<_, _, _, 6, 7, 3> {
        name: "knife edge",
        system: knife_edge::SCENE,
        ode: knife,
        dae: Some(KnifeEdgeDae(knife)),
        quadratures: every_quadrature(),
        steps: vec![0.1, 0.05, 0.025, 0.0125],
        long: (every_quadrature(), vec![0.1, 0.05, 0.025, 0.0125]),
        fictive_steps: Vec::new(),
    })
}

/// `midpoint`, `galerkin(2)`, `galerkin(3)`, `galerkin(4)`, `galerkin(6)` and `galerkin(8)`.
pub fn gauss_to_eight() -> Vec<Quadrature> {
    [1, 2, 3, 4, 6, 8]
        .into_iter()
        .filter_map(|s| Quadrature::galerkin(s).ok())
        .collect()
}

/// `midpoint`, `galerkin(2)` and `galerkin(3)`.
pub fn every_quadrature() -> Vec<Quadrature> {
    (1..=3)
        .filter_map(|s| Quadrature::galerkin(s).ok())
        .collect()
}

/// One run of the study, dirac's or a peer's.
#[derive(Debug, Clone)]
pub struct Row {
    pub scene: &'static str,
    pub horizon: f64,
    pub method: String,
    /// `h = …` for dirac, `tol = …` for a peer.
    pub setting: String,
    pub steps: u64,
    pub error: f64,
    pub energy_error: f64,
    pub violation: f64,
    /// dirac's steps by fixed-point iteration handed to Newton's method (0 for a peer).
    pub handed_over: u64,
    pub seconds_per_unit_time: f64,
}

impl Row {
    pub fn is_dirac(&self) -> bool {
        self.setting.starts_with('h')
    }
}

/// Above this horizon a scene runs its `long` grid, each run timed once, and the peers skip
/// their most expensive settings.
const LONG: f64 = 100.0;

/// Runs `scene` to `horizon`: dirac's grid and every peer that takes the scene, against a
/// reference by Dop853 at 1e-13. The rows, the reference's error estimate and the runs that
/// could not be measured (with why).
pub fn measure<S, F, G, const Y: usize, const Z: usize, const N: usize>(
    scene: &Scene<S, F, G, Y, Z, N>,
    horizon: f64,
) -> Result<(Vec<Row>, f64, Vec<String>), String>
where
    S: DiracSystem<N> + Clone,
    F: FirstOrder<Y, N>,
    G: FirstOrder<Z, N>,
{
    let long = horizon > LONG;
    let repetitions = if long { 1 } else { 3 };
    let (reference, estimate) = peers::reference(&scene.ode, horizon)?;
    let start = scene.ode.sample(0.0, &scene.ode.initial());
    let (quadratures, steps) = if long {
        scene.long.clone()
    } else {
        (scene.quadratures.clone(), scene.steps.clone())
    };
    let mut study = Study::new(scene.system.clone(), horizon, |s| {
        s.start_from_velocity(start.q, start.v)
    })
    .quadratures(quadratures)
    .steps(steps)
    .repetitions(repetitions)
    .reference_with_error(reference, estimate);
    if !scene.fictive_steps.is_empty() {
        study = study.time_transformed(0.0, scene.fictive_steps.clone());
    }
    let dirac = study.run().map_err(|e| e.to_string())?;
    let mut failures: Vec<String> = dirac
        .failures
        .iter()
        .map(|f| format!("{} h = {}: {}", f.quadrature, f.h, f.error))
        .collect();
    let mut rows: Vec<Row> = dirac
        .measurements
        .iter()
        .map(|m| Row {
            scene: scene.name,
            horizon,
            method: m.quadrature.clone(),
            setting: format!("h = {}", m.h),
            steps: m.steps,
            error: m.error,
            energy_error: m.energy_error,
            violation: m.constraint_violation,
            handed_over: m.handed_over,
            seconds_per_unit_time: m.seconds_per_unit_time,
        })
        .collect();
    let tolerances: &[f64] = if long {
        &[1e-6, 1e-8, 1e-10, 1e-12]
    } else {
        &[1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
    };
    let mut runs = Vec::new();
    for peer in [Peer::Dop853, Peer::Dopri5] {
        // Dopri5 at 1e-12 takes 10⁷ steps to T = 10⁴.
        let tight = if long && peer == Peer::Dopri5 {
            1e-10
        } else {
            0.0
        };
        for &tolerance in tolerances.iter().filter(|&&t| t >= tight) {
            let run = peers::measure(
                peer,
                &scene.ode,
                horizon,
                tolerance,
                &reference,
                repetitions,
            );
            runs.push((tolerance, run));
        }
    }
    // BDF only where this build has it (the `bdf` feature).
    if let Some(dae) = scene.dae.as_ref().filter(|_| Peer::Bdf.is_built()) {
        // BDF is of order ≤ 5: 1e-12 costs it 10⁶ steps per unit of time.
        for &tolerance in tolerances.iter().filter(|&&t| t >= 1e-10) {
            let run = peers::measure(Peer::Bdf, dae, horizon, tolerance, &reference, repetitions);
            runs.push((tolerance, run));
        }
    }
    for (tolerance, run) in runs {
        match run {
            Ok(run) => rows.push(Row {
                scene: scene.name,
                horizon,
                method: run.peer.name().to_string(),
                setting: format!("tol = {tolerance:e}"),
                steps: run.steps,
                error: run.error,
                energy_error: run.energy_error,
                violation: run.violation,
                handed_over: 0,
                seconds_per_unit_time: run.seconds_per_unit_time,
            }),
            Err(why) => failures.push(format!("tol = {tolerance:e}: {why}")),
        }
    }
    Ok((rows, estimate, failures))
}

/// Draws `value` of `rows` (log₁₀) against their cost (log₁₀ wall seconds per unit of simulated
/// time), one line per method, to the PNG file `path`.
pub fn draw(
    path: &str,
    title: &str,
    label: &str,
    rows: &[&Row],
    value: fn(&Row) -> f64,
) -> Result<(), String> {
    let series = Series::by_label(rows.iter().map(|r| {
        let point = (r.seconds_per_unit_time.log10(), value(r).log10());
        (&r.method, point)
    }));
    let axes = (
        "log10 wall seconds per unit of simulated time",
        &*format!("log10 {label}"),
    );
    line_chart(path, title, axes, &series).map_err(|e| e.to_string())
}

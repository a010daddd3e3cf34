//! The tour's pictures: orders of convergence, energy errors over time, the knife edge's paths
//! under the three discrete constraints, the LC circuit against its closed form, and the
//! cart-pole balanced by LQR on the step map's derivatives, the pendulum's energy error against
//! cost to T = 10⁴ beside the explicit Runge–Kutta and BDF peers, the heavy top's nutation, its
//! energy error and vertical momentum over 10⁶ steps, a chain of two rigid bodies in space, and
//! a humanoid-like tree of bodies on ball joints tumbling free, and a drum struck off its centre.

use std::error::Error;

use dirac::prelude::*;

use super::{
    cart_pole, circuit, double_pendulum, knife_edge, mechanism, membrane, pendulum, rigid_body,
    rigid_chain, study,
};
use dirac::plot::{Series, SpaceSeries, line_chart, space_chart, space_time_chart};

/// Writes every figure to `output/` and returns their paths.
pub fn draw_all() -> Result<Vec<&'static str>, Box<dyn Error>> {
    Ok(vec![
        convergence()?,
        energy()?,
        knife_edge_paths()?,
        lc_circuit()?,
        cart_pole_lqr()?,
        long_horizon()?,
        heavy_top_nutation()?,
        heavy_top_invariants()?,
        chain_in_space()?,
        humanoid_in_space()?,
        struck_drum()?,
    ])
}

/// The drum `[0, 1.5] × [0, 1]` (edges fixed, 120 × 80 cells) struck at `(0.5, 0.5)`, at
/// `t = 0.6`: the ring of the strike and its reflections from the nearer edges.
pub fn struck_drum() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/membrane.png";
    let t = 0.6;
    let ([x, y], u) = membrane::struck(t)?;
    let rows: Vec<(f64, Vec<f64>)> = (y.iter().enumerate())
        .map(|(j, &y)| (y, u[j * x.len()..(j + 1) * x.len()].to_vec()))
        .collect();
    let title = format!("A drum struck at (0.5, 0.5), u at t = {t}");
    space_time_chart(path, &title, ("x", "y"), &x, &rows)?;
    Ok(path)
}

/// The free humanoid (nine bodies on eight ball joints, no gravity) over 2 s (midpoint, Cayley,
/// h = 0.005): its skeleton at the start and at the end, and the paths of its left hand and of
/// its centre of mass, which moves on a line (its momentum is kept).
pub fn humanoid_in_space() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/humanoid.png";
    let frames = mechanism::humanoid_motion(0.005, 400, 4)?;
    let (first, last) = (&frames[0], &frames[frames.len() - 1]);
    let trail = |label: &str, point: fn(&mechanism::Skeleton) -> [f64; 3]| SpaceSeries {
        label: label.into(),
        points: frames.iter().map(point).collect(),
    };
    let skeleton = |label: String, frame: &mechanism::Skeleton| SpaceSeries {
        label,
        points: frame.1.clone(),
    };
    space_chart(
        path,
        "A humanoid of nine bodies on ball joints, tumbling free for 2 s",
        &[
            skeleton("at t = 0".into(), first),
            skeleton(format!("at t = {:.0}", last.0), last),
            trail("its left hand", |f| f.2),
            trail("its centre of mass", |f| f.3),
        ],
    )?;
    Ok(path)
}

/// The heavy top's symmetry axis `R e₃` seen from above over 4 s (midpoint, Cayley,
/// h = 0.001): it precesses about the vertical while nutating in loops.
pub fn heavy_top_nutation() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/heavy_top.png";
    let axis = rigid_body::top_axis(Product::cayley(), 0.001, 4000, 5)?;
    line_chart(
        path,
        "Heavy top: the tip of its axis seen from above (precession with nutation)",
        ("x", "y"),
        &[Series {
            label: "R e₃ (midpoint, Cayley, h = 0.001)".into(),
            points: axis.iter().map(|(_, a)| (a[0], a[1])).collect(),
        }],
    )?;
    Ok(path)
}

/// The chain of two rigid bodies in space over 3 s (midpoint, Cayley, h = 0.005): the paths of
/// its joint and of the second body's centre of mass, and the chain (pivot, joint, centre) at
/// the start and at the end.
pub fn chain_in_space() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/rigid_chain.png";
    let points = rigid_chain::points_in_space(Product::cayley(), 0.005, 600, 2)?;
    let path_of = |label: &str, point: fn(&rigid_chain::ChainPoints) -> Vector3<f64>| SpaceSeries {
        label: label.into(),
        points: points.iter().map(|p| point(p).into()).collect(),
    };
    let chain_at = |label: &str, p: &rigid_chain::ChainPoints| SpaceSeries {
        label: label.into(),
        points: vec![[0.0; 3], p.joint.into(), p.centre.into()],
    };
    let (first, last) = (&points[0], &points[points.len() - 1]);
    space_chart(
        path,
        "Two rigid bodies joined by a ball joint, 3 s in space (z up)",
        &[
            path_of("joint R₁ d", |p| p.joint),
            path_of("second body's centre R₁ d + R₂ ρ₂", |p| p.centre),
            chain_at("the chain at t = 0", first),
            chain_at(&format!("the chain at t = {:.0}", last.t), last),
        ],
    )?;
    Ok(path)
}

/// The heavy top over 10⁶ steps of h = 0.01 (T = 10⁴) with both retractions: the energy error
/// stays bounded (no drift) and the vertical angular momentum keeps to round-off, every
/// 1 000 steps on a log scale.
pub fn heavy_top_invariants() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/heavy_top_invariants.png";
    let mut series = Vec::new();
    for space in [Product::cayley(), Product::exp()] {
        let rows = rigid_body::top_invariants(space, 1_000_000)?;
        let retraction = format!("{:?}", space.retraction());
        let energy = |row: &(f64, f64, f64)| row.1;
        let momentum = |row: &(f64, f64, f64)| row.2;
        for (what, value) in [
            ("|E − E0|", &energy as &dyn Fn(_) -> f64),
            ("|ΔL_z|", &momentum),
        ] {
            series.push(Series {
                label: format!("log10 {what}, {retraction}"),
                points: rows
                    .iter()
                    .skip(1)
                    .map(|row| (row.0, value(row).max(1e-18).log10()))
                    .collect(),
            });
        }
    }
    line_chart(
        path,
        "Heavy top, 10⁶ midpoint steps of h = 0.01: energy error and vertical momentum",
        ("t", "log10 error"),
        &series,
    )?;
    Ok(path)
}

/// The pendulum to T = 10⁴: the largest energy error against the wall time per unit of simulated
/// time, dirac's three quadratures beside Dop853 and Dopri5 (the `work_precision` example's
/// measurement, for one scene).
pub fn long_horizon() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/long_horizon_energy.png";
    let (rows, _, _) = study::measure(&study::pendulum(), 1e4)?;
    let rows: Vec<&study::Row> = rows.iter().collect();
    study::draw(
        path,
        "Pendulum to T = 10⁴: largest energy error against cost",
        "largest energy error",
        &rows,
        |r| r.energy_error,
    )?;
    Ok(path)
}

/// The cart-pole from a 0.3 rad tilt under LQR feedback (midpoint, h = 0.01, T = 10).
pub fn cart_pole_lqr() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/cart_pole_lqr.png";
    let samples = cart_pole::closed_loop(0.01, 0.3, 1000)?;
    let series = |label: &str, f: fn(&cart_pole::Sample) -> f64| Series {
        label: label.into(),
        points: samples.iter().map(|s| (s.t, f(s))).collect(),
    };
    line_chart(
        path,
        "Cart-pole balanced by LQR on the exact step derivatives (midpoint, h = 0.01)",
        ("t", "state and input"),
        &[
            series("θ (rad)", |s| s.theta),
            series("x (m)", |s| s.x),
            series("u / 10 (N)", |s| s.u / 10.0),
        ],
    )?;
    Ok(path)
}

/// log10 |error at T = 5| against log10 h for the pendulum, every quadrature.
fn convergence() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/convergence.png";
    let quadratures = [
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::galerkin(2)?,
        Quadrature::galerkin(3)?,
        Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3))?,
        Quadrature::galerkin_with_rule(3, Rule::GaussLobatto(4))?,
    ];
    let mut series = Vec::new();
    for quadrature in quadratures {
        let mut points = Vec::new();
        for n in [10, 20, 40, 80, 160] {
            let h = 5.0 / n as f64;
            let error = pendulum::error_at_5(quadrature.clone(), h)?;
            if error > 1e-14 {
                points.push((h.log10(), error.log10()));
            }
        }
        series.push(Series {
            label: quadrature.name(),
            points,
        });
    }
    line_chart(
        path,
        "Pendulum: error at T = 5 against step",
        ("log10 h", "log10 |error|"),
        &series,
    )?;
    Ok(path)
}

/// log10 |E − E0| over time for the double pendulum, h = 0.01.
fn energy() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/energy_error.png";
    let mut series = Vec::new();
    for quadrature in super::quadratures() {
        let name = quadrature.name();
        let mut stepper = double_pendulum::stepper(quadrature, 0.01)?;
        let trajectory = stepper.run_until(20.0)?;
        let e0 = trajectory.energy()[0];
        let points = trajectory
            .t()
            .iter()
            .zip(trajectory.energy())
            .skip(1)
            .map(|(t, e)| (*t, ((e - e0).abs().max(1e-16)).log10()))
            .collect();
        series.push(Series {
            label: name,
            points,
        });
    }
    line_chart(
        path,
        "Double pendulum: energy error, h = 0.01",
        ("t", "log10 |E − E0|"),
        &series,
    )?;
    Ok(path)
}

/// The knife edge's path (x, y) for the three constraint points against the closed form.
fn knife_edge_paths() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/knife_edge.png";
    let (h, steps) = (0.05, 200);
    let exact = (0..=steps)
        .map(|k| knife_edge::exact(k as f64 * h))
        .map(|q| (q[1], q[0]))
        .collect();
    let mut series = vec![Series {
        label: "exact".into(),
        points: exact,
    }];
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        let mut stepper = knife_edge::stepper(point, h)?;
        let trajectory = stepper.run_until(steps as f64 * h)?;
        let points = trajectory.q().iter().map(|q| (q[1], q[0])).collect();
        series.push(Series {
            label: format!("constraint at {point:?}"),
            points,
        });
    }
    line_chart(
        path,
        "Knife edge on an incline, h = 0.05, T = 10",
        ("y (across the slope)", "x (down the slope)"),
        &series,
    )?;
    Ok(path)
}

/// q_c2(t) of the LC circuit with the midpoint rule at h = 0.1 against the closed form.
fn lc_circuit() -> Result<&'static str, Box<dyn Error>> {
    let path = "output/lc_circuit.png";
    let h = 0.1;
    let mut stepper = Stepper::new(circuit::LC, Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(circuit::q0(), SVector::zeros())?;
    let trajectory = stepper.run_until(30.0)?;
    let computed = trajectory
        .t()
        .iter()
        .zip(trajectory.q())
        .map(|(t, q)| (*t, q[2]))
        .collect();
    let exact = (0..=3000)
        .map(|k| k as f64 * 0.01)
        .map(|t| (t, circuit::lc_q_c2(t)))
        .collect();
    let series = [
        Series {
            label: "closed form".into(),
            points: exact,
        },
        Series {
            label: "midpoint, h = 0.1".into(),
            points: computed,
        },
    ];
    line_chart(path, "LC circuit: charge on C2", ("t", "q_c2"), &series)?;
    Ok(path)
}

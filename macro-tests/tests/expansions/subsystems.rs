//! Models made of subsystems in the attribute: an LC circuit in two levels and an RLC of three
//! subsystems, each equal to the same circuit written as one struct.
use dirac::prelude::*;

#[dirac_system(coordinates(q), lagrangian = 0.5 * l * dot(q).powi(2))]
#[derive(Clone, Copy)]
struct Inductor {
    l: f64,
}

#[dirac_system(coordinates(q), lagrangian = -q.powi(2) / (2.0 * c))]
#[derive(Clone, Copy)]
struct Capacitor {
    c: f64,
}

#[dirac_system(coordinates(q), lagrangian = 0.0 * q, forces(-r * dot(q) * dq))]
#[derive(Clone, Copy)]
struct Resistor {
    r: f64,
}

#[dirac_system(subsystems(l, c), junctions(series = l.dq - c.dq))]
#[derive(Clone, Copy)]
struct Loop {
    l: Inductor,
    c: Capacitor,
}

/// The loop with a second capacitor in series: one current through all three.
#[dirac_system(subsystems(outer, c2), junctions(kcl = outer.c.dq - c2.dq))]
#[derive(Clone, Copy)]
struct Circuit {
    outer: Loop,
    c2: Capacitor,
}

/// The same circuit as one struct.
#[dirac_system(
    coordinates(q_l, q_c, q_c2),
    lagrangian = 0.5 * dot(q_l).powi(2) - q_c.powi(2) / 2.0 - q_c2.powi(2) / 4.0,
    constraints(dq_l - dq_c, dq_c - dq_c2),
)]
struct Whole;

/// An RLC of three subsystems (a resistor and two reactive elements).
#[dirac_system(subsystems(l, r, c), junctions(l.dq - r.dq, r.dq - c.dq), quadrature = galerkin(2))]
#[derive(Clone, Copy)]
struct Series {
    l: Inductor,
    r: Resistor,
    c: Capacitor,
}

#[test]
fn compiles_and_runs() -> Result<(), DiracError> {
    let circuit = Circuit {
        outer: Loop {
            l: Inductor { l: 1.0 },
            c: Capacitor { c: 1.0 },
        },
        c2: Capacitor { c: 2.0 },
    };
    assert_eq!(<Circuit as DiracSystem<3>>::ONE_FORMS, 2);
    let mut parts = Stepper::new(circuit, Quadrature::midpoint(), 0.01)?;
    assert_eq!(parts.coordinate_names(), ["outer.l.q", "outer.c.q", "c2.q"]);
    let mut whole = Stepper::new(Whole, Quadrature::midpoint(), 0.01)?;
    // Charges on the two capacitors, no current.
    let q0 = vector![0.0, 1.0, 2.0];
    parts.start_from_velocity(q0, SVector::zeros())?;
    whole.start_from_velocity(q0, SVector::zeros())?;
    for _ in 0..300 {
        parts.step()?;
        whole.step()?;
    }
    assert!((parts.q() - whole.q()).amax() < 1e-12);
    // Half a period of ω = √1.5 later the common charge has moved by about 2.5.
    assert!((parts.q()[1] - 1.0).abs() > 1.0);

    let series = Series {
        l: Inductor { l: 1.0 },
        r: Resistor { r: 0.1 },
        c: Capacitor { c: 1.0 },
    };
    assert_eq!(series.quadrature()?, Quadrature::galerkin(2)?);
    let mut stepper = Stepper::from_system(series, 0.05)?;
    stepper.start_from_velocity(vector![0.0, 0.0, 1.0], SVector::zeros())?;
    stepper.run(200)?;
    // The damped oscillation l q̈ + r q̇ + q/c = 0 from q = 1 at rest, at t = 10:
    // q = e^(−αt) (cos ω t + (α/ω) sin ω t), α = r/2l, ω = √(1/lc − α²).
    let (alpha, t) = (0.05f64, 10.0);
    let omega = (1.0 - alpha * alpha).sqrt();
    let exact = (-alpha * t).exp() * ((omega * t).cos() + alpha / omega * (omega * t).sin());
    assert!(
        (stepper.q()[2] - exact).abs() < 1e-5,
        "{} against {exact}",
        stepper.q()[2]
    );
    Ok(())
}

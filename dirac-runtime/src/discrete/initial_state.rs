//! Consistent initial data: an initial state must satisfy the constraints, their velocity form,
//! and the hidden constraints of degenerate coordinates (those without kinetic energy, whose
//! Euler–Lagrange equations are algebraic).

use nalgebra::{DMatrix, SVector};

use crate::base::float::{exceeds, largest};
use crate::discrete::constraint;
use crate::discrete::hidden_constraint::HiddenConstraints;
use crate::model::system::DiracSystem;

/// Checks `(q0, v0)` against the holonomic constraints `g(q0) = 0`, `dg(q0) v0 = 0`, the one-forms
/// `A(q0) v0 = 0`, and the hidden constraints of the degenerate coordinates `D`: their
/// Euler–Lagrange equations `d/dt ∂L/∂v_D − ∂L/∂q_D − F_D = (Aᵀμ + dgᵀλ)_D` contain no
/// acceleration, so some multipliers must balance them at `t = 0`. Returns what is violated.
///
/// Each residual is compared with `tolerance` times the size of the terms it sums
/// (`Σ_i |∂g/∂q_i q_i|` for `g`, `Σ_i |A_i v_i|` for `A v`, the largest term of a balance): the
/// check is independent of the units, and a state a stepper produced passes it. A constraint,
/// form or balance that is not finite at the state is a violation (a NaN passes no test).
pub(crate) fn check<S: DiracSystem<N>, const N: usize>(
    system: &S,
    t0: f64,
    q0: &SVector<f64, N>,
    v0: &SVector<f64, N>,
    inputs: &[f64],
    tolerance: f64,
) -> Result<(), String> {
    let name = |i: usize| system.coordinate_name(i);
    check_constraints(system, q0, v0, tolerance)?;
    let rows = HiddenConstraints::rows_of(system, q0, v0);
    if rows.coordinates().is_empty() {
        return Ok(());
    }
    // Rows D of  ∂L/∂q + F − d/dt ∂L/∂v + Aᵀμ + dgᵀλ = 0, with d/dt ∂L/∂v_D = Σ_j ∂²L/∂q_j∂v_D v_j.
    let (unbalanced, _, size) = rows.rows_in_velocity(system, q0, v0, t0, inputs);
    let (dead, forms) = (rows.coordinates(), HiddenConstraints::forms(system, q0));
    let matrix = DMatrix::from_fn(dead.len(), forms.nrows(), |r, c| forms[(c, dead[r])]);
    if !unbalanced.iter().all(|x| x.is_finite()) {
        return Err(
            "the Euler–Lagrange rows of the coordinates without kinetic energy are not finite \
             at the initial state"
                .to_string(),
        );
    }
    let residual = if forms.nrows() == 0 {
        largest(unbalanced.iter().copied())
    } else {
        let svd = matrix.clone().svd(true, true);
        let cutoff = 1e-12 * svd.singular_values.amax();
        let rhs = -&unbalanced;
        let multipliers = svd.solve(&rhs, cutoff).map_err(|e| e.to_string())?;
        largest((matrix * multipliers - &rhs).iter().copied())
    };
    if exceeds(residual, tolerance * size) {
        let names: Vec<String> = dead.iter().map(|&i| name(i)).collect();
        return Err(format!(
            "the initial state violates a hidden constraint of the coordinates without kinetic \
             energy ({}): their forces are not balanced by any constraint force (residual \
             {residual:.3e}); e.g. charges on parallel capacitors must have equal voltages",
            names.join(", ")
        ));
    }
    Ok(())
}

/// Checks `(q0, v0)` against the holonomic constraints `g(q0) = 0`, `dg(q0) v0 = 0` and the
/// one-forms `A(q0) v0 = 0` alone (a component of a modular interconnection, whose degenerate
/// coordinates the junctions balance); returns what is violated.
pub(crate) fn check_constraints<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q0: &SVector<f64, N>,
    v0: &SVector<f64, N>,
    tolerance: f64,
) -> Result<(), String> {
    for b in 0..S::HOLONOMIC {
        let (g, form) = constraint::holonomic(system, q0, b);
        if !(g.is_finite() && form.iter().all(|x| x.is_finite())) {
            return Err(format!(
                "holonomic constraint {b} or its differential is not finite at the initial \
                 position (g = {g:.3e})"
            ));
        }
        if exceeds(g.abs(), tolerance * size(&form, q0)) {
            return Err(format!(
                "the initial position violates holonomic constraint {b}: g = {g:.3e}"
            ));
        }
        let rate = form.dot(v0);
        if exceeds(rate.abs(), tolerance * size(&form, v0)) {
            return Err(format!(
                "the initial velocity is not tangent to holonomic constraint {b}: dg·v = {rate:.3e}"
            ));
        }
    }
    let forms: Vec<SVector<f64, N>> = (0..S::ONE_FORMS)
        .map(|a| constraint::one_form(system, q0, a).0)
        .collect();
    for (a, form) in forms.iter().enumerate() {
        if !form.iter().all(|x| x.is_finite()) {
            return Err(format!(
                "constraint one-form {a} ({}) is not finite at the initial position",
                system.one_form_name(a)
            ));
        }
        let rate = form.dot(v0);
        if exceeds(rate.abs(), tolerance * size(form, v0)) {
            return Err(format!(
                "the initial velocity violates constraint one-form {a}: A·v = {rate:.3e}"
            ));
        }
    }
    Ok(())
}

/// `Σ_i |a_i x_i|`: the size of the terms of `a · x`.
fn size<const N: usize>(a: &SVector<f64, N>, x: &SVector<f64, N>) -> f64 {
    a.component_mul(x).abs().sum()
}

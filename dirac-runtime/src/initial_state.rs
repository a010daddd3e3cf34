//! Consistent initial data: an initial state must satisfy the constraints, their velocity form,
//! and the hidden constraints of degenerate coordinates (those without kinetic energy, whose
//! Euler–Lagrange equations are algebraic).

use nalgebra::{DMatrix, DVector, SVector};

use crate::constraint;
use crate::derivatives::{Seed, degenerate, seeded};
use crate::system::DiracSystem;

/// Checks `(q0, v0)` against the holonomic constraints `g(q0) = 0`, `dg(q0) v0 = 0`, the one-forms
/// `A(q0) v0 = 0`, and the hidden constraints of the degenerate coordinates `D`: their
/// Euler–Lagrange equations `d/dt ∂L/∂v_D − ∂L/∂q_D − F_D = (Aᵀμ + dgᵀλ)_D` contain no
/// acceleration, so some multipliers must balance them at `t = 0`. Returns what is violated.
///
/// Each residual is compared with `tolerance` times the size of the terms it sums
/// (`Σ_i |∂g/∂q_i q_i|` for `g`, `Σ_i |A_i v_i|` for `A v`, the largest term of a balance): the
/// check is independent of the units, and a state a stepper produced passes it.
pub(crate) fn check<S: DiracSystem<N>, const N: usize>(
    system: &S,
    t0: f64,
    q0: &SVector<f64, N>,
    v0: &SVector<f64, N>,
    inputs: &[f64],
    tolerance: f64,
) -> Result<(), String> {
    let name = |i: usize| system.coordinate_name(i);
    for b in 0..S::HOLONOMIC {
        let (g, form) = constraint::holonomic(system, q0, b);
        if g.abs() > tolerance * size(&form, q0) {
            return Err(format!(
                "the initial position violates holonomic constraint {b}: g = {g:.3e}"
            ));
        }
        let rate = form.dot(v0);
        if rate.abs() > tolerance * size(&form, v0) {
            return Err(format!(
                "the initial velocity is not tangent to holonomic constraint {b}: dg·v = {rate:.3e}"
            ));
        }
    }
    let forms: Vec<SVector<f64, N>> = (0..S::ONE_FORMS)
        .map(|a| constraint::one_form(system, q0, a).0)
        .collect();
    for (a, form) in forms.iter().enumerate() {
        let rate = form.dot(v0);
        if rate.abs() > tolerance * size(form, v0) {
            return Err(format!(
                "the initial velocity violates constraint one-form {a}: A·v = {rate:.3e}"
            ));
        }
    }
    let dead = degenerate(system, q0, v0);
    if dead.is_empty() {
        return Ok(());
    }
    // Rows D of  ∂L/∂q + F − d/dt ∂L/∂v + Aᵀμ + dgᵀλ = 0, with d/dt ∂L/∂v_D = Σ_j ∂²L/∂q_j∂v_D v_j.
    let qv = seeded(system, q0, v0, Seed::POSITION, Seed::VELOCITY);
    let force = system.force(q0, v0, t0, inputs);
    let unbalanced: SVector<f64, N> = qv.first + force - qv.mixed.transpose() * v0;
    let mut columns: Vec<SVector<f64, N>> = forms;
    columns.extend((0..S::HOLONOMIC).map(|b| constraint::holonomic(system, q0, b).1));
    let matrix = DMatrix::from_fn(dead.len(), columns.len(), |r, c| columns[c][dead[r]]);
    let rhs = DVector::from_iterator(dead.len(), dead.iter().map(|&i| -unbalanced[i]));
    let residual = if columns.is_empty() {
        rhs.amax()
    } else {
        let svd = matrix.clone().svd(true, true);
        let cutoff = 1e-12 * svd.singular_values.amax();
        let multipliers = svd.solve(&rhs, cutoff).map_err(|e| e.to_string())?;
        (matrix * multipliers - &rhs).amax()
    };
    let transport = qv.mixed.transpose() * v0;
    let size = dead
        .iter()
        .map(|&i| {
            qv.first[i]
                .abs()
                .max(force[i].abs())
                .max(transport[i].abs())
        })
        .fold(0.0, f64::max);
    if residual > tolerance * size {
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

/// `Σ_i |a_i x_i|`: the size of the terms of `a · x`.
fn size<const N: usize>(a: &SVector<f64, N>, x: &SVector<f64, N>) -> f64 {
    a.component_mul(x).abs().sum()
}

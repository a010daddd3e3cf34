//! Newton's method with an exact Jacobian and an LU solve, on a preallocated workspace.

use nalgebra::{DMatrix, DVector};

use crate::lu::{self, SingularPivot};

/// Tolerances and iteration cap of Newton's method.
///
/// A solve has converged when the residual's infinity norm is at most
/// `residual_tolerance · scale`, where `scale` is the size of the terms summed into the residual
/// (so the tolerance sits a fixed distance above its round-off floor), and the last update was at
/// most `step_tolerance · (1 + |x|∞)`. The tolerance never asks for less than the round-off floor
/// `64 ε ‖J‖∞ ‖x‖∞`. The returned point is always one whose residual was checked.
///
/// ```
/// let options = dirac_runtime::NewtonOptions { max_iterations: 50, ..Default::default() };
/// assert_eq!(options.residual_tolerance, 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Relative tolerance on the residual.
    pub residual_tolerance: f64,
    /// Relative tolerance on the last update.
    pub step_tolerance: f64,
    /// Most iterations before giving up.
    pub max_iterations: usize,
    /// A pivot below this fraction of the largest Jacobian entry counts as zero.
    pub singular_tolerance: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-12,
            step_tolerance: 1e-9,
            max_iterations: 25,
            singular_tolerance: 1e-13,
        }
    }
}

/// How a successful solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    /// Residual evaluations (each with its Jacobian) performed.
    pub iterations: usize,
    /// Infinity norm of the residual at the returned point.
    pub residual: f64,
}

/// Why a solve failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonFailure {
    /// The tolerance was not met within the cap.
    NoConvergence {
        /// Residual norm at the last iterate.
        residual: f64,
        /// Iterations performed.
        iterations: usize,
    },
    /// The Jacobian could not be factorised.
    Singular(SingularPivot),
    /// The residual or the Jacobian contained NaN or infinity.
    NonFinite,
}

/// Newton's method for `F(x) = 0` on `R^n`, reusing its buffers across solves.
///
/// The caller's closure fills the residual and the Jacobian at `x` and returns the residual's
/// scale: the size of the terms it sums, against which the tolerance is relative. Nothing is
/// allocated per iteration.
///
/// ```
/// use dirac_runtime::{Newton, NewtonOptions};
/// use nalgebra::DVector;
/// // x² = 2
/// let mut newton = Newton::new(1, NewtonOptions::default());
/// let mut x = DVector::from_element(1, 1.0);
/// newton.solve(&mut x, |x, r, j| {
///     r[0] = x[0] * x[0] - 2.0;
///     j[(0, 0)] = 2.0 * x[0];
///     2.0 // the size of the terms of the residual
/// }).unwrap();
/// assert!((x[0] - 2f64.sqrt()).abs() < 1e-15);
/// ```
#[derive(Debug, Clone)]
pub struct Newton {
    options: NewtonOptions,
    residual: DVector<f64>,
    jacobian: DMatrix<f64>,
    pivots: Vec<usize>,
}

impl Newton {
    /// A solver for `n` unknowns.
    pub fn new(n: usize, options: NewtonOptions) -> Self {
        Self {
            options,
            residual: DVector::zeros(n),
            jacobian: DMatrix::zeros(n, n),
            pivots: vec![0; n],
        }
    }

    /// The options in force.
    pub fn options(&self) -> &NewtonOptions {
        &self.options
    }

    /// Solves `F(x) = 0` from the initial guess in `x`; `x` holds the solution on success and an
    /// unspecified iterate on failure.
    pub fn solve<F>(
        &mut self,
        x: &mut DVector<f64>,
        mut evaluate: F,
    ) -> Result<NewtonReport, NewtonFailure>
    where
        F: FnMut(&DVector<f64>, &mut DVector<f64>, &mut DMatrix<f64>) -> f64,
    {
        let mut last_update = f64::INFINITY;
        let mut residual = f64::INFINITY;
        for iteration in 1..=self.options.max_iterations {
            self.jacobian.fill(0.0);
            let scale = evaluate(x, &mut self.residual, &mut self.jacobian);
            // Round-off floor: what perturbing x by a few ulps does to the residual.
            let floor = 64.0 * f64::EPSILON * row_sum_norm(&self.jacobian) * x.amax();
            let tolerance = self.options.residual_tolerance * scale + floor;
            residual = self.residual.amax();
            if !residual.is_finite() {
                return Err(NewtonFailure::NonFinite);
            }
            let settled = last_update <= self.options.step_tolerance * (1.0 + x.amax());
            let converged = residual <= tolerance && (settled || residual == 0.0);
            if converged && iteration > 1 {
                return Ok(NewtonReport {
                    iterations: iteration,
                    residual,
                });
            }
            if self.jacobian.iter().any(|v| !v.is_finite()) {
                return Err(NewtonFailure::NonFinite);
            }
            // Factorised even when the initial guess already solves the equations: a solution
            // is only accepted where the Jacobian shows it is unique.
            lu::factorise(
                &mut self.jacobian,
                &mut self.pivots,
                self.options.singular_tolerance,
            )
            .map_err(NewtonFailure::Singular)?;
            if converged {
                return Ok(NewtonReport {
                    iterations: iteration,
                    residual,
                });
            }
            lu::solve(&self.jacobian, &self.pivots, &mut self.residual);
            *x -= &self.residual;
            last_update = self.residual.amax();
        }
        Err(NewtonFailure::NoConvergence {
            residual,
            iterations: self.options.max_iterations,
        })
    }
}

/// `‖A‖∞`, the largest absolute row sum.
fn row_sum_norm(a: &DMatrix<f64>) -> f64 {
    a.row_iter()
        .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converges_quadratically_on_a_coupled_system() {
        // x + y = 3, x y = 2 from (0.5, 2.8): the root (1, 2).
        let mut newton = Newton::new(2, NewtonOptions::default());
        let mut x = DVector::from_vec(vec![0.5, 2.8]);
        let report = newton
            .solve(&mut x, |x, r, j| {
                r[0] = x[0] + x[1] - 3.0;
                r[1] = x[0] * x[1] - 2.0;
                j.copy_from_slice(&[1.0, x[1], 1.0, x[0]]);
                3.0
            })
            .unwrap();
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 2.0).abs() < 1e-15);
        assert!(report.iterations <= 7, "{report:?}");
    }

    #[test]
    fn reports_no_convergence_and_singularity() {
        let mut newton = Newton::new(
            1,
            NewtonOptions {
                max_iterations: 3,
                ..Default::default()
            },
        );
        let mut x = DVector::from_element(1, 0.3);
        // x² + 1 = 0 has no real root.
        let err = newton.solve(&mut x, |x, r, j| {
            r[0] = x[0] * x[0] + 1.0;
            j[(0, 0)] = 2.0 * x[0];
            1.0
        });
        assert!(matches!(
            err,
            Err(NewtonFailure::NoConvergence { iterations: 3, .. })
        ));
        let mut x = DVector::from_element(1, 0.0);
        let err = newton.solve(&mut x, |x, r, j| {
            r[0] = x[0] * x[0] + 1.0;
            j[(0, 0)] = 2.0 * x[0];
            1.0
        });
        assert_eq!(
            err,
            Err(NewtonFailure::Singular(SingularPivot {
                column: 0,
                involved: vec![0]
            }))
        );
    }
}

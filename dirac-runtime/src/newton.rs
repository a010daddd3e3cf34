//! Newton's method with an exact Jacobian and an LU solve, on a preallocated workspace.

use nalgebra::{DMatrix, DVector};

use crate::error::DiracError;
use crate::lu::{self, SingularPivot};

/// Tolerances, iteration cap and root-acceptance rule of Newton's method.
///
/// A solve has converged when the residual's infinity norm is at most
/// `residual_tolerance · scale`, where `scale` is the size of the terms summed into the residual
/// (so the tolerance sits a fixed distance above its round-off floor), and the last update was at
/// most `step_tolerance · (1 + |x|∞)`. The tolerance never asks for less than the round-off floor
/// `64 ε ‖J‖∞ ‖x‖∞`. The returned point is always one whose residual was checked.
///
/// **Root acceptance.** A root is accepted only if the iteration reached it by contracting: every
/// update above the step tolerance is at most `max_contraction` (default ¼) times the one before.
/// This is the observable side of Kantorovich's theorem. Newton's second update is at most
/// `(βL/2)` times the square of the first, so the measured ratio `θ` bounds Kantorovich's
/// `h_K = βLη` from below by `2θ`; his condition `h_K ≤ ½` then needs `θ ≤ ¼`, and under it the
/// root is the only one in a ball around the initial guess of radius about `η / h_K`, far larger
/// than the distance travelled. A step's root is then the continuation of the trajectory from
/// the predictor. A root reached after growing or slowly shrinking updates (a near-singular
/// Jacobian, a step too large for the dynamics) is refused with [`NewtonFailure::NotContracting`].
/// Linear equations converge in one update and pass at any step size.
///
/// `line_search` halves each update until the residual is finite and decreases (Armijo
/// backtracking): a globalised solve for well-posed but strongly nonlinear equations, used by
/// the Legendre inversion. The step itself takes full Newton steps.
///
/// ```
/// let options = dirac_runtime::NewtonOptions { max_iterations: 50, ..Default::default() };
/// assert_eq!(options.residual_tolerance, 1e-12);
/// assert!(options.validate().is_ok());
/// let nan = dirac_runtime::NewtonOptions { residual_tolerance: f64::NAN, ..Default::default() };
/// assert!(nan.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Relative tolerance on the residual, in `[0, 1)`.
    pub residual_tolerance: f64,
    /// Relative tolerance on the last update, in `[0, 1)`.
    pub step_tolerance: f64,
    /// Most iterations before giving up (at least 1).
    pub max_iterations: usize,
    /// A pivot below this fraction of the largest Jacobian entry counts as zero, in `[0, 1)`.
    pub singular_tolerance: f64,
    /// Largest accepted ratio of successive updates: positive; `f64::INFINITY` turns the
    /// root-acceptance check off.
    pub max_contraction: f64,
    /// Backtrack each update until the residual decreases (globalised Newton).
    pub line_search: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-12,
            step_tolerance: 1e-9,
            max_iterations: 25,
            singular_tolerance: 1e-13,
            max_contraction: 0.25,
            line_search: false,
        }
    }
}

impl NewtonOptions {
    /// Checks every field's range; the error names the field and its value.
    pub fn validate(&self) -> Result<(), DiracError> {
        let unit = |name: &str, value: f64| {
            if (0.0..1.0).contains(&value) {
                Ok(())
            } else {
                Err(DiracError::InvalidOptions(format!(
                    "{name} must be in [0, 1), got {value}"
                )))
            }
        };
        unit("residual_tolerance", self.residual_tolerance)?;
        unit("step_tolerance", self.step_tolerance)?;
        unit("singular_tolerance", self.singular_tolerance)?;
        if self.max_contraction.is_nan() || self.max_contraction <= 0.0 {
            return Err(DiracError::InvalidOptions(format!(
                "max_contraction must be positive (infinity turns the check off), got {}",
                self.max_contraction
            )));
        }
        if self.max_iterations == 0 {
            return Err(DiracError::InvalidOptions(
                "max_iterations must be at least 1".into(),
            ));
        }
        Ok(())
    }
}

/// How a successful solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    /// Residual evaluations (each with its Jacobian) performed.
    pub iterations: usize,
    /// Infinity norm of the residual at the returned point.
    pub residual: f64,
    /// Largest ratio of successive updates above the step tolerance (0 when there was only one):
    /// how far from quadratic the convergence was.
    pub contraction: f64,
}

/// Why a solve failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonFailure {
    /// The tolerance was not met within the cap.
    NoConvergence {
        /// Residual norm at the last iterate.
        residual: f64,
        /// Size of the last update (infinite if none was taken).
        update: f64,
        /// Iterations performed.
        iterations: usize,
    },
    /// The iteration did not contract: an update exceeded `max_contraction` times the previous
    /// one, so a root it reached might not be the one nearest the initial guess.
    NotContracting {
        /// The ratio of successive updates that broke the bound.
        contraction: f64,
        /// Iterations performed.
        iterations: usize,
    },
    /// The Jacobian could not be factorised.
    Singular(SingularPivot),
    /// The residual or the Jacobian contained NaN or infinity.
    NonFinite,
    /// The unknowns' vector does not have the solver's size.
    Dimension {
        /// The solver's number of unknowns.
        expected: usize,
        /// The length of the vector passed.
        got: usize,
    },
}

/// Newton's method for `F(x) = 0` on `R^n`, reusing its buffers across solves.
///
/// The caller's closure fills the residual and adds the Jacobian at `x` (into a zeroed matrix)
/// and returns the residual's scale: the size of the terms it sums, against which the tolerance
/// is relative. Nothing is allocated per iteration.
///
/// ```
/// use dirac_runtime::{Newton, NewtonOptions};
/// use nalgebra::DVector;
/// // x² = 2
/// let mut newton = Newton::new(1, NewtonOptions::default())?;
/// let mut x = DVector::from_element(1, 1.0);
/// newton.solve(&mut x, |x, r, j| {
///     r[0] = x[0] * x[0] - 2.0;
///     j[(0, 0)] = 2.0 * x[0];
///     2.0 // the size of the terms of the residual
/// }).unwrap();
/// assert!((x[0] - 2f64.sqrt()).abs() < 1e-15);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Newton {
    options: NewtonOptions,
    residual: DVector<f64>,
    jacobian: DMatrix<f64>,
    pivots: Vec<usize>,
    /// The Newton update `J⁻¹ F`, kept apart from the residual for the line search.
    update: DVector<f64>,
    /// The trial point of the line search.
    trial: DVector<f64>,
}

/// The residual's norm at a point and the tolerance it is held to there.
#[derive(Debug, Clone, Copy)]
struct Evaluation {
    residual: f64,
    tolerance: f64,
}

impl Newton {
    /// A solver for `n` unknowns; fails on options out of range.
    pub fn new(n: usize, options: NewtonOptions) -> Result<Self, DiracError> {
        options.validate()?;
        Ok(Self {
            options,
            residual: DVector::zeros(n),
            jacobian: DMatrix::zeros(n, n),
            pivots: vec![0; n],
            update: DVector::zeros(n),
            trial: DVector::zeros(n),
        })
    }

    /// The options in force.
    pub fn options(&self) -> &NewtonOptions {
        &self.options
    }

    /// Residual and Jacobian at `x` into the buffers; its norm and tolerance, or `None` when the
    /// residual is not finite.
    fn evaluate<F>(&mut self, x: &DVector<f64>, evaluate: &mut F) -> Option<Evaluation>
    where
        F: FnMut(&DVector<f64>, &mut DVector<f64>, &mut DMatrix<f64>) -> f64,
    {
        self.jacobian.fill(0.0);
        let scale = evaluate(x, &mut self.residual, &mut self.jacobian);
        // Round-off floor: what perturbing x by a few ulps does to the residual.
        let floor = 64.0 * f64::EPSILON * row_sum_norm(&self.jacobian) * x.amax();
        let residual = self.residual.amax();
        residual.is_finite().then_some(Evaluation {
            residual,
            tolerance: self.options.residual_tolerance * scale + floor,
        })
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
        if x.len() != self.residual.len() {
            return Err(NewtonFailure::Dimension {
                expected: self.residual.len(),
                got: x.len(),
            });
        }
        let options = self.options;
        let mut at_x = self
            .evaluate(x, &mut evaluate)
            .ok_or(NewtonFailure::NonFinite)?;
        let mut last_update = f64::INFINITY;
        let mut contraction: f64 = 0.0;
        for iteration in 1..=options.max_iterations {
            let noise = options.step_tolerance * (1.0 + x.amax());
            let converged =
                at_x.residual <= at_x.tolerance && (last_update <= noise || at_x.residual == 0.0);
            let report = NewtonReport {
                iterations: iteration,
                residual: at_x.residual,
                contraction,
            };
            if converged && iteration > 1 {
                return Ok(report);
            }
            if self.jacobian.iter().any(|v| !v.is_finite()) {
                return Err(NewtonFailure::NonFinite);
            }
            // Factorised even when the initial guess already solves the equations: a solution
            // is only accepted where the Jacobian shows it is unique.
            lu::factorise(
                &mut self.jacobian,
                &mut self.pivots,
                options.singular_tolerance,
            )
            .map_err(NewtonFailure::Singular)?;
            if converged {
                return Ok(report);
            }
            self.update.copy_from(&self.residual);
            lu::solve(&self.jacobian, &self.pivots, &mut self.update);
            let update = self.update.amax();
            if last_update.is_finite() && update > noise {
                contraction = contraction.max(update / last_update);
                if contraction > options.max_contraction {
                    return Err(NewtonFailure::NotContracting {
                        contraction,
                        iterations: iteration,
                    });
                }
            }
            if iteration == options.max_iterations {
                break;
            }
            let mut length = 1.0;
            at_x = loop {
                self.trial.copy_from(x);
                self.trial.axpy(-length, &self.update, 1.0);
                let trial = std::mem::take(&mut self.trial);
                let at_trial = self.evaluate(&trial, &mut evaluate);
                self.trial = trial;
                match at_trial {
                    Some(e) if !options.line_search => break e,
                    None if !options.line_search => return Err(NewtonFailure::NonFinite),
                    // Armijo: accept a sufficient decrease of the residual's norm, or a
                    // residual already within tolerance (round-off admits no decrease there).
                    Some(e)
                        if e.residual <= (1.0 - 1e-4 * length) * at_x.residual
                            || e.residual <= e.tolerance =>
                    {
                        break e;
                    }
                    _ if length < 1e-10 => {
                        return Err(NewtonFailure::NoConvergence {
                            residual: at_x.residual,
                            update: last_update,
                            iterations: iteration,
                        });
                    }
                    _ => length *= 0.5,
                }
            };
            x.copy_from(&self.trial);
            last_update = length * update;
        }
        Err(NewtonFailure::NoConvergence {
            residual: at_x.residual,
            update: last_update,
            iterations: options.max_iterations,
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
        let mut newton = Newton::new(2, NewtonOptions::default()).unwrap();
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
                max_contraction: f64::INFINITY,
                ..Default::default()
            },
        )
        .unwrap();
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

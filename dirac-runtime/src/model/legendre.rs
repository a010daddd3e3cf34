//! The Legendre transform: momentum from velocity, velocity from momentum, and the energy.

use nalgebra::{DMatrix, DVector, SVector};

use crate::base::float::row_sum_norm;
use crate::model::derivatives::{PhaseFunction, Seed, seeded};
use crate::model::system::DiracSystem;
use crate::solve::newton::{Newton, NewtonFailure};

/// `p = ∂L/∂v (q, v)`.
///
/// ```
/// use dirac_runtime::{DiracSystem, Scalar, legendre};
/// use nalgebra::{SVector, vector};
/// struct Particle;
/// impl DiracSystem<1> for Particle {
///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 1.5 // mass 3
///     }
/// }
/// assert_eq!(legendre::momentum(&Particle, &vector![0.0], &vector![2.0])[0], 6.0);
/// ```
pub fn momentum<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> SVector<f64, N> {
    seeded(system, q, v, Seed::VELOCITY, Seed::NONE).first
}

/// The energy `E = ⟨p, v⟩ − L(q, v)`.
///
/// ```
/// use dirac_runtime::{DiracSystem, Scalar, legendre};
/// use nalgebra::{SVector, vector};
/// struct Spring;
/// impl DiracSystem<1> for Spring {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// assert_eq!(legendre::energy(&Spring, &vector![1.0], &vector![1.0]), 1.0);
/// ```
pub fn energy<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> f64 {
    let l = seeded(system, q, v, Seed::VELOCITY, Seed::NONE);
    l.first.dot(v) - l.value
}

/// Inverts the Legendre transform: solves `∂L/∂v (q, v) = p` for `v` by Newton's method from
/// `guess`, with the exact Hessian `∂²L/∂v²`. `newton` must be sized for `N` unknowns.
///
/// Velocities without kinetic energy (`dead`, the coordinates whose rows of `∂²L/∂v²` vanish)
/// are not determined by `p`; they keep their guess, and the energy does not depend on them.
pub(crate) fn velocity<F: PhaseFunction<N>, const N: usize>(
    system: &F,
    newton: &mut Newton,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    guess: &SVector<f64, N>,
    dead: &[usize],
) -> Result<SVector<f64, N>, NewtonFailure> {
    velocity_with_energy(system, newton, q, p, guess, dead).map(|(v, _)| v)
}

/// [`velocity`], with the energy `⟨∂L/∂v, v⟩ − L` at the velocity found where the solve
/// evaluated `L` there on its way (the chord step of closed-form derivatives): the numbers
/// [`energy`] gives, without evaluating `L` again. `None` for the energy where the general
/// solve ran.
#[inline(always)]
pub(crate) fn velocity_with_energy<F: PhaseFunction<N>, const N: usize>(
    system: &F,
    newton: &mut Newton,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    guess: &SVector<f64, N>,
    dead: &[usize],
) -> Result<(SVector<f64, N>, Option<f64>), NewtonFailure> {
    if dead.is_empty()
        && let Some((v, energy)) = chord_velocity(system, newton, q, p, guess)
    {
        return Ok((v, Some(energy)));
    }
    newton_velocity(system, newton, q, p, guess, dead).map(|v| (v, None))
}

/// The general solve of [`velocity`]: Newton's method with the Hessian, from `guess`.
#[inline(never)]
fn newton_velocity<F: PhaseFunction<N>, const N: usize>(
    system: &F,
    newton: &mut Newton,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    guess: &SVector<f64, N>,
    dead: &[usize],
) -> Result<SVector<f64, N>, NewtonFailure> {
    let x = newton.solve_from(guess.as_slice(), |x, r, j| {
        let v = SVector::<f64, N>::from_column_slice(x.as_slice());
        // The Hessian only when Newton asks for a Jacobian.
        let second = if j.is_some() {
            Seed::VELOCITY
        } else {
            Seed::NONE
        };
        let l = seeded(system, q, &v, Seed::VELOCITY, second);
        r.copy_from(&(l.first - p));
        for &i in dead {
            r[i] = x[i] - guess[i];
        }
        if let Some(j) = j {
            j.copy_from(&l.mixed);
            for &i in dead {
                j.row_mut(i).fill(0.0);
                j[(i, i)] = 1.0;
            }
        }
        l.first.abs().sup(&p.abs()).amax()
    })?;
    Ok(SVector::from_column_slice(x.as_slice()))
}

/// One Newton step from `guess` with the Hessian `∂²L/∂v²` there, in fixed size, taken where
/// `L` has closed-form second derivatives: exact for a Lagrangian quadratic in the velocities
/// (any mechanical one), it costs a Hessian and a gradient where the general solve adds its
/// dynamic-size bookkeeping (recorded samples solve a velocity each). The point it reaches is
/// returned only where `newton` accepts it (`Newton::accepts`): the residual within tolerance
/// and the correction there at round-off. A Hessian whose condition number `‖H‖∞‖H⁻¹‖∞` exceeds the inverse of the
/// solver's singular tolerance is left to the general solve, which refuses it as singular.
/// `None` sends the caller to the general solve. With the velocity comes the energy there,
/// `⟨∂L/∂v, v⟩ − L`, from the gradient the acceptance test evaluated.
fn chord_velocity<F: PhaseFunction<N>, const N: usize>(
    system: &F,
    newton: &Newton,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    guess: &SVector<f64, N>,
) -> Option<(SVector<f64, N>, f64)> {
    let hessian = system.closed_hessian(q, guess)?;
    let inverse = hessian.vv.try_inverse()?;
    let mut sums = [0.0; N];
    let norm = row_sum_norm(&hessian.vv, &mut sums);
    // A condition number that is NaN or too large: not this path's to judge.
    let condition = norm * row_sum_norm(&inverse, &mut sums);
    if condition.is_nan() || condition * newton.options().singular_tolerance > 1.0 {
        return None;
    }
    let v = guess - inverse * (hessian.gradient.v - p);
    let at_v = system.closed_gradient(q, &v)?;
    let residual = at_v.v - p;
    let update = inverse * residual;
    let scale = at_v.v.abs().sup(&p.abs()).amax();
    let finite = v.iter().chain(residual.iter()).all(|x| x.is_finite());
    let accepted = newton.accepts(residual.amax(), scale, norm, v.amax(), update.amax());
    (finite && accepted).then(|| (v, at_v.v.dot(&v) - at_v.value))
}

/// The Legendre transform of a constrained model: solves
///
/// ```text
/// ∂L/∂v (q, v) = p + Cᵀν,    C v = 0
/// ```
///
/// for `(v, ν)` from `guess`, where the rows of `C` are the constraint forms at `q` (one-forms,
/// holonomic differentials, hidden constraints' differentials). A discrete momentum carries a
/// component along the constraint forces (`Cᵀν`) that the velocity does not: the solution is
/// the velocity the constraints allow whose momentum differs from `p` by a constraint impulse.
/// The velocities of coordinates without kinetic energy are fixed by `C v = 0`; where they are
/// not (the matrix `[[∂²L/∂v², −Cᵀ], [C, 0]]` is singular), Newton fails. `newton` must be sized
/// for `N + C.nrows()` unknowns.
///
/// Where some degenerate rows are first-order equations (`dynamic`: a resistor beside a
/// capacitor), their velocities are fixed by those equations, not by `p` (a coordinate `d`
/// without kinetic energy has `∂L/∂v_d = ϑ_d(q)`, whatever `v`). The momentum rows of the
/// degenerate coordinates are then replaced by
///
/// ```text
/// Pᵀ (∂L/∂v_D − p_D − (Cᵀν)_D) = 0,      Wᵀ R_D(q, v, t) = 0,
/// ```
///
/// where `W` spans the combinations of the degenerate rows that no constraint force reaches
/// (`Wᵀ C_Dᵀ = 0`, so the multipliers drop out of `Wᵀ R_D`, and these rows are the model's
/// first-order equations at `(q, t)`) and `P` the others (whose momentum rows fix the
/// impulses on `D`). The rows stay as many as the unknowns, and the velocity satisfies the
/// constraints and the first-order equations at `q` exactly, so that a state started from
/// `(q, p)` passes the start checks.
pub(crate) fn constrained_velocity<F: PhaseFunction<N>, const N: usize>(
    system: &F,
    newton: &mut Newton,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    forms: &DMatrix<f64>,
    guess: &SVector<f64, N>,
    dynamic: Option<&DynamicRows<'_, N>>,
) -> Result<(SVector<f64, N>, DVector<f64>), NewtonFailure> {
    let m = forms.nrows();
    let mut x = DVector::zeros(N + m);
    x.rows_mut(0, N).copy_from(guess);
    newton.solve(&mut x, |x, r, j| {
        let v = SVector::<f64, N>::from_column_slice(&x.as_slice()[..N]);
        let nu = x.rows(N, m);
        let l = seeded(system, q, &v, Seed::VELOCITY, Seed::VELOCITY);
        let impulse = forms.transpose() * nu;
        let mut scale = l.first.abs().sup(&p.abs()).amax();
        for i in 0..N {
            r[i] = l.first[i] - p[i] - impulse[i];
            scale = scale.max(impulse[i].abs());
        }
        let rate = forms * v;
        r.rows_mut(N, m).copy_from(&rate);
        // Line-searched solves always ask for the Jacobian; any other gets a local one.
        let mut local = None;
        let j = match j {
            Some(j) => j,
            None => local.insert(DMatrix::zeros(N + m, N + m)),
        };
        j.view_mut((0, 0), (N, N)).copy_from(&l.mixed);
        j.view_mut((0, N), (N, m)).copy_from(&(-forms.transpose()));
        j.view_mut((N, 0), (m, N)).copy_from(forms);
        if let Some(dynamic) = dynamic {
            scale = scale.max(dynamic.replace_rows(&v, r, j));
        }
        scale.max(forms.amax() * v.amax())
    })?;
    let v = SVector::from_column_slice(&x.as_slice()[..N]);
    Ok((v, x.rows(N, m).into_owned()))
}

/// The degenerate rows of a constrained model that contain velocities (a resistor beside a
/// capacitor), for [`constrained_velocity`].
pub(crate) struct DynamicRows<'a, const N: usize> {
    /// The degenerate coordinates `D`.
    pub coordinates: &'a [usize],
    /// An orthonormal basis `P` (columns over `D`) of the combinations of their rows that the
    /// constraint forces reach.
    pub reached: &'a DMatrix<f64>,
    /// A basis `W` of the combinations they do not reach.
    pub unreached: &'a DMatrix<f64>,
    /// `v ↦ (R_D(q, v, t), ∂R_D/∂v, size of its terms)`, the rows without multipliers.
    pub rows: &'a dyn Fn(&SVector<f64, N>) -> RowsInVelocity,
}

/// Rows, their Jacobian in `v`, and the size of their terms.
pub(crate) type RowsInVelocity = (DVector<f64>, DMatrix<f64>, f64);

impl<const N: usize> DynamicRows<'_, N> {
    /// Replaces the momentum rows of `D` in `(r, j)` by their `P` combinations and the
    /// first-order equations `Wᵀ R_D`; returns the size of the terms of `R_D`.
    fn replace_rows(&self, v: &SVector<f64, N>, r: &mut DVector<f64>, j: &mut DMatrix<f64>) -> f64 {
        let dead = self.coordinates;
        let on_dead =
            |m: &DMatrix<f64>| DMatrix::from_fn(dead.len(), m.ncols(), |a, c| m[(dead[a], c)]);
        let momentum = DVector::from_iterator(dead.len(), dead.iter().map(|&d| r[d]));
        let reached_rows = self.reached.transpose() * momentum;
        let reached_jacobian = self.reached.transpose() * on_dead(j);
        let (rows, rows_by_v, size) = (self.rows)(v);
        let equations = self.unreached.transpose() * rows;
        let equations_by_v = self.unreached.transpose() * rows_by_v;
        let reached = self.reached.ncols();
        for (k, &d) in dead.iter().enumerate() {
            j.row_mut(d).fill(0.0);
            if k < reached {
                r[d] = reached_rows[k];
                j.row_mut(d).copy_from(&reached_jacobian.row(k));
            } else {
                r[d] = equations[k - reached];
                j.view_mut((d, 0), (1, N))
                    .copy_from(&equations_by_v.row(k - reached));
            }
        }
        size
    }
}

/// The velocity of a Lagrangian linear in the velocities, `L = ϑ(q)·v − H(q)`, at `q`: its
/// momentum `ϑ(q)` does not depend on `v`, and its Euler–Lagrange equations are of first order,
/// `R(q, v) = ∂L/∂q − (∂²L/∂q∂v)ᵀ v = (ϑ'ᵀ − ϑ') v − ∇H = 0`, which Newton solves from `guess`
/// with the exact Jacobian `∂²L/∂q∂v − (∂²L/∂q∂v)ᵀ` (the third derivatives of a Lagrangian
/// linear in `v` vanish there). `newton` must be sized for `N` unknowns; a singular `ϑ'ᵀ − ϑ'`
/// (a symplectic form that degenerates) fails as a singular Jacobian.
pub(crate) fn first_order_velocity<S: DiracSystem<N>, const N: usize>(
    system: &S,
    newton: &mut Newton,
    q: &SVector<f64, N>,
    guess: &SVector<f64, N>,
) -> Result<SVector<f64, N>, NewtonFailure> {
    let mut x = DVector::from_column_slice(guess.as_slice());
    newton.solve(&mut x, |x, r, j| {
        let v = SVector::<f64, N>::from_column_slice(x.as_slice());
        let l = seeded(system, q, &v, Seed::POSITION, Seed::VELOCITY);
        let transport = l.mixed.transpose() * v;
        r.copy_from(&(l.first - transport));
        if let Some(j) = j {
            j.copy_from(&(l.mixed - l.mixed.transpose()));
        }
        l.first.abs().sup(&transport.abs()).amax()
    })?;
    Ok(SVector::from_column_slice(x.as_slice()))
}

#[cfg(test)]
mod tests {
    use nalgebra::{SMatrix, vector};

    use super::*;
    use crate::base::scalar::Scalar;
    use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
    use crate::solve::newton::NewtonOptions;

    /// `L = f(v) − q²/2` on one coordinate, with its derivatives in closed form.
    #[derive(Debug, Clone, Copy)]
    enum Speed {
        /// `f = cosh`: `p = sinh v`, not quadratic.
        Cosh,
        /// `f = v³/3`: `∂²L/∂v² = 2v` vanishes at `v = 0`.
        Cube,
    }

    impl Speed {
        /// `(f′(v), f″(v))`.
        fn derivatives(self, v: f64) -> (f64, f64) {
            match self {
                Speed::Cosh => (v.sinh(), v.cosh()),
                Speed::Cube => (v * v, 2.0 * v),
            }
        }
    }

    impl DiracSystem<1> for Speed {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
            let f = match self {
                Speed::Cosh => v[0].cosh(),
                Speed::Cube => v[0] * v[0] * v[0] / 3.0,
            };
            f - q[0] * q[0] * 0.5
        }
        fn lagrangian_gradient(
            &self,
            q: &SVector<f64, 1>,
            v: &SVector<f64, 1>,
        ) -> Option<LagrangianGradient<1>> {
            let value = self.lagrangian(q, v);
            let v = vector![self.derivatives(v[0]).0];
            Some(LagrangianGradient { value, q: -q, v })
        }
        fn lagrangian_hessian(
            &self,
            q: &SVector<f64, 1>,
            v: &SVector<f64, 1>,
        ) -> Option<LagrangianHessian<1>> {
            Some(LagrangianHessian {
                gradient: self.lagrangian_gradient(q, v)?,
                qq: SMatrix::from_element(-1.0),
                qv: SMatrix::zeros(),
                vv: SMatrix::from_element(self.derivatives(v[0]).1),
            })
        }
    }

    /// `L = ½ vᵀMv − q₀ q₁` in closed form: quadratic in the velocities.
    struct Quadratic(SMatrix<f64, 2, 2>);

    impl DiracSystem<2> for Quadratic {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
            let m = &self.0;
            (v[0] * v[0] * m[(0, 0)]
                + v[0] * v[1] * (m[(0, 1)] + m[(1, 0)])
                + v[1] * v[1] * m[(1, 1)])
                * 0.5
                - q[0] * q[1]
        }
        fn lagrangian_gradient(
            &self,
            q: &SVector<f64, 2>,
            v: &SVector<f64, 2>,
        ) -> Option<LagrangianGradient<2>> {
            Some(LagrangianGradient {
                value: self.lagrangian(q, v),
                q: vector![-q[1], -q[0]],
                v: self.0 * v,
            })
        }
        fn lagrangian_hessian(
            &self,
            q: &SVector<f64, 2>,
            v: &SVector<f64, 2>,
        ) -> Option<LagrangianHessian<2>> {
            Some(LagrangianHessian {
                gradient: self.lagrangian_gradient(q, v)?,
                qq: SMatrix::<f64, 2, 2>::new(0.0, -1.0, -1.0, 0.0),
                qv: SMatrix::zeros(),
                vv: self.0,
            })
        }
    }

    fn newton(n: usize) -> Newton {
        Newton::new(n, NewtonOptions::default()).unwrap()
    }

    #[test]
    fn the_chord_step_inverts_a_quadratic_lagrangian_from_any_guess() {
        let mass = SMatrix::<f64, 2, 2>::new(2.0, 1.0, 1.0, 3.0);
        let (q, p) = (vector![0.3, -0.2], vector![1.0, -2.0]);
        let exact = mass.try_inverse().unwrap() * p;
        let chord = chord_velocity(&Quadratic(mass), &newton(2), &q, &p, &vector![50.0, -70.0]);
        let (v, energy) = chord.unwrap();
        assert!((v - exact).amax() < 1e-14, "{v:?} against {exact}");
        // ½ vᵀMv + q_0 q_1, and the numbers `energy` gives at that velocity.
        let closed = 0.5 * exact.dot(&(mass * exact)) + q[0] * q[1];
        assert!((energy - closed).abs() < 1e-14, "{energy} against {closed}");
        assert_eq!(energy, super::energy(&Quadratic(mass), &q, &v));
    }

    #[test]
    fn the_chord_step_is_refused_where_one_step_does_not_reach_the_root() {
        let (q, p) = (vector![0.1], vector![2.0]);
        // From 0.44 off, one Newton step on sinh v = 2 leaves v 0.09 off: not a root.
        assert_eq!(
            chord_velocity(&Speed::Cosh, &newton(1), &q, &p, &vector![1.0]),
            None
        );
        // The general solve takes over and finds it.
        let v = velocity(&Speed::Cosh, &mut newton(1), &q, &p, &vector![1.0], &[]).unwrap();
        assert!((v[0] - 2.0_f64.asinh()).abs() < 1e-15);
        // From a guess 1e-9 off, one step is at round-off from the root: accepted.
        let close = vector![2.0_f64.asinh() + 1e-9];
        let (v, _) = chord_velocity(&Speed::Cosh, &newton(1), &q, &p, &close).unwrap();
        assert!((v[0] - 2.0_f64.asinh()).abs() < 1e-15);
    }

    #[test]
    fn the_chord_step_is_refused_where_its_correction_is_not_at_round_off() {
        let (q, p) = (vector![0.1], vector![2.0]);
        let root = 2.0_f64.asinh();
        // From 4.5e-7 off, one step lands about 1e-13 off: the residual (~2e-13) is within the
        // tolerance (1e-12 of |p| = 2), but the correction there is not round-off.
        let guess = vector![root + 4.5e-7];
        assert_eq!(
            chord_velocity(&Speed::Cosh, &newton(1), &q, &p, &guess),
            None
        );
        let one_step = guess[0] - (guess[0].sinh() - p[0]) / guess[0].cosh();
        let residual = (one_step.sinh() - p[0]).abs();
        assert!(
            residual < 1e-12 * p[0] && (one_step - root).abs() > 1e-14,
            "{residual:e}"
        );
    }

    #[test]
    fn the_chord_step_leaves_ill_conditioned_and_singular_hessians_to_the_general_solve() {
        // ∂²L/∂v² = diag(1, 1e-14): invertible, but beyond the singular tolerance.
        let stiff = Quadratic(SMatrix::<f64, 2, 2>::new(1.0, 0.0, 0.0, 1e-14));
        let (q, p) = (vector![0.0, 0.0], vector![1.0, 1e-14]);
        assert_eq!(
            chord_velocity(&stiff, &newton(2), &q, &p, &vector![0.0, 0.0]),
            None
        );
        // ∂²L/∂v² = 2v vanishes at the guess v = 0: no inverse.
        let flat = chord_velocity(
            &Speed::Cube,
            &newton(1),
            &vector![0.0],
            &vector![4.0],
            &vector![0.0],
        );
        assert_eq!(flat, None);
    }
}

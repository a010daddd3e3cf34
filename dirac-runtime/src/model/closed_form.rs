//! The Lagrangian's first and second derivatives in closed form, where a model has them.
//!
//! `#[dirac_system]` derives them at compile time from a Lagrangian written as an expression
//! (a graph of its operations differentiated by the chain rule, emitted as straight-line `f64`
//! code), and [`DiracSystem::lagrangian_gradient`] and [`DiracSystem::lagrangian_hessian`]
//! return them. The runtime then takes them instead of evaluating `L` over dual numbers; third
//! derivatives and Lagrangians read in a curved chart still use dual numbers. A model written by
//! hand may implement them too: a stepper compares them with dual numbers at the start of every
//! run and refuses a model whose closed forms disagree (see [`check`]).

use nalgebra::{SMatrix, SVector};

use crate::base::error::DiracError;
use crate::base::float::exceeds;
use crate::model::derivatives::{PhaseFunction, Seed, seeded_by_duals};
use crate::model::system::DiracSystem;

/// `L` and its first derivatives at one `(q, v)`.
///
/// A model written by hand supplies them like this (and a stepper checks them at its start):
///
/// ```
/// use dirac_runtime::{DiracSystem, LagrangianGradient, Scalar, closed_form};
/// use nalgebra::{SVector, vector};
///
/// /// L = (v² − q²)/2.
/// struct Oscillator;
///
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
///     fn lagrangian_gradient(
///         &self,
///         q: &SVector<f64, 1>,
///         v: &SVector<f64, 1>,
///     ) -> Option<LagrangianGradient<1>> {
///         Some(LagrangianGradient { value: (v[0] * v[0] - q[0] * q[0]) * 0.5, q: -q, v: *v })
///     }
/// }
///
/// assert!(closed_form::check(&Oscillator, &vector![0.3], &vector![0.7]).is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagrangianGradient<const N: usize> {
    /// `L(q, v)`.
    pub value: f64,
    /// `∂L/∂q`.
    pub q: SVector<f64, N>,
    /// `∂L/∂v`.
    pub v: SVector<f64, N>,
}

/// `L` with its first and second derivatives at one `(q, v)`.
///
/// ```
/// use dirac_runtime::{DiracError, DiracSystem, LagrangianGradient, LagrangianHessian, Scalar};
/// use dirac_runtime::closed_form;
/// use nalgebra::{SMatrix, SVector, vector};
///
/// /// L = (v² − q²)/2, with a sign slip in its hand-written ∂²L/∂q².
/// struct Slip;
///
/// impl DiracSystem<1> for Slip {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
///     fn lagrangian_hessian(
///         &self,
///         q: &SVector<f64, 1>,
///         v: &SVector<f64, 1>,
///     ) -> Option<LagrangianHessian<1>> {
///         Some(LagrangianHessian {
///             gradient: LagrangianGradient {
///                 value: (v[0] * v[0] - q[0] * q[0]) * 0.5,
///                 q: -q,
///                 v: *v,
///             },
///             qq: SMatrix::identity(), // should be −1
///             qv: SMatrix::zeros(),
///             vv: SMatrix::identity(),
///         })
///     }
/// }
///
/// let refused = closed_form::check(&Slip, &vector![0.3], &vector![0.7]);
/// assert!(matches!(refused, Err(DiracError::InconsistentDerivatives(_))));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagrangianHessian<const N: usize> {
    /// `L`, `∂L/∂q`, `∂L/∂v`.
    pub gradient: LagrangianGradient<N>,
    /// `∂²L/∂q²`.
    pub qq: SMatrix<f64, N, N>,
    /// `∂²L/∂q∂v`: entry `(i, j)` is `∂²L/∂q_i∂v_j`.
    pub qv: SMatrix<f64, N, N>,
    /// `∂²L/∂v²`.
    pub vv: SMatrix<f64, N, N>,
}

impl<const N: usize> LagrangianGradient<N> {
    /// `L = 0` with zero gradient: the start of a sum over a model's parts.
    pub fn zero() -> Self {
        Self {
            value: 0.0,
            q: SVector::zeros(),
            v: SVector::zeros(),
        }
    }
}

impl<const N: usize> LagrangianHessian<N> {
    /// `L = 0` with zero derivatives: the start of a sum over a model's parts.
    pub fn zero() -> Self {
        Self {
            gradient: LagrangianGradient::zero(),
            qq: SMatrix::zeros(),
            qv: SMatrix::zeros(),
            vv: SMatrix::zeros(),
        }
    }
}

/// Which entries of the Lagrangian's Hessian vanish identically: `#[dirac_system]` reads them off
/// the expression (`∂²L/∂q∂v = 0` for `L = T(v) − V(q)`, `∂²L/∂q² = 0` for a potential linear in
/// `q`, `∂²L/∂v_i∂v_j = 0` off the diagonal of a diagonal mass matrix), and a step skips their
/// products. A stepper checks the claim at the start of every run ([`check`]).
///
/// ```
/// use dirac_runtime::HessianZeros;
///
/// // L = ½ (v₀² + v₁²) − V(q₀) − W(q₁): ∂²L/∂q∂v vanishes, ∂²L/∂q² and ∂²L/∂v² are diagonal.
/// let diagonal = [[false, true], [true, false]];
/// let zeros = HessianZeros::<2> { qq: diagonal, qv: [[true; 2]; 2], vv: diagonal };
/// assert!(zeros.vanishes(0, 1) && !zeros.vanishes(0, 0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HessianZeros<const N: usize> {
    /// `qq[i][j]`: `∂²L/∂q_i∂q_j = 0` everywhere.
    pub qq: [[bool; N]; N],
    /// `qv[i][j]`: `∂²L/∂q_i∂v_j = 0` everywhere.
    pub qv: [[bool; N]; N],
    /// `vv[i][j]`: `∂²L/∂v_i∂v_j = 0` everywhere.
    pub vv: [[bool; N]; N],
}

impl<const N: usize> HessianZeros<N> {
    /// No entry known to vanish.
    pub const NONE: Self = Self {
        qq: [[false; N]; N],
        qv: [[false; N]; N],
        vv: [[false; N]; N],
    };

    /// Whether entry `(i, j)` of every block a step combines vanishes: `∂²L/∂q_i∂q_j`,
    /// `∂²L/∂q_i∂v_j`, `∂²L/∂q_j∂v_i` and `∂²L/∂v_i∂v_j`, so that any weighted sum of the
    /// blocks (`∂²L/∂q∂v` and its transpose among them) is zero there.
    ///
    /// # Panics
    /// Where `i` or `j` is not below `N`.
    pub const fn vanishes(&self, i: usize, j: usize) -> bool {
        self.qq[i][j] && self.qv[i][j] && self.qv[j][i] && self.vv[i][j]
    }
}

/// Relative disagreement with dual numbers beyond which closed forms are refused.
const TOLERANCE: f64 = 1e-8;

/// Compares the model's closed forms, where it has them, with dual numbers at `(q, v)`: an
/// `Err(InconsistentDerivatives)` naming the first derivative that differs by more than `1e-8`
/// of the largest of its kind. Points where the Lagrangian is not finite are not judged. The
/// one-forms' closed forms ([`DiracSystem::one_form_with_derivative`]) are compared at `q` the
/// same way, the row and every entry of its derivative, those the model leaves out being zero.
/// A Hessian entry claimed to vanish ([`DiracSystem::LAGRANGIAN_HESSIAN_ZEROS`]) must vanish
/// under dual numbers at `(q, v)`.
pub fn check<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> Result<(), DiracError> {
    check_one_forms(system, q)?;
    let zeros = S::LAGRANGIAN_HESSIAN_ZEROS;
    let gradient = system.lagrangian_gradient(q, v);
    let hessian = system.lagrangian_hessian(q, v);
    if gradient.is_none() && hessian.is_none() && zeros == HessianZeros::NONE {
        return Ok(());
    }
    let reference = by_duals(system, q, v);
    for (claimed, block, name) in [
        (&zeros.qq, &reference.qq, ["q", "q"]),
        (&zeros.qv, &reference.qv, ["q", "v"]),
        (&zeros.vv, &reference.vv, ["v", "v"]),
    ] {
        for (i, j) in (0..N).flat_map(|i| (0..N).map(move |j| (i, j))) {
            // Not judged where the dual numbers are not finite (as the comparisons below).
            let entry = block[(i, j)];
            if claimed[i][j] && entry.is_finite() && entry != 0.0 {
                let [x, y] = name;
                return Err(DiracError::InconsistentDerivatives(format!(
                    "∂²L/∂{x}_{i}∂{y}_{j} is said to vanish (LAGRANGIAN_HESSIAN_ZEROS), but dual \
                     numbers give {} at q = {:?}, v = {:?}",
                    entry,
                    q.as_slice(),
                    v.as_slice()
                )));
            }
        }
    }
    let at = format!("q = {:?}, v = {:?}", q.as_slice(), v.as_slice());
    compare(gradient, hessian, &reference, &at)
}

/// `L`, its gradient and its Hessian blocks at `(q, v)` by dual numbers alone.
fn by_duals<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> LagrangianHessian<N> {
    let qv = seeded_by_duals(lagrangian, q, v, Seed::POSITION, Seed::VELOCITY);
    LagrangianHessian {
        gradient: LagrangianGradient {
            value: qv.value,
            q: qv.first,
            v: qv.second,
        },
        qq: seeded_by_duals(lagrangian, q, v, Seed::POSITION, Seed::POSITION).mixed,
        qv: qv.mixed,
        vv: seeded_by_duals(lagrangian, q, v, Seed::VELOCITY, Seed::VELOCITY).mixed,
    }
}

/// The closed forms of `lagrangian` at `(q, v)`, where it has them, against its dual numbers
/// (see [`check`]); `at` names the point in the error.
pub(crate) fn check_function<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    at: &str,
) -> Result<(), DiracError> {
    let gradient = lagrangian.closed_gradient(q, v);
    let hessian = lagrangian.closed_hessian(q, v);
    if gradient.is_none() && hessian.is_none() {
        return Ok(());
    }
    compare(gradient, hessian, &by_duals(lagrangian, q, v), at)
}

/// Closed forms against `reference`, the first entry beyond the tolerance named.
fn compare<const N: usize>(
    gradient: Option<LagrangianGradient<N>>,
    hessian: Option<LagrangianHessian<N>>,
    reference: &LagrangianHessian<N>,
    at: &str,
) -> Result<(), DiracError> {
    let first = |g: &LagrangianGradient<N>| {
        let mut all = vec![g.value];
        all.extend(g.q.iter().chain(g.v.iter()));
        all
    };
    let second = |h: &LagrangianHessian<N>| {
        h.qq.iter()
            .chain(h.qv.iter())
            .chain(h.vv.iter())
            .copied()
            .collect::<Vec<_>>()
    };
    let compare =
        |what: &str, closed: Vec<f64>, duals: Vec<f64>| match disagreement(&closed, &duals) {
            None => Ok(()),
            Some(k) => Err(DiracError::InconsistentDerivatives(format!(
                "the closed-form {what} of the Lagrangian differs from dual numbers at {at}: \
                 entry {k} is {} against {}",
                closed[k], duals[k]
            ))),
        };
    if let Some(g) = gradient {
        compare("gradient", first(&g), first(&reference.gradient))?;
    }
    if let Some(h) = hessian {
        compare("gradient", first(&h.gradient), first(&reference.gradient))?;
        compare("Hessian", second(&h), second(reference))?;
    }
    Ok(())
}

/// The one-forms' closed-form derivatives against dual numbers at `q` (see [`check`]).
fn check_one_forms<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
) -> Result<(), DiracError> {
    if !S::ONE_FORM_DERIVATIVES {
        return Ok(());
    }
    for a in 0..S::ONE_FORMS {
        let mut closed = SMatrix::<f64, N, N>::zeros();
        let mut outside = None;
        let closed_row = system.one_form_with_derivative(q, a, |i, j, x| match (i < N, j < N) {
            (true, true) => closed[(i, j)] += x,
            _ => outside = Some((i, j)),
        });
        let name = system.one_form_name(a);
        if let Some((i, j)) = outside {
            return Err(DiracError::InconsistentDerivatives(format!(
                "the closed-form derivative of {name} names entry ({i}, {j}), outside {N} × {N}"
            )));
        }
        let row = system.one_form(&crate::model::derivatives::lift(q, 1.0), a);
        let values = row.map(|x| x.re);
        if let Some(i) = disagreement(closed_row.as_slice(), values.as_slice()) {
            return Err(DiracError::InconsistentDerivatives(format!(
                "the closed-form row of {name} differs from `one_form` at q = {:?}: \
                 A_{i} is {} against {}",
                q.as_slice(),
                closed_row[i],
                values[i]
            )));
        }
        let duals =
            SMatrix::<f64, N, N>::from_fn(|i, j| crate::model::derivatives::gradient(&row[i])[j]);
        if let Some(k) = disagreement(closed.as_slice(), duals.as_slice()) {
            // Column-major: entry k is (k mod N, k div N).
            let (i, j) = (k % N, k / N);
            return Err(DiracError::InconsistentDerivatives(format!(
                "the closed-form derivative of {name} differs from dual numbers at q = {:?}: \
                 ∂A_{i}/∂q_{j} is {} against {}",
                q.as_slice(),
                closed[(i, j)],
                duals[(i, j)]
            )));
        }
    }
    Ok(())
}

/// The first entry where `closed` differs from `duals` by more than `1e-8` of the largest of
/// `duals`, or `None` (also where `duals` are not finite: such a point is not judged). A
/// difference that is NaN (a closed form NaN where the duals are finite) disagrees.
fn disagreement(closed: &[f64], duals: &[f64]) -> Option<usize> {
    if !duals.iter().all(|x| x.is_finite()) {
        return None;
    }
    let scale = duals.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let bound = TOLERANCE * scale.max(f64::MIN_POSITIVE);
    closed
        .iter()
        .zip(duals)
        .position(|(a, b)| exceeds((a - b).abs(), bound))
}

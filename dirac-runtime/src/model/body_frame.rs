//! The closed forms of a Lagrangian on `Rᴷ × SO(3)ᴬ`, read in the body frame.
//!
//! On a model with rotations, [`lagrangian_gradient`] and [`lagrangian_hessian`] give the
//! derivatives along `R exp(ŵ)` on each rotation (`x + w` on the vectors) and along the rates
//! `(ẋ, Ω)` themselves:
//!
//! ```text
//! g_k = ∂/∂w_k L(R exp(ŵ), Ω),   H_kl = ∂²/∂w_k∂w_l L(R exp(ŵ), Ω)   at w = 0,
//! ```
//!
//! the second derivative symmetric by its definition. `#[dirac_system]` writes them from the
//! Lagrangian's derivatives in the entries of the matrices `R` (closed forms of the expression
//! it lowers to), which [`BodyFrame`] turns into body-frame ones: with `G = ∂L/∂R`, an entry
//! `R_rc` moves along `w` by `(e_c × r_r) · w` (`r_r` the row `r` of `R`), so
//!
//! ```text
//! g = vee(RᵀG),   H = Tᵀ (∂²L/∂R²) T + ½ (M + Mᵀ) − tr(M) I,   M = RᵀG,
//! ```
//!
//! the last terms from `exp(ŵ) = I + ŵ + ŵ²/2 + …` and `ê_k ê_l = e_l e_kᵀ − δ_kl I`.
//!
//! [`lagrangian_gradient`]: crate::model::system::DiracSystem::lagrangian_gradient
//! [`lagrangian_hessian`]: crate::model::system::DiracSystem::lagrangian_hessian

use nalgebra::{Matrix3, SVector, Vector3};

use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
use crate::space::product::Configuration;

/// Collects a Lagrangian's derivatives in the entries of its rotation matrices and its
/// coordinates into its body-frame closed forms on `Rᴷ × SO(3)ᴬ` (see the [module](self)).
///
/// Positions are numbered as the generated code numbers them: the `K` vectors' coordinates,
/// then the nine entries `R_rc` of each rotation (at `K + 9a + 3r + c`); rates as the chart
/// numbers them: the `K` velocities, then each rotation's `Ω` (at `K + 3a + c`).
///
/// ```
/// use dirac_runtime::body_frame::BodyFrame;
/// use dirac_runtime::product::Configuration;
/// use dirac_runtime::rotation::Retraction;
/// use nalgebra::vector;
///
/// // L = −R₂₂ (a potential −e₃ᵀ R e₃): ∂L/∂R₂₂ = −1 at position 0 + 9·0 + 3·2 + 2 = 8.
/// let r = Retraction::Exp.map(&vector![0.3, -0.2, 0.1]);
/// let q = Configuration::<f64, 0, 1, 0>::of_rotation(r);
/// let mut forms = BodyFrame::<3, 0, 1>::new(&q, -r[(2, 2)]);
/// forms.position(8, -1.0);
/// let hessian = forms.hessian();
/// // ∂/∂w L(R exp(ŵ)) = −(R ê_k)₂₂: the body-frame gradient is −(e₂ × row₂(R)).
/// let expected = -vector![0.0, 0.0, 1.0].cross(&r.row(2).transpose());
/// assert!((hessian.gradient.q - expected).amax() < 1e-15);
/// ```
#[derive(Debug, Clone)]
pub struct BodyFrame<'a, const N: usize, const K: usize, const A: usize> {
    q: &'a Configuration<f64, K, A, 0>,
    forms: LagrangianHessian<N>,
    /// `∂L/∂R` of each rotation.
    ambient: [Matrix3<f64>; A],
}

/// Where a position moves the chart's coordinates: a vector's own (index, weight 1) or a
/// rotation entry's `e_c × r_r` on its rotation's three.
enum Direction {
    Vector(usize),
    Rotation(usize, Vector3<f64>),
}

impl<'a, const N: usize, const K: usize, const A: usize> BodyFrame<'a, N, K, A> {
    /// Starts the forms of a Lagrangian with value `value` at `q`, every derivative zero.
    pub fn new(q: &'a Configuration<f64, K, A, 0>, value: f64) -> Self {
        const { assert!(N == K + 3 * A, "N = K + 3A on Rᴷ × SO(3)ᴬ") };
        let mut forms = LagrangianHessian::zero();
        forms.gradient.value = value;
        Self {
            q,
            forms,
            ambient: [Matrix3::zeros(); A],
        }
    }

    fn direction(&self, i: usize) -> Direction {
        if i < K {
            return Direction::Vector(i);
        }
        let (a, entry) = ((i - K) / 9, (i - K) % 9);
        let (r, c) = (entry / 3, entry % 3);
        let row = self.q.rotation[a].row(r).transpose();
        Direction::Rotation(K + 3 * a, Vector3::ith(c, 1.0).cross(&row))
    }

    /// Adds `x·(direction)` to the chart vector `out`.
    fn add(out: &mut SVector<f64, N>, direction: &Direction, x: f64) {
        match direction {
            Direction::Vector(i) => out[*i] += x,
            Direction::Rotation(at, t) => {
                for k in 0..3 {
                    out[at + k] += x * t[k];
                }
            }
        }
    }

    /// `∂L/∂(position i)` is `x`.
    pub fn position(&mut self, i: usize, x: f64) {
        if i >= K {
            let (a, entry) = ((i - K) / 9, (i - K) % 9);
            self.ambient[a][(entry / 3, entry % 3)] += x;
        }
        let direction = self.direction(i);
        Self::add(&mut self.forms.gradient.q, &direction, x);
    }

    /// `∂L/∂(rate j)` is `x`.
    pub fn velocity(&mut self, j: usize, x: f64) {
        self.forms.gradient.v[j] += x;
    }

    /// `∂²L/∂(position i)∂(position j)` is `x`, given once for `i ≤ j`.
    pub fn position_position(&mut self, i: usize, j: usize, x: f64) {
        let (di, dj) = (self.direction(i), self.direction(j));
        let mut ti = SVector::<f64, N>::zeros();
        let mut tj = SVector::<f64, N>::zeros();
        Self::add(&mut ti, &di, 1.0);
        Self::add(&mut tj, &dj, 1.0);
        self.forms.qq += ti * tj.transpose() * x;
        if i != j {
            self.forms.qq += tj * ti.transpose() * x;
        }
    }

    /// `∂²L/∂(position i)∂(rate j)` is `x`.
    pub fn position_velocity(&mut self, i: usize, j: usize, x: f64) {
        let direction = self.direction(i);
        let mut column = self.forms.qv.column(j).into_owned();
        Self::add(&mut column, &direction, x);
        self.forms.qv.set_column(j, &column);
    }

    /// `∂²L/∂(rate i)∂(rate j)` is `x`, given once for `i ≤ j`.
    pub fn velocity_velocity(&mut self, i: usize, j: usize, x: f64) {
        self.forms.vv[(i, j)] += x;
        if i != j {
            self.forms.vv[(j, i)] += x;
        }
    }

    /// `L` and its body-frame gradient.
    pub fn gradient(self) -> LagrangianGradient<N> {
        self.forms.gradient
    }

    /// `L` with its body-frame first and second derivatives.
    pub fn hessian(self) -> LagrangianHessian<N> {
        let mut forms = self.forms;
        for (a, g) in self.ambient.iter().enumerate() {
            let m = self.q.rotation[a].transpose() * g;
            let curvature = (m + m.transpose()) * 0.5 - Matrix3::identity() * m.trace();
            let at = K + 3 * a;
            let mut block = forms.qq.fixed_view_mut::<3, 3>(at, at);
            block += curvature;
        }
        forms
    }
}

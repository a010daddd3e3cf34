//! Quadratures that turn a continuous Lagrangian into a discrete one.
//!
//! Every quadrature here is a Galerkin discretisation: the path on one step is the polynomial of
//! degree `s` through `q_k`, `s − 1` internal points and `q_{k+1}` (equispaced in time), and the action
//! integral is approximated by an `r`-point rule on `[0, 1]`,
//!
//! ```text
//! L_d(Q_0, …, Q_s) = h Σ_i b_i L( Σ_j ℓ_j(c_i) Q_j , (1/h) Σ_j ℓ'_j(c_i) Q_j ).
//! ```
//!
//! The midpoint rule is degree 1 with the 1-point Gauss–Legendre rule, the trapezoid rule degree 1
//! with the 2-point Gauss–Lobatto rule. Measured orders are in `docs/mathematics.md` and asserted in
//! `tests/suite/convergence.rs`.

use nalgebra::SVector;

use crate::base::error::DiracError;

/// The quadrature rule on `[0, 1]` used to integrate the Lagrangian along one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Rule {
    /// Gauss–Legendre with this many nodes (interior nodes only).
    GaussLegendre(usize),
    /// Gauss–Lobatto with this many nodes (both end points included; at least 2).
    GaussLobatto(usize),
}

/// A quadrature of the action over one step: interpolation degree, rule, and the tables the
/// discrete Lagrangian needs (nodes, weights, basis values and derivatives at the nodes).
///
/// ```
/// use dirac_runtime::{Quadrature, Rule};
/// let q = Quadrature::galerkin_with_rule(2, Rule::GaussLegendre(2))?;
/// assert_eq!(q.degree(), 2);
/// assert_eq!(q.name(), "galerkin(2)");
/// let lobatto = Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3))?;
/// assert_eq!(lobatto.name(), "galerkin(2, gauss_lobatto(3))");
/// assert!((q.weights().iter().sum::<f64>() - 1.0).abs() < 1e-15);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "QuadratureSpec", into = "QuadratureSpec")
)]
pub struct Quadrature {
    degree: usize,
    rule: Rule,
    nodes: Vec<f64>,
    weights: Vec<f64>,
    /// `basis[i * (s + 1) + j] = ℓ_j(c_i)`.
    basis: Vec<f64>,
    /// `basis_derivative[i * (s + 1) + j] = ℓ'_j(c_i)` (derivative in unit time).
    basis_derivative: Vec<f64>,
}

/// Highest interpolation degree accepted: equispaced interpolation is well conditioned up to here.
pub const MAX_DEGREE: usize = 8;
/// Most quadrature nodes accepted.
pub const MAX_NODES: usize = 16;

impl Quadrature {
    /// `L_d = h L((q0 + q1)/2, (q1 − q0)/h)`: second order, symmetric.
    ///
    /// ```
    /// let q = dirac_runtime::Quadrature::midpoint();
    /// assert_eq!(q.nodes(), &[0.5]);
    /// ```
    pub fn midpoint() -> Self {
        Self::build(1, Rule::GaussLegendre(1))
    }

    /// `L_d = (h/2)[L(q0, (q1 − q0)/h) + L(q1, (q1 − q0)/h)]`: second order (Störmer–Verlet for
    /// separable Lagrangians).
    ///
    /// ```
    /// let q = dirac_runtime::Quadrature::trapezoid();
    /// assert_eq!(q.nodes(), &[0.0, 1.0]);
    /// ```
    pub fn trapezoid() -> Self {
        Self::build(1, Rule::GaussLobatto(2))
    }

    /// Galerkin discretisation of degree `degree` with the given rule.
    ///
    /// The rule must have enough nodes to determine the internal points: at least `degree`
    /// Gauss–Legendre nodes or `degree + 1` Gauss–Lobatto nodes.
    ///
    /// ```
    /// use dirac_runtime::{Quadrature, Rule};
    /// assert!(Quadrature::galerkin_with_rule(3, Rule::GaussLegendre(3)).is_ok());
    /// assert!(Quadrature::galerkin_with_rule(3, Rule::GaussLegendre(2)).is_err());
    /// ```
    pub fn galerkin_with_rule(degree: usize, rule: Rule) -> Result<Self, DiracError> {
        let invalid = |msg: String| Err(DiracError::InvalidQuadrature(msg));
        if degree == 0 || degree > MAX_DEGREE {
            return invalid(format!(
                "the degree must be between 1 and {MAX_DEGREE}, got {degree}"
            ));
        }
        let (nodes, needed) = match rule {
            Rule::GaussLegendre(r) => (r, degree),
            Rule::GaussLobatto(r) => (r, degree + 1),
        };
        if nodes > MAX_NODES {
            return invalid(format!(
                "at most {MAX_NODES} nodes are supported, got {nodes}"
            ));
        }
        if nodes < needed {
            return invalid(format!(
                "degree {degree} needs at least {needed} nodes of this rule to determine its \
                 {} internal point(s), got {nodes}",
                degree - 1
            ));
        }
        Ok(Self::build(degree, rule))
    }

    /// The Galerkin method of degree `s` with `s` Gauss–Legendre nodes (order `2s`): the
    /// attribute's `galerkin(s)`.
    ///
    /// ```
    /// let q = dirac_runtime::Quadrature::galerkin(2)?;
    /// assert_eq!(q.internal_points(), 1);
    /// assert_eq!(q.name(), "galerkin(2)");
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn galerkin(degree: usize) -> Result<Self, DiracError> {
        Self::galerkin_with_rule(degree, Rule::GaussLegendre(degree))
    }

    fn build(degree: usize, rule: Rule) -> Self {
        let (nodes, weights) = match rule {
            Rule::GaussLegendre(r) => gauss_legendre(r),
            Rule::GaussLobatto(r) => gauss_lobatto(r),
        };
        let points: Vec<f64> = (0..=degree).map(|j| j as f64 / degree as f64).collect();
        let mut basis = Vec::with_capacity(nodes.len() * (degree + 1));
        let mut basis_derivative = Vec::with_capacity(nodes.len() * (degree + 1));
        for &c in &nodes {
            for j in 0..=degree {
                basis.push(lagrange(&points, j, c));
                basis_derivative.push(lagrange_derivative(&points, j, c));
            }
        }
        Self {
            degree,
            rule,
            nodes,
            weights,
            basis,
            basis_derivative,
        }
    }

    /// Interpolation degree `s`: the path on a step is a polynomial of this degree.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Number of internal points `s − 1`, extra unknowns of each step.
    pub fn internal_points(&self) -> usize {
        self.degree - 1
    }

    /// The rule integrating the action.
    pub fn rule(&self) -> Rule {
        self.rule
    }

    /// Quadrature nodes `c_i` in `[0, 1]`.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Quadrature weights `b_i`, summing to 1.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// `ℓ_j(c_i)`: the weight of point `j` (`0..=degree`) in the position at node `i`; `None`
    /// outside the table.
    ///
    /// ```
    /// let q = dirac_runtime::Quadrature::midpoint();
    /// assert_eq!(q.basis(0, 1), Some(0.5));
    /// assert_eq!(q.basis(5, 5), None);
    /// ```
    pub fn basis(&self, node: usize, point: usize) -> Option<f64> {
        self.index(node, point).map(|k| self.basis[k])
    }

    /// `ℓ'_j(c_i)`: the weight of point `j` in `h` times the velocity at node `i`; `None` outside
    /// the table.
    pub fn basis_derivative(&self, node: usize, point: usize) -> Option<f64> {
        self.index(node, point).map(|k| self.basis_derivative[k])
    }

    fn index(&self, node: usize, point: usize) -> Option<usize> {
        (node < self.nodes.len() && point <= self.degree).then(|| node * (self.degree + 1) + point)
    }

    /// `ℓ_j(c_i)` for indices the caller keeps in range (the step's loops).
    pub(crate) fn ell(&self, node: usize, point: usize) -> f64 {
        self.basis[node * (self.degree + 1) + point]
    }

    /// `ℓ'_j(c_i)` for indices the caller keeps in range.
    pub(crate) fn ell_prime(&self, node: usize, point: usize) -> f64 {
        self.basis_derivative[node * (self.degree + 1) + point]
    }

    /// The path through `0, increments[0], …, increments[s−1]` at node `i`: its value
    /// `Σ_j ℓ_j(c_i) ξ_j` and its rate `Σ_j ℓ'_j(c_i) ξ_j / h` (for indices the caller keeps in
    /// range).
    pub(crate) fn path_at<const N: usize>(
        &self,
        node: usize,
        increments: &[SVector<f64, N>],
        h: f64,
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        let points = 1..=increments.len();
        path_sums(
            increments,
            points.clone().map(|j| self.ell(node, j)),
            points.map(|j| self.ell_prime(node, j) / h),
        )
    }

    /// The path through `0, points[0], …, points[s−1]` (equispaced in `[0, 1]`) at any fraction
    /// `theta` of the step: its value and its rate in time (dense output).
    pub(crate) fn path_through<const N: usize>(
        &self,
        theta: f64,
        points: &[SVector<f64, N>],
        h: f64,
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        // The equispaced grid, on the stack.
        let mut grid = [0.0; MAX_DEGREE + 1];
        for (j, x) in grid.iter_mut().enumerate().take(self.degree + 1) {
            *x = j as f64 / self.degree as f64;
        }
        let grid = &grid[..=self.degree];
        let mut xi = SVector::zeros();
        let mut rate = SVector::zeros();
        for (j, z) in points.iter().enumerate() {
            xi += z * lagrange(grid, j + 1, theta);
            rate += z * (lagrange_derivative(grid, j + 1, theta) / h);
        }
        (xi, rate)
    }

    /// A short name in the attribute's syntax: `midpoint`, `trapezoid`, `galerkin(s)` or
    /// `galerkin(s, rule(r))`.
    pub fn name(&self) -> String {
        match (self.degree, self.rule) {
            (1, Rule::GaussLegendre(1)) => "midpoint".into(),
            (1, Rule::GaussLobatto(2)) => "trapezoid".into(),
            (s, Rule::GaussLegendre(r)) if s == r => format!("galerkin({s})"),
            (s, Rule::GaussLegendre(r)) => format!("galerkin({s}, gauss_legendre({r}))"),
            (s, Rule::GaussLobatto(r)) => format!("galerkin({s}, gauss_lobatto({r}))"),
        }
    }
}

/// What a quadrature is serialized as: its degree and rule (the tables are rebuilt, and checked,
/// when it is read back).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
struct QuadratureSpec {
    degree: usize,
    rule: Rule,
}

#[cfg(feature = "serde")]
impl TryFrom<QuadratureSpec> for Quadrature {
    type Error = DiracError;
    fn try_from(spec: QuadratureSpec) -> Result<Self, DiracError> {
        Self::galerkin_with_rule(spec.degree, spec.rule)
    }
}

#[cfg(feature = "serde")]
impl From<Quadrature> for QuadratureSpec {
    fn from(quadrature: Quadrature) -> Self {
        Self {
            degree: quadrature.degree,
            rule: quadrature.rule,
        }
    }
}

/// Lagrange basis polynomial `ℓ_j` through `points`, evaluated at `c`.
fn lagrange(points: &[f64], j: usize, c: f64) -> f64 {
    points
        .iter()
        .enumerate()
        .filter(|&(m, _)| m != j)
        .map(|(_, &tm)| (c - tm) / (points[j] - tm))
        .product()
}

/// Derivative of `ℓ_j` at `c`.
pub(crate) fn lagrange_derivative(points: &[f64], j: usize, c: f64) -> f64 {
    let tj = points[j];
    (0..points.len())
        .filter(|&l| l != j)
        .map(|l| {
            let others: f64 = (0..points.len())
                .filter(|&m| m != j && m != l)
                .map(|m| (c - points[m]) / (tj - points[m]))
                .product();
            others / (tj - points[l])
        })
        .sum()
}

/// Legendre polynomial `P_n(x)` and `P_{n−1}(x)` by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p_prev, mut p) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let next = ((2.0 * kf - 1.0) * x * p - (kf - 1.0) * p_prev) / kf;
        p_prev = p;
        p = next;
    }
    (p, p_prev)
}

/// Gauss–Legendre nodes and weights on `[0, 1]`, by Newton's method on `P_r`.
fn gauss_legendre(r: usize) -> (Vec<f64>, Vec<f64>) {
    let n = r as f64;
    let mut nodes = Vec::with_capacity(r);
    let mut weights = Vec::with_capacity(r);
    for i in 0..r {
        // Tricomi's initial guess, descending; iterate to round-off.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, p1) = legendre(r, x);
            dp = n * (x * p - p1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                let (p, p1) = legendre(r, x);
                dp = n * (x * p - p1) / (x * x - 1.0);
                break;
            }
        }
        nodes.push(0.5 * (1.0 - x));
        weights.push(1.0 / ((1.0 - x * x) * dp * dp));
    }
    (nodes, weights)
}

/// Gauss–Lobatto nodes and weights on `[0, 1]`: the end points and the roots of `P'_{r−1}`.
fn gauss_lobatto(r: usize) -> (Vec<f64>, Vec<f64>) {
    let n = r - 1;
    let nf = n as f64;
    let mut nodes = Vec::with_capacity(r);
    let mut weights = Vec::with_capacity(r);
    for i in 0..r {
        let mut x = -(std::f64::consts::PI * i as f64 / nf).cos();
        if i > 0 && i < n {
            // Newton on P'_n using (1 − x²) P''_n = 2x P'_n − n(n+1) P_n.
            for _ in 0..100 {
                let (p, p1) = legendre(n, x);
                let dp = nf * (x * p - p1) / (x * x - 1.0);
                let ddp = (2.0 * x * dp - nf * (nf + 1.0) * p) / (1.0 - x * x);
                let dx = dp / ddp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
        }
        let (p, _) = legendre(n, x);
        nodes.push(0.5 * (x + 1.0));
        weights.push(1.0 / (nf * (nf + 1.0) * p * p));
    }
    (nodes, weights)
}

/// The path through `0, increments[0], …, increments[s−1]` at one node from the basis values
/// `ℓ_j(c_i)` and rates `ℓ'_j(c_i)/h` of its points `j = 1..=s`: `(Σ_j ℓ_j ξ_j, Σ_j ℓ'_j ξ_j / h)`,
/// summed in the order of the points.
#[inline(always)]
pub(crate) fn path_sums<const N: usize>(
    increments: &[SVector<f64, N>],
    basis: impl Iterator<Item = f64>,
    rates: impl Iterator<Item = f64>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let mut xi = SVector::zeros();
    let mut rate = SVector::zeros();
    for (z, (a, d)) in increments.iter().zip(basis.zip(rates)) {
        xi += z * a;
        rate += z * d;
    }
    (xi, rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integrates `t^k` on [0, 1] with the rule.
    fn integrate(q: &Quadrature, k: i32) -> f64 {
        q.nodes()
            .iter()
            .zip(q.weights())
            .map(|(c, w)| w * c.powi(k))
            .sum()
    }

    #[test]
    fn gauss_legendre_is_exact_to_degree_2r_minus_1() {
        for r in 1..=8 {
            let q = Quadrature::galerkin_with_rule(1, Rule::GaussLegendre(r)).unwrap();
            for k in 0..(2 * r as i32) {
                let exact = 1.0 / (k as f64 + 1.0);
                assert!((integrate(&q, k) - exact).abs() < 1e-14, "r={r} k={k}");
            }
            // ... and no further: the error on t^2r is (r!)⁴/((2r+1)((2r)!)²) on [0, 1].
            let k = 2 * r as i32;
            let f = |n: usize| (1..=n).map(|i| i as f64).product::<f64>();
            let error = f(r).powi(4) / ((2 * r + 1) as f64 * f(2 * r).powi(2));
            let measured = 1.0 / (k as f64 + 1.0) - integrate(&q, k);
            assert!((measured - error).abs() < 1e-3 * error + 1e-15, "r={r}");
        }
    }

    #[test]
    fn gauss_lobatto_is_exact_to_degree_2r_minus_3() {
        for r in 2..=8 {
            let q = Quadrature::galerkin_with_rule(1, Rule::GaussLobatto(r)).unwrap();
            assert_eq!(q.nodes()[0], 0.0);
            assert!((q.nodes()[r - 1] - 1.0).abs() < 1e-15);
            for k in 0..(2 * r as i32 - 2) {
                let exact = 1.0 / (k as f64 + 1.0);
                assert!((integrate(&q, k) - exact).abs() < 1e-14, "r={r} k={k}");
            }
        }
    }

    #[test]
    fn basis_interpolates_polynomials_and_their_derivatives() {
        let q = Quadrature::galerkin(3).unwrap();
        // p(t) = 1 + 2t − t³ sampled at 0, 1/3, 2/3, 1.
        let p = |t: f64| 1.0 + 2.0 * t - t.powi(3);
        let dp = |t: f64| 2.0 - 3.0 * t * t;
        for (i, &c) in q.nodes().iter().enumerate() {
            let value: f64 = (0..=3).map(|j| q.ell(i, j) * p(j as f64 / 3.0)).sum();
            let slope: f64 = (0..=3).map(|j| q.ell_prime(i, j) * p(j as f64 / 3.0)).sum();
            assert!((value - p(c)).abs() < 1e-14);
            assert!((slope - dp(c)).abs() < 1e-13);
        }
    }

    #[test]
    fn named_rules_match_their_formulas() {
        let m = Quadrature::midpoint();
        assert_eq!((m.nodes(), m.weights()), (&[0.5][..], &[1.0][..]));
        assert_eq!(
            (m.basis(0, 0), m.basis_derivative(0, 1)),
            (Some(0.5), Some(1.0))
        );
        let t = Quadrature::trapezoid();
        assert_eq!(t.weights(), &[0.5, 0.5]);
        assert_eq!(t.name(), "trapezoid");
    }

    #[test]
    fn underdetermined_and_oversized_rules_are_rejected() {
        assert!(Quadrature::galerkin_with_rule(0, Rule::GaussLegendre(1)).is_err());
        assert!(Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(2)).is_err());
        assert!(Quadrature::galerkin_with_rule(2, Rule::GaussLegendre(MAX_NODES + 1)).is_err());
        assert!(Quadrature::galerkin_with_rule(MAX_DEGREE + 1, Rule::GaussLegendre(9)).is_err());
    }
}

//! Which step a Lagrangian linear in the velocities, `L = ϑ(q)·v − H(q)`, is advanced by.

/// Which step a Lagrangian linear in every velocity, `L = ϑ(q)·v − H(q)`, is advanced by (one
/// linear in some velocities only is always collocated on the rows of those). Both
/// keep the momentum on the primary constraint `p = ϑ(q)` at every step and reach order `2s`
/// with `galerkin(s)` (Gauss rules only); they differ in what they do over long times and in
/// how they depend on the gauge of `ϑ` (the mathematics and the figures are in the
/// `first_order` module of this crate and in `tests/suite/first_order.rs`).
///
/// - `Collocation` collocates the first-order Euler–Lagrange equations at the Gauss nodes. It
///   depends on `ϑ` only through the form `dϑ`, so its trajectory is the same in every gauge
///   `ϑ + ∇φ`; it is not symplectic for a non-constant `dϑ`, and the error in `H` of degree 2
///   and 3 grows linearly, at the method's order (Lotka–Volterra, h = 0.05, T = 500: from 1.4e-6
///   to 1.4e-5 at degree 2).
/// - `SymmetricProjection` is the variational Galerkin step, started from a point moved off
///   `(q_k, ϑ(q_k))` and projected back onto `p = ϑ(q)` at its end along the same Hamiltonian
///   direction of the constraint, with one multiplier per coordinate. Where the rule integrates
///   `ϑ·q̇` well (`ϑ` rational in `q`, as in the usual gauges) the error in `H` stays bounded
///   with no drift (the same run: 1.1248e-6 in the first and in the last tenth). It depends on
///   the gauge: with `ϑ` changed by the gradient of `q2 sin q1` its orders hold but `H` drifts,
///   faster than under collocation (measured in `tests/suite/first_order.rs`).
///
/// ```
/// use dirac_runtime::FirstOrderScheme;
/// assert_eq!(FirstOrderScheme::default(), FirstOrderScheme::Collocation);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FirstOrderScheme {
    /// Collocate the first-order equations at the Gauss nodes (the same in every gauge).
    #[default]
    Collocation,
    /// The variational step with a symmetric projection onto `p = ϑ(q)` (bounded `H` in
    /// gauges the quadrature integrates well).
    SymmetricProjection,
}

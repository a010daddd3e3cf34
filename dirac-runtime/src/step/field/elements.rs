//! Gauss–Lobatto elements in space: each cell of a field on a line carries the field at the
//! `r + 1` Gauss–Lobatto points of its width, the field between them is the polynomial of degree
//! `r` through them, and the cell's action is integrated by the same Gauss–Lobatto rule.
//!
//! On the cell `[x_e, x_e + Δx]`, with points `c_m ∈ [0, 1]`, weights `w_m` (`Σ w_m = 1`) and
//! the Lagrange basis `ℓ_m` of the points, the slope at point `q` is
//! `u_x(c_q) = Σ_m D_qm u_m / Δx`, `D_qm = ℓ'_m(c_q)`, and the cell's potential is
//! `Δx Σ_q w_q U(x_q, u_q, u_x(c_q))`. Its gradient is
//! `∂/∂u_m = w_m Δx ∂U/∂u(q = m) + Σ_q w_q ∂U/∂u_x(q) D_qm`, and the kinetic energy lumps onto the
//! points, `w_m Δx ρ`. Degree 1 is the trapezoidal cell.

use super::Boundary;
use crate::base::error::DiracError;
use crate::quadrature::{Quadrature, Rule, lagrange_derivative};

/// The highest degree offered: beyond it the points crowd the ends of a cell and the step's
/// stability limit (about `Δx/r²`) makes a higher degree cost more than it gains.
pub const MOST_DEGREE: usize = 8;

/// The Gauss–Lobatto points, weights and differentiation matrix of cells of one degree.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Elements {
    /// The points `c_m` in `[0, 1]`, `c_0 = 0`, `c_r = 1`.
    pub points: Vec<f64>,
    /// The weights `w_m`, summing to 1.
    pub weights: Vec<f64>,
    /// `D_qm = ℓ'_m(c_q)`, row by row.
    pub derivative: Vec<f64>,
}

impl Elements {
    /// Cells of degree `degree` (1 to [`MOST_DEGREE`]); `Unsupported` otherwise.
    pub fn new(degree: usize) -> Result<Self, DiracError> {
        if !(1..=MOST_DEGREE).contains(&degree) {
            return Err(DiracError::Unsupported(format!(
                "cells of degree {degree} in space: the degrees offered are 1 to {MOST_DEGREE}"
            )));
        }
        let rule = Quadrature::galerkin_with_rule(degree, Rule::GaussLobatto(degree + 1))?;
        let points = rule.nodes().to_vec();
        let weights = rule.weights().to_vec();
        let derivative = (0..=degree)
            .flat_map(|q| (0..=degree).map(move |m| (q, m)))
            .map(|(q, m)| lagrange_derivative(&points, m, points[q]))
            .collect();
        Ok(Self {
            points,
            weights,
            derivative,
        })
    }

    /// The degree `r`.
    pub fn degree(&self) -> usize {
        self.points.len() - 1
    }

    /// The weight of node `i` of the `n` along an axis of cells of width `width` held by
    /// `boundary` (its share of the lumped kinetic energy): `w_m width` at point `m` inside a
    /// cell, twice `w_0 width` where two cells meet, `w_0 width` at a free end, zero at a fixed
    /// one. For the trapezoidal cell: the width, half of it at a free end.
    pub fn node_weight(&self, boundary: Boundary, n: usize, i: usize, width: f64) -> f64 {
        let w = &self.weights;
        match (boundary, i == 0 || i == n - 1, i % self.degree()) {
            (Boundary::Fixed, true, _) => 0.0,
            (Boundary::Free, true, _) => w[0] * width,
            (_, _, 0) => 2.0 * w[0] * width,
            (_, _, m) => w[m] * width,
        }
    }

    /// `D_qm`.
    pub fn d(&self, q: usize, m: usize) -> f64 {
        self.derivative[q * self.points.len() + m]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Degree 1 is the trapezoidal cell; at every degree the weights sum to 1, the points are
    /// symmetric, and `D` differentiates the polynomials of the degree exactly.
    #[test]
    fn lobatto_cells_differentiate_their_polynomials() {
        let one = Elements::new(1).unwrap();
        assert_eq!(one.points, vec![0.0, 1.0]);
        assert_eq!(one.weights, vec![0.5, 0.5]);
        assert_eq!(one.derivative, vec![-1.0, 1.0, -1.0, 1.0]);
        // Degree 3: the points ½ ± ½√(1/5) inside, the weights 1/12 and 5/12.
        let three = Elements::new(3).unwrap();
        let inner = 0.5 * (0.2_f64).sqrt();
        for (c, exact) in three
            .points
            .iter()
            .zip([0.0, 0.5 - inner, 0.5 + inner, 1.0])
        {
            assert!((c - exact).abs() < 1e-15);
        }
        for (w, exact) in three.weights.iter().zip([1.0, 5.0, 5.0, 1.0]) {
            assert!((w - exact / 12.0).abs() < 1e-15);
        }
        for degree in 1..=MOST_DEGREE {
            let cell = Elements::new(degree).unwrap();
            let sum: f64 = cell.weights.iter().sum();
            assert!(
                (sum - 1.0).abs() < 1e-14,
                "degree {degree}: weights sum to {sum}"
            );
            for (c, d) in cell.points.iter().zip(cell.points.iter().rev()) {
                assert!((c + d - 1.0).abs() < 1e-14);
            }
            for power in 0..=degree as i32 {
                for q in 0..=degree {
                    let slope: f64 = (0..=degree)
                        .map(|m| cell.d(q, m) * cell.points[m].powi(power))
                        .sum();
                    let exact = match power {
                        0 => 0.0,
                        p => p as f64 * cell.points[q].powi(p - 1),
                    };
                    assert!(
                        (slope - exact).abs() < 1e-9,
                        "degree {degree}, x^{power} at {q}"
                    );
                }
            }
        }
        assert!(Elements::new(0).is_err());
        assert!(Elements::new(MOST_DEGREE + 1).is_err());
    }
}

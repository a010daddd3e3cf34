//! The Jacobian of a Newton solve: the matrix the residual's closure fills, its factorisation and
//! its solves. [`Dense`] is one LU of the whole matrix; [`Bordered`]
//! factors diagonal blocks on their own and couples them through a Schur complement (the
//! modular step of an interconnection, see [`modular`](crate::step::modular)).

use nalgebra::DMatrix;

use crate::base::float::row_sum_norm;
use crate::solve::lu::{self, SingularPivot};

pub use crate::solve::bordered::{BlockMatrix, Bordered};

/// A Jacobian [`Newton`](crate::Newton)'s method fills, factorises in place and solves with.
///
/// ```
/// use dirac_runtime::jacobian::{Dense, Jacobian};
/// let mut j = Dense::new(2);
/// j.matrix().copy_from_slice(&[2.0, 0.0, 1.0, 4.0]); // columns: [[2, 1], [0, 4]]
/// assert_eq!(j.norm(), 4.0);
/// j.factorise(1e-13).unwrap();
/// let mut b = [3.0, 4.0];
/// j.solve(&mut b);
/// assert_eq!(b, [1.0, 1.0]);
/// ```
pub trait Jacobian: Clone + std::fmt::Debug {
    /// What the residual's closure adds the Jacobian into.
    type Matrix;

    /// The number of unknowns (and rows).
    fn size(&self) -> usize;

    /// The matrix, to be filled.
    fn matrix(&mut self) -> &mut Self::Matrix;

    /// Zeroes the matrix before it is filled.
    fn clear(&mut self);

    /// Whether the matrix still has the shape of `n` unknowns (a closure must not resize it).
    fn fits(&self, n: usize) -> bool;

    /// Gives the matrix the shape of `n` unknowns again, after a closure changed it.
    fn restore(&mut self, n: usize);

    /// `‖J‖∞`, the largest absolute row sum: not finite where an entry is not.
    fn norm(&mut self) -> f64;

    /// Whether every entry is finite.
    fn is_finite(&self) -> bool;

    /// Factorises in place; a pivot at or below `tolerance` times the largest entry of its row
    /// counts as zero, and the error names the unknown that could not be eliminated.
    fn factorise(&mut self, tolerance: f64) -> Result<(), SingularPivot>;

    /// Solves `J y = b` in place of `b` with the factorisation.
    fn solve(&self, b: &mut [f64]);

    /// Entries per parallel task of the solver's passes over its vectors (copies, norms,
    /// updates), where the Jacobian itself works across threads; `usize::MAX` (the default):
    /// on one thread. The passes' results do not depend on it.
    fn vector_grain(&self) -> usize {
        usize::MAX
    }
}

/// A dense Jacobian, factorised by one LU with partial pivoting.
#[derive(Debug, Clone)]
pub struct Dense {
    matrix: DMatrix<f64>,
    pivots: Vec<usize>,
    /// The rows' scales while the matrix is factorised (scratch).
    scales: Vec<f64>,
}

impl Dense {
    /// A zero `n × n` Jacobian.
    pub fn new(n: usize) -> Self {
        Self {
            matrix: DMatrix::zeros(n, n),
            pivots: vec![0; n],
            scales: vec![0.0; n],
        }
    }

    /// `max |u_ii| / min |u_ii|` over the factorisation's pivots: a lower bound of the
    /// matrix's condition number.
    pub(crate) fn pivot_ratio(&self) -> f64 {
        let (largest, smallest) = (0..self.matrix.nrows())
            .map(|i| self.matrix[(i, i)].abs())
            .fold((0.0_f64, f64::INFINITY), |(l, s), u| (l.max(u), s.min(u)));
        largest / smallest
    }
}

impl Jacobian for Dense {
    type Matrix = DMatrix<f64>;

    fn size(&self) -> usize {
        self.matrix.nrows()
    }

    fn matrix(&mut self) -> &mut DMatrix<f64> {
        &mut self.matrix
    }

    fn clear(&mut self) {
        self.matrix.as_mut_slice().fill(0.0);
    }

    fn fits(&self, n: usize) -> bool {
        self.matrix.shape() == (n, n)
    }

    fn restore(&mut self, n: usize) {
        *self = Self::new(n);
    }

    fn norm(&mut self) -> f64 {
        row_sum_norm(&self.matrix, &mut self.scales)
    }

    fn is_finite(&self) -> bool {
        self.matrix.iter().all(|v| v.is_finite())
    }

    fn factorise(&mut self, tolerance: f64) -> Result<(), SingularPivot> {
        lu::factorise(
            &mut self.matrix,
            &mut self.pivots,
            &mut self.scales,
            tolerance,
        )
    }

    fn solve(&self, b: &mut [f64]) {
        lu::solve(&self.matrix, &self.pivots, b);
    }
}

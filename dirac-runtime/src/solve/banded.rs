//! LU factorisation with partial pivoting of a band matrix, in place: the Schur complement of a
//! [`Bordered`](crate::solve::jacobian::Bordered) Jacobian, whose couplings touch only their
//! neighbours in a chain or a ladder. `m` unknowns with `b` diagonals on each side cost
//! `O(m b²)` to factorise and `O(m b)` to solve.

use crate::base::error::DiracError;
use crate::base::float::largest;
use crate::solve::jacobian::Jacobian;
use crate::solve::lu::SingularPivot;

/// An `m × m` matrix with `lower` diagonals below the main one and `upper` above, stored row by
/// row with room for the `lower` diagonals that pivoting adds above.
#[derive(Debug, Clone)]
pub(crate) struct Banded {
    m: usize,
    lower: usize,
    upper: usize,
    /// Row `i` holds columns `i − lower ..= i + upper + lower` (`width` entries).
    data: Vec<f64>,
    pivots: Vec<usize>,
    scales: Vec<f64>,
}

impl Banded {
    /// A zero matrix of `m` rows with `lower` and `upper` diagonals.
    pub fn new(m: usize, lower: usize, upper: usize) -> Self {
        let width = 2 * lower + upper + 1;
        Self {
            m,
            lower,
            upper,
            data: vec![0.0; m * width],
            pivots: vec![0; m],
            scales: vec![0.0; m],
        }
    }

    /// [`new`](Self::new), refused with `Unsupported` where its storage would pass 2²⁶ numbers
    /// (512 MB): a band as wide as the matrix (a junction between distant components, a ring's
    /// closing junction), for which `what` (the solve it is for) would not fit.
    pub fn within_memory(
        m: usize,
        lower: usize,
        upper: usize,
        what: &str,
    ) -> Result<Self, DiracError> {
        let entries = (2 * lower + upper + 1).checked_mul(m);
        if entries.is_none_or(|n| n > 1 << 26) {
            return Err(DiracError::Unsupported(format!(
                "{what} as a band of {m} rows and half-widths {lower}, {upper} (more than 2^26 \
                 numbers): a junction joins components far apart in their order (a ring's \
                 closing junction); order the components so that joined ones are near, or step \
                 the interconnection monolithically"
            )));
        }
        Ok(Self::new(m, lower, upper))
    }

    fn width(&self) -> usize {
        2 * self.lower + self.upper + 1
    }

    fn index(&self, i: usize, j: usize) -> usize {
        debug_assert!(j + self.lower >= i && j <= i + self.upper + self.lower);
        i * self.width() + j + self.lower - i
    }

    /// Zeroes every entry.
    pub fn clear(&mut self) {
        self.data.fill(0.0);
    }

    /// Adds `value` to entry `(i, j)`, which must lie within the band.
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        debug_assert!(
            j <= i + self.upper && i <= j + self.lower,
            "outside the band"
        );
        let at = self.index(i, j);
        self.data[at] += value;
    }

    /// Factorises in place (`P A = L U`); a pivot at or below `tolerance` times the largest
    /// entry of its row counts as zero, and the error names its column.
    pub fn factorise(&mut self, tolerance: f64) -> Result<(), SingularPivot> {
        let (m, lower, upper) = (self.m, self.lower, self.upper);
        let width = self.width();
        for i in 0..m {
            let row = &self.data[i * width..(i + 1) * width];
            self.scales[i] = row.iter().fold(0.0, |s: f64, v| s.max(v.abs()));
        }
        for k in 0..m {
            let last = (k + lower).min(m - 1);
            let (mut p, mut best) = (k, self.data[self.index(k, k)].abs());
            for i in k + 1..=last {
                let v = self.data[self.index(i, k)].abs();
                if v > best {
                    (p, best) = (i, v);
                }
            }
            self.pivots[k] = p;
            if best <= tolerance * self.scales[p] || !best.is_finite() {
                return Err(SingularPivot {
                    column: k,
                    involved: self.null_vector_support(k),
                });
            }
            let end = (k + upper + lower).min(m - 1);
            if p != k {
                for j in k..=end {
                    let (a, b) = (self.index(k, j), self.index(p, j));
                    self.data.swap(a, b);
                }
                self.scales.swap(k, p);
            }
            let pivot = self.data[self.index(k, k)];
            for i in k + 1..=last {
                let at = self.index(i, k);
                let factor = self.data[at] / pivot;
                self.data[at] = factor;
                if factor != 0.0 {
                    for j in k + 1..=end {
                        let (a, b) = (self.index(i, j), self.index(k, j));
                        self.data[a] -= factor * self.data[b];
                    }
                }
            }
        }
        Ok(())
    }

    /// After elimination stopped at column `k`, column `k` is a combination of columns `0..k`:
    /// `x = (−U₀₀⁻¹ u, 1, 0, …)` solves `A x = 0` there. The indices where `x` is not small.
    fn null_vector_support(&self, k: usize) -> Vec<usize> {
        let mut x = vec![0.0; k + 1];
        x[k] = 1.0;
        for i in (0..k).rev() {
            let end = (i + self.upper + self.lower).min(k);
            let s: f64 = (i + 1..=end)
                .map(|j| self.data[self.index(i, j)] * x[j])
                .sum();
            x[i] = -s / self.data[self.index(i, i)];
        }
        let largest = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        (0..=k).filter(|&i| x[i].abs() > 1e-8 * largest).collect()
    }

    /// Solves `A x = b` in place of `b` with the factors.
    pub fn solve(&self, b: &mut [f64]) {
        let (m, lower, upper) = (self.m, self.lower, self.upper);
        for k in 0..m {
            b.swap(k, self.pivots[k]);
            for i in k + 1..=(k + lower).min(m.saturating_sub(1)) {
                b[i] -= self.data[self.index(i, k)] * b[k];
            }
        }
        if m == 0 {
            return;
        }
        for k in (0..m).rev() {
            let end = (k + upper + lower).min(m - 1);
            let mut sum = b[k];
            for (j, bj) in b.iter().enumerate().take(end + 1).skip(k + 1) {
                sum -= self.data[self.index(k, j)] * bj;
            }
            b[k] = sum / self.data[self.index(k, k)];
        }
    }
}

impl Jacobian for Banded {
    type Matrix = Banded;

    fn size(&self) -> usize {
        self.m
    }

    fn matrix(&mut self) -> &mut Banded {
        self
    }

    fn clear(&mut self) {
        self.data.fill(0.0);
    }

    fn fits(&self, n: usize) -> bool {
        n == self.m && self.data.len() == self.m * self.width() && self.pivots.len() == self.m
    }

    fn restore(&mut self, n: usize) {
        *self = Self::new(n, self.lower, self.upper);
    }

    fn norm(&mut self) -> f64 {
        let width = self.width();
        let sums = self
            .data
            .chunks_exact(width.max(1))
            .map(|row| row.iter().map(|v| v.abs()).sum());
        largest(sums)
    }

    fn is_finite(&self) -> bool {
        self.data.iter().all(|v| v.is_finite())
    }

    fn factorise(&mut self, tolerance: f64) -> Result<(), SingularPivot> {
        Banded::factorise(self, tolerance)
    }

    fn solve(&self, b: &mut [f64]) {
        Banded::solve(self, b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A band matrix of `m` rows with `lower`/`upper` diagonals, entries from a fixed sequence,
    /// a weak diagonal so that pivoting happens.
    fn sample(m: usize, lower: usize, upper: usize) -> DMatrix<f64> {
        DMatrix::from_fn(m, m, |i, j| {
            if j + lower < i || j > i + upper {
                0.0
            } else {
                let s = ((7 * i + 13 * j + 3) % 17) as f64 - 8.0;
                if i == j { 0.1 * s } else { s }
            }
        })
    }

    #[test]
    fn solves_as_the_dense_lu_with_pivoting() {
        for (m, lower, upper) in [(1, 0, 0), (6, 1, 1), (9, 2, 1), (12, 3, 3), (7, 6, 6)] {
            let a = sample(m, lower, upper);
            let mut band = Banded::new(m, lower, upper);
            for i in 0..m {
                for j in 0..m {
                    if a[(i, j)] != 0.0 {
                        band.add(i, j, a[(i, j)]);
                    }
                }
            }
            band.factorise(1e-13).unwrap();
            let x = DVector::from_fn(m, |i, _| 1.0 + i as f64);
            let mut b = (&a * &x).as_slice().to_vec();
            band.solve(&mut b);
            let error = (DVector::from_vec(b) - &x).amax();
            assert!(error < 1e-12 * m as f64, "m {m}: error {error}");
        }
    }

    #[test]
    fn a_singular_band_names_its_column() {
        let mut band = Banded::new(3, 1, 1);
        // Rows 0 and 1 are equal: column 1 cannot be eliminated.
        for (i, j, v) in [
            (0, 0, 1.0),
            (0, 1, 2.0),
            (1, 0, 1.0),
            (1, 1, 2.0),
            (2, 2, 1.0),
        ] {
            band.add(i, j, v);
        }
        let singular = band.factorise(1e-13).unwrap_err();
        assert_eq!((singular.column, singular.involved), (1, vec![0, 1]));
    }
}

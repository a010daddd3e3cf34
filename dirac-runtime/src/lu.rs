//! LU factorisation with partial pivoting, in place, without allocation: the linear solve inside
//! every Newton iteration.

use nalgebra::DMatrix;

/// Why a factorisation failed: the column whose pivot vanished, and the unknowns that a null
/// vector of the matrix moves (the directions the equations do not determine).
#[derive(Debug, Clone, PartialEq)]
pub struct SingularPivot {
    /// Column (unknown) that could not be eliminated.
    pub column: usize,
    /// Unknowns with a nonzero entry in a null vector of the columns up to `column`.
    pub involved: Vec<usize>,
}

/// Factorises `a` in place (`P a = L U`, unit lower `L` below the diagonal) and records the row
/// permutation in `pivots`. A pivot at or below `tolerance` times the largest entry of its own
/// row of `a` counts as zero: rows in different units (a velocity row beside a momentum row of a
/// heavy body) do not make a regular pivot look singular, and a row that elimination cancels
/// still does. `scales` (`n` entries) is scratch.
pub(crate) fn factorise(
    a: &mut DMatrix<f64>,
    pivots: &mut [usize],
    scales: &mut [f64],
    tolerance: f64,
) -> Result<(), SingularPivot> {
    let n = a.nrows();
    let scales = &mut scales[..n];
    scales.fill(0.0);
    // Column by column through the column-major storage.
    for column in a.as_slice().chunks_exact(n.max(1)) {
        for (scale, x) in scales.iter_mut().zip(column) {
            *scale = scale.max(x.abs());
        }
    }
    for k in 0..n {
        let (mut p, mut best) = (k, a[(k, k)].abs());
        for i in k + 1..n {
            if a[(i, k)].abs() > best {
                (p, best) = (i, a[(i, k)].abs());
            }
        }
        pivots[k] = p;
        if best <= tolerance * scales[p] || !best.is_finite() {
            return Err(SingularPivot {
                column: k,
                involved: null_vector_support(a, k),
            });
        }
        if p != k {
            a.swap_rows(k, p);
            scales.swap(k, p);
        }
        let pivot = a[(k, k)];
        for i in k + 1..n {
            let factor = a[(i, k)] / pivot;
            a[(i, k)] = factor;
            for j in k + 1..n {
                a[(i, j)] -= factor * a[(k, j)];
            }
        }
    }
    Ok(())
}

/// After elimination stopped at column `k`, column `k` is a combination of columns `0..k`:
/// `x = (−U₀₀⁻¹ u, 1, 0, …)` solves `A x = 0` there. Returns the indices where `x` is not small.
fn null_vector_support(lu: &DMatrix<f64>, k: usize) -> Vec<usize> {
    let mut x = vec![0.0; k + 1];
    x[k] = 1.0;
    for i in (0..k).rev() {
        let s: f64 = (i + 1..=k).map(|j| lu[(i, j)] * x[j]).sum();
        x[i] = -s / lu[(i, i)];
    }
    let largest = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    (0..=k).filter(|&i| x[i].abs() > 1e-8 * largest).collect()
}

/// Solves `A x = b` in place of `b` with the factors from [`factorise`].
pub(crate) fn solve(lu: &DMatrix<f64>, pivots: &[usize], b: &mut [f64]) {
    let n = lu.nrows();
    // Column-major factors read through one slice: the bounds are checked once, here.
    let a = lu.as_slice();
    let (b, pivots) = (&mut b[..n], &pivots[..n]);
    assert_eq!(a.len(), n * n, "a square factorisation");
    for (k, &p) in pivots.iter().enumerate() {
        b.swap(k, p);
    }
    // L y = P b, column by column: the same order of subtractions as row by row.
    for j in 0..n {
        let (y, column) = (b[j], &a[j * n..(j + 1) * n]);
        for i in j + 1..n {
            b[i] -= column[i] * y;
        }
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for j in i + 1..n {
            s -= a[i + j * n] * b[j];
        }
        b[i] = s / a[i + i * n];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 1.0, 1.0, 1.0, 4.0, -1.0, 3.0]);
        let x = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        let mut b = &a * &x;
        let mut lu = a.clone();
        let mut pivots = [0; 3];
        factorise(&mut lu, &mut pivots, &mut [0.0; 3], 1e-14).unwrap();
        solve(&lu, &pivots, b.as_mut_slice());
        assert!((b - x).amax() < 1e-14);
    }

    #[test]
    fn reports_the_column_of_a_singular_matrix() {
        let mut a = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 1.0, 0.0, 1.0]);
        let mut pivots = [0; 3];
        let err = factorise(&mut a, &mut pivots, &mut [0.0; 3], 1e-14).unwrap_err();
        assert_eq!(err.column, 2);
        // The columns are dependent: col0 + col1 − col2 = 0.
        assert_eq!(err.involved, vec![0, 1, 2]);
    }
}

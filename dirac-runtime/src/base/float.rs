//! Error measures that a NaN cannot make look small, the matrix norm the solver and the
//! Jacobian shapes judge by, and sums that keep their rounding errors (TwoSum).

use nalgebra::{Dim, IsContiguous, Matrix, SVector, Storage};

/// Whether the error measure `x` exceeds `bound`, or either is NaN: a test that a NaN (a
/// constraint or balance that is not finite) cannot pass.
pub(crate) fn exceeds(x: f64, bound: f64) -> bool {
    x.is_nan() || bound.is_nan() || x > bound
}

/// `a + b` rounded and its rounding error, exactly: `sum + error = a + b` (Knuth's TwoSum,
/// whichever operand is larger).
#[inline(always)]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let sum = a + b;
    let b_part = sum - a;
    (sum, (a - (sum - b_part)) + (b - b_part))
}

/// `first + Σ terms` summed in two parts (each addition's rounding error kept), as the
/// rounded sum and its remainder: `sum + rest` is the exact sum to far below an ulp of `sum`.
pub(crate) fn rounded_sum(first: f64, terms: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut sum, mut error) = (first, 0.0);
    for term in terms {
        let (next, rounding) = two_sum(sum, term);
        (sum, error) = (next, error + rounding);
    }
    two_sum(sum, error)
}

/// `x += increment` with the rounding error of each component's addition added to `lo`
/// (`x_new + e = x + increment` exactly).
#[inline(always)]
pub(crate) fn two_sum_add<const N: usize>(
    x: &mut SVector<f64, N>,
    lo: &mut SVector<f64, N>,
    increment: &SVector<f64, N>,
) {
    for i in 0..N {
        let (sum, error) = two_sum(x[i], increment[i]);
        lo[i] += error;
        x[i] = sum;
    }
}

/// `x + lo` as a rounded sum and the carry of a compensated sum (the sum's excess over
/// `x + lo`, which the next addition takes back, as a Kahan sum does).
pub(crate) fn folded<const N: usize>(
    x: &SVector<f64, N>,
    lo: &SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let (mut sum, mut error) = (*x, SVector::zeros());
    two_sum_add(&mut sum, &mut error, lo);
    (sum, -error)
}

/// The largest magnitude among `values`, or NaN where one is NaN (which `f64::max` and
/// nalgebra's `amax` pass over): an error measure that a NaN cannot make look small.
pub(crate) fn largest(values: impl IntoIterator<Item = f64>) -> f64 {
    values.into_iter().fold(0.0, |m: f64, x| {
        if m.is_nan() || x.is_nan() {
            f64::NAN
        } else {
            m.max(x.abs())
        }
    })
}

/// `‖A‖∞`, the largest absolute row sum, accumulated column by column in `sums` (scratch, a
/// row each: the same sums in the same order as row by row). Not finite where an entry is not.
pub(crate) fn row_sum_norm<R: Dim, C: Dim, S: Storage<f64, R, C> + IsContiguous>(
    a: &Matrix<f64, R, C, S>,
    sums: &mut [f64],
) -> f64 {
    let sums = &mut sums[..a.nrows()];
    sums.fill(0.0);
    for column in a.as_slice().chunks_exact(a.nrows().max(1)) {
        for (sum, x) in sums.iter_mut().zip(column) {
            *sum += x.abs();
        }
    }
    largest(sums.iter().copied())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_measures_do_not_pass_over_nan() {
        assert_eq!(largest([1.0, -3.0, 2.0]), 3.0);
        assert_eq!(largest(std::iter::empty()), 0.0);
        for at in 0..3 {
            let mut values = [1.0, -3.0, 2.0];
            values[at] = f64::NAN;
            // nalgebra's amax passes over a NaN that a larger entry follows.
            assert!(largest(values).is_nan(), "NaN at {at}");
        }
        assert!(!exceeds(1.0, 1.0) && exceeds(1.5, 1.0));
        assert!(exceeds(f64::NAN, 1.0) && exceeds(0.0, f64::NAN));
    }
}

//! Dense LU factorisation with partial pivoting, in place, for the Newton iterations of the
//! implicit methods: real (`f64`) and complex (`Complex<f64>`) `n × n` systems.
//!
//! nalgebra's `LU::new` takes the matrix by value and allocates its permutation at every
//! factorisation; the implicit methods refactor whenever the step size changes, so this
//! variant keeps the matrix and the pivots in buffers allocated once per integration (the
//! crate's rule: no heap allocation per step). It stores the matrices as nalgebra `DMatrix`
//! and is checked against `nalgebra::LU` in the tests below.

use nalgebra::{ComplexField, DMatrix};

/// Relative difference of step sizes below which an iteration matrix factored for one serves
/// the other: simplified Newton iterations only need an approximate matrix, and steps
/// computed as differences of times differ from the intended size in the last bits.
pub(crate) const SAME_STEP: f64 = 1e-9;

/// An `n × n` matrix and, after [`factor`](Self::factor), its LU factors `P A = L U` (unit
/// lower `L` below the diagonal, `U` on and above it, `P` as the row interchanges of
/// LINPACK's `DGEFA`).
#[derive(Debug, Clone)]
pub(crate) struct LuFactors<T: ComplexField + Copy> {
    lu: DMatrix<T>,
    /// Row exchanged with row `k` at elimination step `k`.
    pivots: Vec<usize>,
}

/// The matrix was exactly singular: a zero pivot at elimination step `column`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Singular {
    pub(crate) column: usize,
}

impl<T: ComplexField + Copy> LuFactors<T> {
    /// Buffers for `n × n` systems (the matrix starts as zeros).
    pub(crate) fn new(n: usize) -> Self {
        Self {
            lu: DMatrix::from_element(n, n, T::zero()),
            pivots: vec![0; n],
        }
    }

    /// The matrix to fill before [`factor`](Self::factor); after it, the factors.
    pub(crate) fn matrix_mut(&mut self) -> &mut DMatrix<T> {
        &mut self.lu
    }

    /// Factors the matrix in place: Gaussian elimination with partial pivoting on the largest
    /// `|re| + |im|` in each column.
    ///
    /// # Errors
    /// [`Singular`] at the first column with no non-zero pivot; the buffer then holds a
    /// partial elimination and must be refilled.
    pub(crate) fn factor(&mut self) -> Result<(), Singular> {
        let n = self.lu.nrows();
        let a = &mut self.lu;
        for k in 0..n {
            let mut pivot = k;
            let mut largest = a[(k, k)].norm1();
            for i in k + 1..n {
                let size = a[(i, k)].norm1();
                if size > largest {
                    largest = size;
                    pivot = i;
                }
            }
            self.pivots[k] = pivot;
            if a[(pivot, k)].is_zero() {
                return Err(Singular { column: k });
            }
            if pivot != k {
                a.swap_rows(k, pivot);
            }
            let inverse = T::one() / a[(k, k)];
            for i in k + 1..n {
                a[(i, k)] *= inverse;
            }
            for j in k + 1..n {
                let u = a[(k, j)];
                if !u.is_zero() {
                    for i in k + 1..n {
                        let l = a[(i, k)];
                        a[(i, j)] -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the factors (`b` becomes `x`).
    ///
    /// # Shapes
    /// `b` has `n` entries.
    pub(crate) fn solve_in_place(&self, b: &mut [T]) {
        let n = self.lu.nrows();
        debug_assert_eq!(b.len(), n);
        let a = &self.lu;
        for (k, &pivot) in self.pivots.iter().enumerate() {
            if pivot != k {
                b.swap(k, pivot);
            }
        }
        for j in 0..n {
            let x = b[j];
            if !x.is_zero() {
                for i in j + 1..n {
                    b[i] -= a[(i, j)] * x;
                }
            }
        }
        for j in (0..n).rev() {
            b[j] /= a[(j, j)];
            let x = b[j];
            for i in 0..j {
                b[i] -= a[(i, j)] * x;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Complex, DVector};

    #[test]
    fn real_solve_matches_nalgebra() {
        let values = [
            2.0, -1.0, 0.5, 3.0, //
            0.0, 1e-3, 4.0, -2.0, //
            1.0, 2.0, -3.0, 0.25, //
            -5.0, 0.0, 1.0, 1.0,
        ];
        let matrix = DMatrix::from_row_slice(4, 4, &values);
        let b = DVector::from_vec(vec![1.0, -2.0, 3.0, 0.5]);
        let expected = matrix.clone().lu().solve(&b).unwrap();
        let mut lu = LuFactors::<f64>::new(4);
        lu.matrix_mut().copy_from(&matrix);
        lu.factor().unwrap();
        let mut x = b.as_slice().to_vec();
        lu.solve_in_place(&mut x);
        for (x, e) in x.iter().zip(expected.iter()) {
            assert!((x - e).abs() < 1e-13, "{x} vs {e}");
        }
        // The same factors solve again (they are not consumed).
        let mut again = b.as_slice().to_vec();
        lu.solve_in_place(&mut again);
        assert_eq!(again, x);
    }

    #[test]
    fn complex_solve_matches_nalgebra() {
        let matrix = DMatrix::from_fn(3, 3, |i, j| {
            Complex::new(
                (i as f64 + 1.0) * 0.7 - j as f64,
                if i == j { 2.0 } else { 0.3 },
            )
        });
        let b = DVector::from_fn(3, |i, _| Complex::new(i as f64, 1.0 - i as f64));
        let expected = matrix.clone().lu().solve(&b).unwrap();
        let mut lu = LuFactors::<Complex<f64>>::new(3);
        lu.matrix_mut().copy_from(&matrix);
        lu.factor().unwrap();
        let mut x = b.as_slice().to_vec();
        lu.solve_in_place(&mut x);
        for (x, e) in x.iter().zip(expected.iter()) {
            assert!((x - e).norm() < 1e-13, "{x} vs {e}");
        }
    }

    /// Partial pivoting: a zero leading entry is no obstacle (a permutation), and a tiny one
    /// is not used as the pivot, which without pivoting multiplies the rounding of the
    /// second row by 1e20 (`[[1e-20, 1], [1, 1]] x = [1, 2]`, `x ≈ [1, 1]`: without the
    /// row exchange `x₁` comes out 0).
    #[test]
    fn rows_are_exchanged_for_the_largest_pivot() {
        let cases = [
            ([0.0, 1.0, 1.0, 0.0], [2.0, 3.0], [3.0, 2.0]),
            ([1e-20, 1.0, 1.0, 1.0], [1.0, 2.0], [1.0, 1.0]),
        ];
        for (values, b, expected) in cases {
            let mut lu = LuFactors::<f64>::new(2);
            lu.matrix_mut()
                .copy_from(&DMatrix::from_row_slice(2, 2, &values));
            lu.factor().unwrap();
            let mut x = b.to_vec();
            lu.solve_in_place(&mut x);
            for (x, e) in x.iter().zip(expected) {
                assert!((x - e).abs() < 1e-15, "{values:?}: {x} vs {e}");
            }
        }
    }

    #[test]
    fn singular_matrices_are_reported() {
        let mut lu = LuFactors::<f64>::new(2);
        lu.matrix_mut()
            .copy_from(&DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]));
        assert_eq!(lu.factor(), Err(Singular { column: 1 }));
        let mut empty = LuFactors::<f64>::new(0);
        assert!(empty.factor().is_ok());
        empty.solve_in_place(&mut []);
    }
}

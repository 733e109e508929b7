//! Small fixed-size linear solves for code generic in the dimension N.
//!
//! Written here because nalgebra's decompositions on `SMatrix<f64, N, N>` need typenum bounds (`DimMin`) that
//! would have to be repeated on every generic caller; a partial-pivoting elimination of a 2x2 or 3x3 system is a
//! dozen lines and allocates nothing, which matters in the distance hot path.

use nalgebra::{SMatrix, SVector};

/// Solves A x = b for each right-hand side by Gaussian elimination with partial pivoting; `None` when A is
/// singular to working precision.
pub fn solve<const N: usize, const K: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, K>,
) -> Option<SMatrix<f64, N, K>> {
    let scale = a.amax();
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    if N == 2 {
        // Cramer's rule: the distance hot path solves a 2x2 system at every Newton step.
        let det = a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)];
        if det.abs() <= scale * scale * 1e-14 {
            return None;
        }
        let mut x = SMatrix::<f64, N, K>::zeros();
        for k in 0..K {
            x[(0, k)] = (b[(0, k)] * a[(1, 1)] - a[(0, 1)] * b[(1, k)]) / det;
            x[(1, k)] = (a[(0, 0)] * b[(1, k)] - b[(0, k)] * a[(1, 0)]) / det;
        }
        return Some(x);
    }
    let mut a = *a;
    let mut b = *b;
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[(i, col)].abs().total_cmp(&a[(j, col)].abs()))?;
        if a[(pivot, col)].abs() <= scale * 1e-14 {
            return None;
        }
        a.swap_rows(col, pivot);
        b.swap_rows(col, pivot);
        for row in (col + 1)..N {
            let factor = a[(row, col)] / a[(col, col)];
            for k in col..N {
                a[(row, k)] -= factor * a[(col, k)];
            }
            for k in 0..K {
                b[(row, k)] -= factor * b[(col, k)];
            }
        }
    }
    let mut x = SMatrix::<f64, N, K>::zeros();
    for row in (0..N).rev() {
        for k in 0..K {
            let tail: f64 = ((row + 1)..N).map(|j| a[(row, j)] * x[(j, k)]).sum();
            x[(row, k)] = (b[(row, k)] - tail) / a[(row, row)];
        }
    }
    Some(x)
}

/// Eigen-decomposition of a small symmetric matrix (through nalgebra's dynamic matrices, off the hot path):
/// eigenvalues ascending with their unit eigenvectors.
pub fn symmetric_eigen<const N: usize>(m: &SMatrix<f64, N, N>) -> Vec<(f64, SVector<f64, N>)> {
    let dynamic = nalgebra::DMatrix::from_column_slice(N, N, m.as_slice());
    let eigen = dynamic.symmetric_eigen();
    let mut pairs: Vec<(f64, SVector<f64, N>)> = (0..N)
        .map(|i| {
            let v = SVector::<f64, N>::from_iterator(eigen.eigenvectors.column(i).iter().copied());
            (eigen.eigenvalues[i], v)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn solves_two_by_two_systems_and_refuses_singular_ones() {
        let a = nalgebra::Matrix2::new(0.0, 2.0, 3.0, 1.0);
        let x = nalgebra::Vector2::new(1.5, -2.0);
        assert!((solve(&a, &(a * x)).unwrap() - x).norm() < 1e-12);
        assert!(solve(&nalgebra::Matrix2::new(1.0, 2.0, 2.0, 4.0), &x).is_none());
    }

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let x = Vector3::new(1.0, -2.0, 0.5);
        let solved = solve(&a, &(a * x)).unwrap();
        assert!((solved - x).norm() < 1e-12);
        assert!(solve(
            &Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0),
            &x
        )
        .is_none());
    }

    #[test]
    fn eigenpairs_are_sorted_and_satisfy_the_definition() {
        let m = Matrix3::new(4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 1.0);
        let pairs = symmetric_eigen(&m);
        assert!(pairs[0].0 <= pairs[1].0 && pairs[1].0 <= pairs[2].0);
        for (value, vector) in pairs {
            assert!((m * vector - vector * value).norm() < 1e-10);
        }
    }
}

//! Linear least squares for tall systems, min |A x - b|, without ever holding A: rows are generated chunk by chunk,
//! each chunk is reduced by Householder QR to its triangle R_k and Q_k^T b_k (TSQR, Demmel et al. 2012), the
//! chunks in parallel, and the stacked triangles are reduced once more. The answer is the one of a QR of the whole
//! A (same R up to the signs of its rows), so the conditioning is that of A, not of A^T A as with normal equations;
//! the memory is a chunk per core instead of the tall matrix.
//!
//! Written here because nalgebra's QR works on a matrix it is given whole, and the fits' tall matrices (300 000 x
//! 15 for 100 000 points) cost more to allocate and fill than to reduce. The chunks are fixed in size and stacked
//! in order, so the answer does not depend on the number of threads.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Rows per chunk: a chunk of 15 columns is 240 kB, which stays in a core's cache while it is reduced.
const CHUNK_ROWS: usize = 2048;

/// The rows of one chunk, written in place.
pub(super) struct Rows<'a> {
    m: usize,
    values: &'a mut Vec<f64>,
    targets: &'a mut Vec<f64>,
}

impl Rows<'_> {
    /// Adds a row with its target; returns the row (zeros) to fill.
    pub(super) fn push(&mut self, target: f64) -> &mut [f64] {
        let start = self.values.len();
        self.values.resize(start + self.m, 0.0);
        self.targets.push(target);
        &mut self.values[start..]
    }
}

/// A system reduced to `m` unknowns: min |A x - b| has the same solution as min |r x - qtb|.
#[derive(Debug, Clone)]
pub(super) struct Reduced {
    r: DMatrix<f64>,
    qtb: DVector<f64>,
}

impl Reduced {
    /// The reduction of the rows that `emit` writes for items `0..items`: `emit(item, rows)` adds each of its rows
    /// (any number, in order) with [`Rows::push`]. Items are taken CHUNK_ROWS / `rows_per_item` at a time,
    /// `rows_per_item` being the most rows one item emits.
    pub(super) fn of_rows<F>(items: usize, rows_per_item: usize, m: usize, emit: F) -> Self
    where
        F: Fn(usize, &mut Rows) + Sync,
    {
        let per_chunk = (CHUNK_ROWS / rows_per_item.max(1)).max(1);
        let chunks: Vec<Reduced> = (0..items.div_ceil(per_chunk))
            .into_par_iter()
            .map(|chunk| {
                let range = chunk * per_chunk..((chunk + 1) * per_chunk).min(items);
                let mut values = Vec::with_capacity(range.len() * rows_per_item * m);
                let mut targets = Vec::with_capacity(range.len() * rows_per_item);
                let mut rows = Rows {
                    m,
                    values: &mut values,
                    targets: &mut targets,
                };
                for item in range {
                    emit(item, &mut rows);
                }
                let a = DMatrix::from_row_slice(targets.len(), m, &values);
                Self::of_matrix(a, DVector::from_vec(targets))
            })
            .collect();
        Self::stack(&chunks, None)
    }

    /// Householder QR of a whole (small or chunk-sized) system.
    fn of_matrix(a: DMatrix<f64>, mut b: DVector<f64>) -> Self {
        let m = a.ncols();
        let rows = a.nrows();
        if rows == 0 {
            return Self {
                r: DMatrix::zeros(0, m),
                qtb: DVector::zeros(0),
            };
        }
        let qr = a.qr();
        qr.q_tr_mul(&mut b);
        let r = qr.r();
        let kept = rows.min(m);
        Self {
            r: r.rows(0, kept).into_owned(),
            qtb: b.rows(0, kept).into_owned(),
        }
    }

    /// The reduction of several reduced systems stacked, with optional extra rows (a diagonal regulariser: the
    /// weight of each unknown, its target 0).
    pub(super) fn stack(parts: &[Reduced], diagonal: Option<&[f64]>) -> Self {
        let m = parts
            .iter()
            .map(|p| p.r.ncols())
            .next()
            .or(diagonal.map(<[f64]>::len))
            .unwrap_or(0);
        let extra = diagonal.map_or(0, <[f64]>::len);
        let rows: usize = parts.iter().map(|p| p.r.nrows()).sum::<usize>() + extra;
        let mut a = DMatrix::<f64>::zeros(rows, m);
        let mut b = DVector::<f64>::zeros(rows);
        let mut at = 0;
        for part in parts {
            let k = part.r.nrows();
            a.rows_mut(at, k).copy_from(&part.r);
            b.rows_mut(at, k).copy_from(&part.qtb);
            at += k;
        }
        if let Some(weights) = diagonal {
            for (j, w) in weights.iter().enumerate() {
                a[(at + j, j)] = *w;
            }
        }
        Self::of_matrix(a, b)
    }

    /// The Euclidean norm of each column of A (that of R's columns: Q is orthogonal).
    pub(super) fn column_norms(&self) -> Vec<f64> {
        self.r.column_iter().map(|c| c.norm()).collect()
    }

    /// The solution and the condition number of A (largest over smallest singular value); `None` when A is
    /// singular to working precision or not finite.
    pub(super) fn solve(&self) -> Option<(Vec<f64>, f64)> {
        let m = self.r.ncols();
        if self.r.nrows() < m {
            return None;
        }
        let singular = self.r.clone().singular_values();
        let (largest, smallest) = (singular.max(), singular.min());
        if smallest <= largest * 1e-15 || !largest.is_finite() {
            return None;
        }
        let x = self.r.solve_upper_triangular(&self.qtb)?;
        Some((x.iter().copied().collect(), largest / smallest))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The old path: one Householder QR of the whole dense matrix.
    fn dense(a: &DMatrix<f64>, b: &DVector<f64>) -> Vec<f64> {
        let qr = a.clone().qr();
        let mut qtb = b.clone();
        qr.q_tr_mul(&mut qtb);
        let m = a.ncols();
        let x = qr.r().solve_upper_triangular(&qtb.rows(0, m)).unwrap();
        x.iter().copied().collect()
    }

    #[test]
    fn chunked_reduction_solves_like_one_dense_qr() {
        // 3 rows per item of a cubic in one variable over 5 000 items: three chunks and a ragged one, and an
        // ill-conditioned (Vandermonde) system, where normal equations would lose half the digits.
        let m = 7;
        let row = |t: f64| -> Vec<f64> { (0..m).map(|k| t.powi(k as i32)).collect() };
        let emit = |item: usize, rows: &mut Rows| {
            let t = item as f64 / 5_000.0 * 2.0 - 1.0;
            for (shift, target) in [(0.0, 0.0), (1e-3, 1e-3), (-1e-3, -1e-3)] {
                rows.push((3.0 * t).sin() + target)
                    .copy_from_slice(&row(t + shift));
            }
        };
        let reduced = Reduced::of_rows(5_000, 3, m, emit);
        let mut a = DMatrix::<f64>::zeros(15_000, m);
        let mut b = DVector::<f64>::zeros(15_000);
        let mut at = 0;
        let (mut values, mut targets) = (Vec::new(), Vec::new());
        let mut rows = Rows {
            m,
            values: &mut values,
            targets: &mut targets,
        };
        for item in 0..5_000 {
            emit(item, &mut rows);
        }
        for (i, target) in targets.iter().enumerate() {
            a.row_mut(i).copy_from_slice(&values[i * m..(i + 1) * m]);
            b[i] = *target;
            at += 1;
        }
        assert_eq!(at, 15_000);
        let (x, condition) = reduced.solve().unwrap();
        let expected = dense(&a, &b);
        let scale = expected.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        for (got, want) in x.iter().zip(&expected) {
            assert!((got - want).abs() <= 1e-12 * scale, "{got} vs {want}");
        }
        assert!(condition > 10.0, "condition {condition}");
        // A regularised stack: the extra diagonal rows as a dense matrix would have them.
        let weights = vec![0.5; m];
        let both = Reduced::stack(&[reduced], Some(&weights))
            .solve()
            .unwrap()
            .0;
        let mut a_reg = a.clone().insert_rows(15_000, m, 0.0);
        for j in 0..m {
            a_reg[(15_000 + j, j)] = 0.5;
        }
        let b_reg = b.clone().insert_rows(15_000, m, 0.0);
        let expected = dense(&a_reg, &b_reg);
        for (got, want) in both.iter().zip(&expected) {
            assert!((got - want).abs() <= 1e-12 * scale, "{got} vs {want}");
        }
    }

    #[test]
    fn a_singular_system_is_refused() {
        let reduced = Reduced::of_rows(100, 1, 2, |i, rows| {
            rows.push(i as f64).copy_from_slice(&[1.0, 2.0])
        });
        assert!(reduced.solve().is_none());
    }
}

//! A square sparse matrix in compressed rows with sorted columns, u32 indices.
//!
//! Every matrix this crate assembles is square and (apart from the boundary-curve rows) symmetric,
//! so the same arrays read as compressed *columns* of the transpose: that is how they are handed to
//! faer's sparse Cholesky without a copy. u32 indices halve the index traffic of the sparse
//! products, which are memory-bound.

use rayon::prelude::*;

/// Square sparse matrix, compressed rows, sorted column indices, diagonal always present.
#[derive(Clone, Debug, PartialEq)]
pub struct Csr {
    pub n: usize,
    pub row_ptr: Vec<u32>,
    pub col: Vec<u32>,
    pub val: Vec<f64>,
}

/// Rows below this count run serially (rayon's overhead dominates small products).
const PAR_ROWS: usize = 20_000;

impl Csr {
    pub fn nnz(&self) -> usize {
        self.col.len()
    }

    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (a, b) = (self.row_ptr[i] as usize, self.row_ptr[i + 1] as usize);
        (&self.col[a..b], &self.val[a..b])
    }

    /// Entry (i, j), zero when not stored.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (c, v) = self.row(i);
        match c.binary_search(&(j as u32)) {
            Ok(k) => v[k],
            Err(_) => 0.0,
        }
    }

    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n).map(|i| self.get(i, i)).collect()
    }

    /// Largest |A_ij − A_ji| (0 for a symmetric matrix); O(nnz log deg).
    pub fn asymmetry(&self) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..self.n {
            let (c, v) = self.row(i);
            for (&j, &a) in c.iter().zip(v) {
                worst = worst.max((a - self.get(j as usize, i)).abs());
            }
        }
        worst
    }

    /// y = A·x for `k` ≤ 4 interleaved columns (x[i*k + c]), rows in parallel for large matrices.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64], k: usize) {
        assert!(x.len() == self.n * k && y.len() == self.n * k, "mul_vec: sizes");
        match k {
            1 => self.mul::<1>(x, y),
            2 => self.mul::<2>(x, y),
            3 => self.mul::<3>(x, y),
            4 => self.mul::<4>(x, y),
            _ => panic!("mul_vec supports 1 to 4 interleaved columns"),
        }
    }

    fn mul<const K: usize>(&self, x: &[f64], y: &mut [f64]) {
        let row = |(i, yi): (usize, &mut [f64])| {
            let (a, b) = (self.row_ptr[i] as usize, self.row_ptr[i + 1] as usize);
            let mut acc = [0.0f64; K];
            for (&j, &v) in self.col[a..b].iter().zip(&self.val[a..b]) {
                let xj = &x[j as usize * K..j as usize * K + K];
                for c in 0..K {
                    acc[c] += v * xj[c];
                }
            }
            yi.copy_from_slice(&acc);
        };
        if self.n >= PAR_ROWS {
            y.par_chunks_mut(K).enumerate().with_min_len(2048).for_each(row);
        } else {
            y.chunks_mut(K).enumerate().for_each(row);
        }
    }

    /// The dense matrix (tests only; n² memory).
    pub fn to_dense(&self) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; self.n]; self.n];
        for (i, row) in d.iter_mut().enumerate() {
            let (c, v) = self.row(i);
            for (&j, &a) in c.iter().zip(v) {
                row[j as usize] += a;
            }
        }
        d
    }

    /// D·A (row scaling by `d`), same pattern.
    pub fn scale_rows(&self, d: &[f64]) -> Csr {
        let mut out = self.clone();
        for i in 0..self.n {
            let (a, b) = (self.row_ptr[i] as usize, self.row_ptr[i + 1] as usize);
            for v in &mut out.val[a..b] {
                *v *= d[i];
            }
        }
        out
    }

    /// Index of the diagonal entry of each row.
    pub fn diagonal_positions(&self) -> Vec<usize> {
        (0..self.n)
            .map(|i| {
                let (c, _) = self.row(i);
                self.row_ptr[i] as usize + c.binary_search(&(i as u32)).unwrap_or(0)
            })
            .collect()
    }
}

/// Splits `data` into one mutable slice per row of `ptr` (so rows can be processed in parallel).
pub(crate) fn split_rows_mut<'a, T>(mut data: &'a mut [T], ptr: &[u32]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(ptr.len().saturating_sub(1));
    for w in ptr.windows(2) {
        let (head, tail) = std::mem::take(&mut data).split_at_mut((w[1] - w[0]) as usize);
        out.push(head);
        data = tail;
    }
    out
}

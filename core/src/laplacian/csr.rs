//! A square sparse matrix in compressed rows with sorted columns, u32 indices.
//!
//! Every matrix this crate assembles is square and (apart from the boundary-curve rows) symmetric,
//! so the same arrays read as compressed *columns* of the transpose: that is how they are handed to
//! faer's sparse Cholesky without a copy. u32 indices halve the index traffic of the sparse
//! products, which are memory-bound.

use rayon::prelude::*;

use crate::error::Result;
use crate::job::Progress;

/// Square sparse matrix, compressed rows, sorted column indices, diagonal always present.
#[derive(Clone, Debug, PartialEq)]
pub struct Csr {
    pub n: usize,
    pub row_ptr: Vec<u32>,
    pub col: Vec<u32>,
    pub val: Vec<f64>,
}

/// Triplets moved between two polls of [`Csr::from_triplets_polled`] (a few ms).
const TRIPLETS_PER_POLL: usize = 1 << 18;
/// Rows sorted between two polls of [`Csr::from_triplets_polled`].
const ROWS_PER_POLL: usize = 512;

/// Rows below this count run serially (rayon's overhead dominates small products).
const PAR_ROWS: usize = 20_000;

impl Csr {
    /// The `n × n` matrix summing the `(i, j, v)` entries (duplicates added up, a zero diagonal
    /// entry stored where none is given).
    pub fn from_triplets(n: usize, t: Vec<(u32, u32, f64)>) -> Csr {
        Csr::from_triplets_polled(n, t, &Progress::new())
            .expect("from_triplets_polled fails only through progress.check(), and a fresh Progress is never cancelled")
    }

    /// [`Csr::from_triplets`], polling `progress`. The entries are bucketed by row (a counting
    /// sort) and each short row is then sorted by column: O(entries) and interruptible, where one
    /// sort of all entries (millions for a 30k-unknown highlight fairing QP) is neither.
    pub fn from_triplets_polled(n: usize, t: Vec<(u32, u32, f64)>, progress: &Progress) -> Result<Csr> {
        // Each row's diagonal first, so that it is stored even when no triplet names it.
        let mut start = vec![0usize; n + 1];
        for (k, &(i, _, _)) in t.iter().enumerate() {
            progress.check_every(k, 4 * TRIPLETS_PER_POLL)?;
            start[i as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i] + 1;
        }
        let mut next = start.clone();
        let mut entries = vec![(0u32, 0.0f64); t.len() + n];
        for (i, e) in next.iter_mut().take(n).enumerate() {
            entries[*e] = (i as u32, 0.0);
            *e += 1;
        }
        for (k, &(i, j, v)) in t.iter().enumerate() {
            progress.check_every(k, TRIPLETS_PER_POLL)?;
            entries[next[i as usize]] = (j, v);
            next[i as usize] += 1;
        }
        drop(t);
        let mut m = Csr { n, row_ptr: Vec::with_capacity(n + 1), col: Vec::new(), val: Vec::new() };
        m.row_ptr.push(0);
        for i in 0..n {
            progress.check_every(i, ROWS_PER_POLL)?;
            let row = &mut entries[start[i]..start[i + 1]];
            // Stable: duplicates are summed in the order they were supplied.
            row.sort_by_key(|e| e.0);
            let row_start = m.col.len();
            for &(j, v) in row.iter() {
                match (m.col.last(), m.val.last_mut()) {
                    (Some(&last), Some(x)) if m.col.len() > row_start && last == j => *x += v,
                    _ => {
                        m.col.push(j);
                        m.val.push(v);
                    }
                }
            }
            m.row_ptr.push(m.col.len() as u32);
        }
        Ok(m)
    }

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triplets_are_summed_sorted_and_get_a_diagonal() {
        // Row 0: (0,2) given twice, (0,0) once; row 1: nothing (zero diagonal stored); row 2:
        // columns out of order.
        let t = vec![(0, 2, 1.5), (2, 1, -1.0), (0, 0, 4.0), (2, 0, 3.0), (0, 2, 0.5), (2, 2, 2.0)];
        let a = Csr::from_triplets(3, t);
        assert_eq!(a.row_ptr, vec![0, 2, 3, 6]);
        assert_eq!(a.col, vec![0, 2, 1, 0, 1, 2]);
        assert_eq!(a.to_dense(), vec![vec![4.0, 0.0, 2.0], vec![0.0, 0.0, 0.0], vec![3.0, -1.0, 2.0]]);
        assert_eq!(a.diagonal_positions(), vec![0, 2, 5]);
    }

    #[test]
    fn triplet_assembly_polls_per_rows_and_stops_at_a_cancel() {
        let n = 3 * ROWS_PER_POLL;
        let t: Vec<(u32, u32, f64)> = (0..n as u32).map(|i| (i, (i + 1) % n as u32, 1.0)).collect();
        let p = Progress::new();
        let a = Csr::from_triplets_polled(n, t.clone(), &p).unwrap();
        assert_eq!(a.nnz(), 2 * n);
        // One poll at triplet 0 of each of the two passes over them, one per ROWS_PER_POLL rows.
        assert_eq!(p.checks(), 2 + 3);
        let p = Progress::new();
        p.cancel_at_check(4);
        assert!(matches!(Csr::from_triplets_polled(n, t, &p), Err(crate::Error::Cancelled)));
    }
}

//! The stencil of an operator: its sparsity pattern and, per stored entry, the face pairs that
//! contribute to it, so that values are refilled from per-pair weights without a rebuild.

use rayon::prelude::*;

use super::csr::{split_rows_mut, Csr};
use crate::error::{Error, Result};
use crate::mesh::Faces;

/// Which vertex pairs of a face the stencil holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairLayout {
    /// Polygon edges only (uniform operator).
    Edges,
    /// Every pair of the face's vertices: edges first (pair k = corners (k, k+1)), then diagonals.
    AllPairs,
}

const EDGE_FLAG: u32 = 1 << 31;

/// The sparsity pattern of an operator with, for every stored entry, the list of face pairs that
/// contribute to it. Built once per connectivity; values are refilled from per-pair weights, so
/// re-assembly (mean-curvature flow) costs one pass over the faces and one over the entries.
#[derive(Debug, Clone)]
pub struct Stencil {
    pub n: usize,
    pub layout: PairLayout,
    /// Pairs of face f are `pair_offset[f]..pair_offset[f+1]` in the per-pair weight array.
    pub pair_offset: Vec<u32>,
    /// Pattern (values zero), sorted columns, diagonal present in every row.
    pub pattern: Csr,
    /// Entries of slot s (an index into `pattern.col`) are `slot_ptr[s]..slot_ptr[s+1]` of `entry`.
    slot_ptr: Vec<u32>,
    /// Pair index of each entry; the top bit says the pair is a polygon edge.
    entry: Vec<u32>,
    /// Per slot: number of faces having this pair as an edge (saturating at 255).
    pub edge_mult: Vec<u8>,
    pub diag_pos: Vec<usize>,
}

fn pairs_of(arity: usize, layout: PairLayout) -> usize {
    match layout {
        PairLayout::Edges => arity,
        PairLayout::AllPairs => arity * arity.saturating_sub(1) / 2,
    }
}

/// Local (corner, corner) of pair `p` of a face with `k` corners in the AllPairs/Edges layout:
/// pairs 0..k are the edges (c, c+1), then the diagonals (i, j), i < j−1, row by row.
pub(super) fn local_pairs(k: usize, layout: PairLayout) -> Vec<(usize, usize)> {
    let mut v: Vec<(usize, usize)> = (0..k).map(|c| (c, (c + 1) % k)).collect();
    if layout == PairLayout::AllPairs && k > 3 {
        for i in 0..k {
            for j in i + 2..k {
                if !(i == 0 && j == k - 1) {
                    v.push((i, j));
                }
            }
        }
    }
    v
}

impl Stencil {
    /// Builds the pattern of the operators on `faces` over `n` vertices.
    pub fn new(faces: &Faces, n: usize, layout: PairLayout) -> Result<Stencil> {
        let nf = faces.len();
        let mut pair_offset = Vec::with_capacity(nf + 1);
        pair_offset.push(0u32);
        let mut total = 0usize;
        for f in 0..nf {
            total += pairs_of(faces.arity(f), layout);
            pair_offset.push(u32::try_from(total).map_err(|_| too_large("operator pairs", total))?);
        }
        if total >= EDGE_FLAG as usize || 2 * total >= u32::MAX as usize {
            return Err(too_large("operator pairs", total));
        }
        // Directed entries (row, col, pair) by counting sort on the row. Triangle meshes take a
        // direct loop (this is the hot path of every assembly from scratch).
        let mut count = vec![0u32; n + 1];
        let tris = faces.as_triangles();
        if let Some(t) = tris {
            for &v in t {
                count[v as usize + 1] += 2;
            }
            // Repeated corners (a == b) would be skipped below: uncount them.
            for t in t.chunks_exact(3) {
                for c in 0..3 {
                    if t[c] == t[(c + 1) % 3] {
                        count[t[c] as usize + 1] -= 2;
                    }
                }
            }
        } else {
            for f in 0..nf {
                for_pairs(faces.get(f), pair_offset[f], layout, &mut |a, b, _| {
                    if a != b {
                        count[a as usize + 1] += 1;
                        count[b as usize + 1] += 1;
                    }
                });
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let ent_ptr = count.clone();
        let mut fill = count;
        let m = ent_ptr[n] as usize;
        let mut ent: Vec<(u32, u32)> = vec![(0, 0); m];
        let mut put = |a: u32, b: u32, p: u32| {
            if a != b {
                ent[fill[a as usize] as usize] = (b, p);
                fill[a as usize] += 1;
                ent[fill[b as usize] as usize] = (a, p);
                fill[b as usize] += 1;
            }
        };
        if let Some(t) = tris {
            for (f, t) in t.chunks_exact(3).enumerate() {
                let base = 3 * f as u32;
                put(t[0], t[1], base | EDGE_FLAG);
                put(t[1], t[2], (base + 1) | EDGE_FLAG);
                put(t[2], t[0], (base + 2) | EDGE_FLAG);
            }
        } else {
            for f in 0..nf {
                for_pairs(faces.get(f), pair_offset[f], layout, &mut put);
            }
        }
        // Per row: sort by column, count distinct columns (+ diagonal).
        let mut rows = split_rows_mut(&mut ent, &ent_ptr);
        let row_len: Vec<u32> = rows
            .par_iter_mut()
            .enumerate()
            .with_min_len(512)
            .map(|(i, r)| {
                r.sort_unstable();
                let mut distinct = 1; // diagonal
                let mut last = u32::MAX;
                for &(c, _) in r.iter() {
                    if c != last && c as usize != i {
                        distinct += 1;
                    }
                    last = c;
                }
                distinct
            })
            .collect();
        drop(rows);
        let mut row_ptr = Vec::with_capacity(n + 1);
        row_ptr.push(0u32);
        let mut acc = 0u64;
        for &l in &row_len {
            acc += l as u64;
            row_ptr.push(u32::try_from(acc).map_err(|_| too_large("operator entries", acc as usize))?);
        }
        let nnz = acc as usize;
        let mut col = vec![0u32; nnz];
        let mut slot_start = vec![0u32; nnz];
        let mut edge_mult = vec![0u8; nnz];
        {
            let cols = split_rows_mut(&mut col, &row_ptr);
            let starts = split_rows_mut(&mut slot_start, &row_ptr);
            let mults = split_rows_mut(&mut edge_mult, &row_ptr);
            let ents = &ent;
            let ent_ptr = &ent_ptr;
            cols.into_par_iter().zip(starts).zip(mults).enumerate().with_min_len(512).for_each(
                |(i, ((cols, starts), mults))| {
                    let r = &ents[ent_ptr[i] as usize..ent_ptr[i + 1] as usize];
                    let mut s = 0usize;
                    let mut k = 0usize;
                    let mut diag_done = false;
                    while k < r.len() || !diag_done {
                        let next = if k < r.len() { r[k].0 } else { u32::MAX };
                        if !diag_done && (i as u32) < next {
                            cols[s] = i as u32;
                            starts[s] = ent_ptr[i] + k as u32;
                            mults[s] = 0;
                            s += 1;
                            diag_done = true;
                            continue;
                        }
                        let c = next;
                        let start = k;
                        let mut edges = 0u32;
                        while k < r.len() && r[k].0 == c {
                            edges += (r[k].1 & EDGE_FLAG != 0) as u32;
                            k += 1;
                        }
                        cols[s] = c;
                        starts[s] = ent_ptr[i] + start as u32;
                        mults[s] = edges.min(255) as u8;
                        s += 1;
                    }
                },
            );
        }
        let mut slot_ptr = slot_start;
        slot_ptr.push(m as u32);
        let entry: Vec<u32> = ent.into_iter().map(|(_, p)| p).collect();
        let pattern = Csr { n, row_ptr, col, val: vec![0.0; nnz] };
        let diag_pos = pattern.diagonal_positions();
        Ok(Stencil { n, layout, pair_offset, pattern, slot_ptr, entry, edge_mult, diag_pos })
    }

    /// The pattern of the uniform (umbrella) operator only: edge neighbours, edge multiplicities
    /// and the diagonal, without the per-pair entry lists that weighted assembly needs (so about
    /// half the work and memory of [`Stencil::new`]). [`Stencil::stiffness`] must not be called on
    /// it; [`Stencil::uniform_stiffness`] and everything topological works.
    pub fn uniform(faces: &Faces, n: usize) -> Result<Stencil> {
        let corners = faces.indices().len();
        if 2 * corners >= u32::MAX as usize {
            return Err(too_large("operator entries", 2 * corners));
        }
        // Directed neighbour entries (both directions of every polygon edge), counting sort by row.
        let mut count = vec![0u32; n + 1];
        let each_edge = |g: &mut dyn FnMut(u32, u32)| {
            if let Some(t) = faces.as_triangles() {
                for t in t.chunks_exact(3) {
                    g(t[0], t[1]);
                    g(t[1], t[2]);
                    g(t[2], t[0]);
                }
            } else {
                for f in faces.iter() {
                    for k in 0..f.len() {
                        g(f[k], f[(k + 1) % f.len()]);
                    }
                }
            }
        };
        each_edge(&mut |a, b| {
            if a != b {
                count[a as usize + 1] += 1;
                count[b as usize + 1] += 1;
            }
        });
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let ent_ptr = count.clone();
        let mut fill = count;
        let mut nb = vec![0u32; ent_ptr[n] as usize];
        each_edge(&mut |a, b| {
            if a != b {
                nb[fill[a as usize] as usize] = b;
                fill[a as usize] += 1;
                nb[fill[b as usize] as usize] = a;
                fill[b as usize] += 1;
            }
        });
        drop(fill);
        // Per row: sort, count distinct neighbours (+ the diagonal).
        let row_len: Vec<u32> = split_rows_mut(&mut nb, &ent_ptr)
            .into_par_iter()
            .with_min_len(1024)
            .map(|r| {
                r.sort_unstable();
                1 + r.iter().enumerate().filter(|&(k, &c)| k == 0 || r[k - 1] != c).count() as u32
            })
            .collect();
        let mut row_ptr = Vec::with_capacity(n + 1);
        row_ptr.push(0u32);
        let mut acc = 0u64;
        for &l in &row_len {
            acc += l as u64;
            row_ptr.push(u32::try_from(acc).map_err(|_| too_large("operator entries", acc as usize))?);
        }
        let nnz = acc as usize;
        let mut col = vec![0u32; nnz];
        let mut edge_mult = vec![0u8; nnz];
        let mut diag_pos = vec![0usize; n];
        split_rows_mut(&mut col, &row_ptr)
            .into_par_iter()
            .zip(split_rows_mut(&mut edge_mult, &row_ptr))
            .zip(diag_pos.par_iter_mut())
            .enumerate()
            .with_min_len(1024)
            .for_each(|(i, ((cols, mults), dpos))| {
                let r = &nb[ent_ptr[i] as usize..ent_ptr[i + 1] as usize];
                let (mut s, mut k) = (0usize, 0usize);
                let mut diag_done = false;
                while k < r.len() || !diag_done {
                    let c = if k < r.len() { r[k] } else { u32::MAX };
                    if !diag_done && (i as u32) < c {
                        cols[s] = i as u32;
                        mults[s] = 0;
                        *dpos = row_ptr[i] as usize + s;
                        s += 1;
                        diag_done = true;
                        continue;
                    }
                    let start = k;
                    while k < r.len() && r[k] == c {
                        k += 1;
                    }
                    cols[s] = c;
                    mults[s] = (k - start).min(255) as u8;
                    s += 1;
                }
            });
        let pattern = Csr { n, row_ptr, col, val: vec![0.0; nnz] };
        Ok(Stencil {
            n,
            layout: PairLayout::Edges,
            pair_offset: vec![0],
            pattern,
            slot_ptr: Vec::new(),
            entry: Vec::new(),
            edge_mult,
            diag_pos,
        })
    }

    pub fn pair_count(&self) -> usize {
        *self.pair_offset.last().unwrap_or(&0) as usize
    }

    /// Stiffness `S` from per-pair weights: `S_ij = −½ Σ w_pair`, diagonal = −Σ off-diagonals.
    pub fn stiffness(&self, pair_w: &[f64]) -> Csr {
        assert!(
            self.slot_ptr.len() == self.pattern.nnz() + 1,
            "Stencil::stiffness needs a stencil built by Stencil::new (not Stencil::uniform)"
        );
        let mut s = self.pattern.clone();
        let slot_ptr = &self.slot_ptr;
        let entry = &self.entry;
        s.val.par_iter_mut().enumerate().with_min_len(4096).for_each(|(k, v)| {
            let mut acc = 0.0;
            for &e in &entry[slot_ptr[k] as usize..slot_ptr[k + 1] as usize] {
                acc += pair_w[(e & !EDGE_FLAG) as usize];
            }
            *v = -0.5 * acc;
        });
        self.fix_diagonal(&mut s);
        s
    }

    /// Uniform (umbrella) stiffness: −1 for every edge neighbour, valence on the diagonal.
    /// Pairs that are only polygon diagonals get an explicit 0.
    pub fn uniform_stiffness(&self) -> Csr {
        let mut s = self.pattern.clone();
        s.val.par_iter_mut().zip(&self.edge_mult).with_min_len(4096).for_each(|(v, &m)| {
            *v = if m > 0 { -1.0 } else { 0.0 };
        });
        self.fix_diagonal(&mut s);
        s
    }

    fn fix_diagonal(&self, s: &mut Csr) {
        let sums: Vec<f64> = (0..self.n)
            .into_par_iter()
            .with_min_len(2048)
            .map(|i| {
                let (a, b) = (s.row_ptr[i] as usize, s.row_ptr[i + 1] as usize);
                -(s.val[a..b].iter().sum::<f64>() - s.val[self.diag_pos[i]])
            })
            .collect();
        for (i, d) in sums.into_iter().enumerate() {
            s.val[self.diag_pos[i]] = d;
        }
    }

    /// Vertices on an open boundary: incident to an edge that belongs to exactly one face.
    pub fn boundary_vertices(&self) -> Vec<bool> {
        let p = &self.pattern;
        (0..self.n)
            .map(|i| (p.row_ptr[i] as usize..p.row_ptr[i + 1] as usize).any(|s| self.edge_mult[s] == 1))
            .collect()
    }

    /// Number of edges shared by more than two faces.
    pub fn nonmanifold_edges(&self) -> usize {
        let p = &self.pattern;
        (0..self.n)
            .map(|i| {
                (p.row_ptr[i] as usize..p.row_ptr[i + 1] as usize)
                    .filter(|&s| p.col[s] as usize > i && self.edge_mult[s] > 2)
                    .count()
            })
            .sum()
    }

    /// Boundary neighbours of a vertex (other ends of its boundary edges).
    pub fn boundary_neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let p = &self.pattern;
        (p.row_ptr[i] as usize..p.row_ptr[i + 1] as usize)
            .filter(move |&s| self.edge_mult[s] == 1)
            .map(move |s| p.col[s] as usize)
    }
}

/// Calls `g(a, b, pair | edge flag)` for every pair of `face` in `layout`, pairs numbered from `base`.
fn for_pairs(face: &[u32], base: u32, layout: PairLayout, g: &mut dyn FnMut(u32, u32, u32)) {
    if face.len() == 3 {
        for c in 0..3 {
            g(face[c], face[(c + 1) % 3], (base + c as u32) | EDGE_FLAG);
        }
    } else {
        for (p, &(a, b)) in local_pairs(face.len(), layout).iter().enumerate() {
            let flag = if p < face.len() { EDGE_FLAG } else { 0 };
            g(face[a], face[b], (base + p as u32) | flag);
        }
    }
}

fn too_large(what: &str, n: usize) -> Error {
    Error::TooLarge { what: what.into(), limit: u32::MAX as u64 / 2, actual: n as u64 }
}

//! Discrete Laplace operators and mass matrices on polygon meshes.
//!
//! # Conventions (fixed here once; seed 004 §1.6 lists where the thesis is inconsistent)
//!
//! * Every operator is stored as a **symmetric positive-semidefinite stiffness** `S` (positive
//!   diagonal, non-positive off-diagonals for positive weights, rows summing to zero) plus a
//!   **per-vertex scale** `d`. The row operator is `L = diag(d)⁻¹ S ≈ −Δ` (the sign of eq. 3-6/3-7).
//!   Smoothing therefore moves `x ← x − λ L x` explicitly, or solves `(D + h S) x = D x₀`
//!   implicitly, which is symmetric positive definite for every operator below, so one sparse
//!   Cholesky (or CG) serves them all.
//! * **Weights** `w_ij` follow the thesis: `w_ij = Σ cot(opposite angle)` over the triangles that
//!   contain the pair, so for two triangles `w = cot α + cot β` (eq. 3-5 case a) and
//!   `S_ij = −w_ij / 2` (the Dirichlet-energy matrix; libigl's `cotmatrix` is `−S`).
//! * **Polygons** (the documented extension, "fan average"): a face with `k` corners contributes
//!   the mean, over its `k` fan triangulations (one fan from each corner), of the cotangent
//!   weights of the fan triangles. For a quad the fans from opposite corners coincide, so the mean
//!   is ½·(triangulation along one diagonal + triangulation along the other): exactly Xiong's
//!   mean operator used by TQLBO (eq. 3-5 cases b–e, and the ring area of eq. 3-4). Consequences:
//!   case (b) on unit squares gives 2, case (c) (the diagonal vertex) gets
//!   `½(cot θ_j2 + cot θ_j5)` (the derivation's factor, not the printed one; 0 on rectangles), and
//!   an n-gon is never rejected: it is an average of valid triangulations, so `S` stays symmetric
//!   PSD with zero row sums. The stencil of a polygon includes all its vertex pairs (face
//!   adjacency, as the thesis's N(v_i)).
//! * **Scales `d`**: `uniform` → valence (umbrella); `cotan` → lumped mass (barycentric or
//!   mixed Voronoi of Meyer et al.); `tqlbo` → ring area `A_i` of eq. 3-4, so
//!   `L_ij = −w_ij / (2A_i)` (eq. 3-6); `tqlbo_normalized` → `Σ_j w_ij / 2`, so
//!   `L_ij = −w_ij / Σ_j w_ij`, diagonal 1 (eq. 3-7).
//! * **Degenerate elements** are judged by shape, not by absolute size: a triangle whose
//!   `2·area < 1e-10 · (longest edge)²` contributes no cotangent weight (its angles are
//!   meaningless), and a vertex whose scale is below `1e-12` of the mesh's mean is locked. The
//!   thesis/Blender lock every vertex next to a face of area < 1e-5, which freezes a whole model
//!   measured in metres (the Stanford bunny); ours does not depend on units.
//! * **Boundary curve rows** (eq. 4-3 with corrected row sums): a boundary vertex is smoothed as a
//!   1-D curve along its boundary edges: `B_ij = −2 e_ij / E_i`, `B_ii = 2`, with
//!   `e_ij = 1/|x_i − x_j|` and `E_i` summed over boundary neighbours only. On a uniformly
//!   spaced straight boundary this is the 1-D second difference (−1, 2, −1).

pub mod csr;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use csr::split_rows_mut;
pub use csr::Csr;

use crate::error::{Error, Result};
use crate::geometry::{cross, dist, dot, norm, sub};
use crate::mesh::{Faces, Point3};

/// Which discrete Laplacian to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum OperatorKind {
    /// Umbrella operator: every edge neighbour weighs 1, scale = valence.
    Uniform,
    /// Cotangent weights (fan average on polygons), scale = lumped mass (`mass` parameter).
    #[default]
    Cotan,
    /// Seed 004 hybrid quad/triangle operator, eq. 3-6: scale = ring area of eq. 3-4.
    Tqlbo,
    /// Seed 004 normalised operator, eq. 3-7: scale-free, diagonal 1.
    TqlboNormalized,
}

/// Lumped (diagonal) mass matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum MassKind {
    /// One third of the incident triangle areas.
    Barycentric,
    /// Meyer et al. mixed Voronoi areas (obtuse triangles split ½/¼/¼).
    #[default]
    Voronoi,
}

impl OperatorKind {
    /// True when the operator's scale is an area, so a time step has units of length².
    pub fn area_scaled(self) -> bool {
        matches!(self, OperatorKind::Cotan | OperatorKind::Tqlbo)
    }
}

/// Which vertex pairs of a face the stencil holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairLayout {
    /// Polygon edges only (uniform operator).
    Edges,
    /// Every pair of the face's vertices: edges first (pair k = corners (k, k+1)), then diagonals.
    AllPairs,
}

/// Relative shape threshold below which a triangle's cotangents are dropped (see module docs).
pub const DEGENERATE_SHAPE: f64 = 1e-10;
/// A vertex whose scale is below this fraction of the mean scale is locked.
pub const LOCK_RELATIVE: f64 = 1e-12;
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
fn local_pairs(k: usize, layout: PairLayout) -> Vec<(usize, usize)> {
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

/// Per-face geometric terms, from one pass over the faces.
#[derive(Debug, Clone)]
pub struct FaceTerms {
    /// Cotangent weight per face pair (stencil layout), fan-averaged on polygons.
    pub pair_w: Vec<f64>,
    /// Per-vertex barycentric mass (⅓ incident triangle area).
    pub mass_barycentric: Vec<f64>,
    /// Per-vertex mixed Voronoi mass.
    pub mass_voronoi: Vec<f64>,
    /// Per-vertex ring area of eq. 3-4 (full incident triangle areas, mean over quad diagonals).
    pub ring_area: Vec<f64>,
    /// Triangles (or fan triangles of polygons) below the shape threshold: no cotangent weight.
    pub degenerate_triangles: usize,
}

/// Per-corner terms of one triangle: cot at each corner, barycentric, Voronoi, ring area.
#[inline]
pub(crate) fn triangle_terms(p: [Point3; 3]) -> ([f64; 3], [f64; 3], f64, bool) {
    let e = [sub(p[2], p[1]), sub(p[0], p[2]), sub(p[1], p[0])]; // edge opposite corner c
    let l2 = [dot(e[0], e[0]), dot(e[1], e[1]), dot(e[2], e[2])];
    let twice_area = norm(cross(e[2], sub(p[2], p[0])));
    let lmax2 = l2[0].max(l2[1]).max(l2[2]);
    let area = 0.5 * twice_area;
    if !(twice_area > DEGENERATE_SHAPE * lmax2) {
        return ([0.0; 3], [area / 3.0; 3], area, true);
    }
    // cot at corner c = (u·v)/|u×v| with u, v the edges leaving c; u·v = (l_u² + l_v² − l_opp²)/2.
    let cot = [
        (l2[1] + l2[2] - l2[0]) / (2.0 * twice_area),
        (l2[2] + l2[0] - l2[1]) / (2.0 * twice_area),
        (l2[0] + l2[1] - l2[2]) / (2.0 * twice_area),
    ];
    let mut vor = [0.0; 3];
    if cot[0] < 0.0 || cot[1] < 0.0 || cot[2] < 0.0 {
        for c in 0..3 {
            vor[c] = if cot[c] < 0.0 { area / 2.0 } else { area / 4.0 };
        }
    } else {
        // Voronoi part of corner c: (|e_{c+1}|² cot_{c+1} + |e_{c+2}|² cot_{c+2}) / 8.
        for c in 0..3 {
            let (a, b) = ((c + 1) % 3, (c + 2) % 3);
            vor[c] = (l2[a] * cot[a] + l2[b] * cot[b]) / 8.0;
        }
    }
    (cot, vor, area, false)
}

/// Computes the per-pair cotangent weights and the per-vertex areas (stencil layout AllPairs, or
/// Edges for a triangle-only mesh, where both layouts coincide).
pub fn face_terms(positions: &[Point3], faces: &Faces, stencil: &Stencil) -> FaceTerms {
    let n = positions.len();
    let nf = faces.len();
    let mut pair_w = vec![0.0; stencil.pair_count()];
    let corners = faces.indices().len();
    // Per-corner (bary, voronoi, ring) contributions, then scattered to vertices.
    let mut corner = vec![[0.0f64; 3]; corners];
    let offsets = faces.offsets();
    let degenerate: usize = if let Some(tris) = faces.as_triangles() {
        pair_w
            .par_chunks_mut(3)
            .zip(corner.par_chunks_mut(3))
            .zip(tris.par_chunks(3))
            .with_min_len(2048)
            .map(|((w, c), t)| {
                let p = [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
                let (cot, vor, area, deg) = triangle_terms(p);
                // pair c = corners (c, c+1): opposite corner c+2.
                for k in 0..3 {
                    w[k] = cot[(k + 2) % 3];
                    c[k] = [area / 3.0, vor[k], area];
                }
                deg as usize
            })
            .sum()
    } else {
        let mut deg = 0;
        for f in 0..nf {
            let face = faces.get(f);
            let w = &mut pair_w[stencil.pair_offset[f] as usize..stencil.pair_offset[f + 1] as usize];
            let c = &mut corner[offsets[f] as usize..offsets[f + 1] as usize];
            deg += polygon_terms(positions, face, stencil.layout, w, c);
        }
        deg
    };
    let mut mass_barycentric = vec![0.0; n];
    let mut mass_voronoi = vec![0.0; n];
    let mut ring_area = vec![0.0; n];
    for (&v, c) in faces.indices().iter().zip(&corner) {
        let v = v as usize;
        mass_barycentric[v] += c[0];
        mass_voronoi[v] += c[1];
        ring_area[v] += c[2];
    }
    FaceTerms { pair_w, mass_barycentric, mass_voronoi, ring_area, degenerate_triangles: degenerate }
}

/// Fan-average terms of one polygon (see module docs); returns the number of degenerate fan
/// triangles. `w` is in the stencil's pair layout, `c` per corner (bary, voronoi, ring).
fn polygon_terms(
    positions: &[Point3],
    face: &[u32],
    layout: PairLayout,
    w: &mut [f64],
    c: &mut [[f64; 3]],
) -> usize {
    let k = face.len();
    if k < 3 {
        return 0;
    }
    let pairs = local_pairs(k, layout);
    let mut index = vec![usize::MAX; k * k];
    for (p, &(a, b)) in pairs.iter().enumerate() {
        index[a * k + b] = p;
        index[b * k + a] = p;
    }
    let fans = if k == 3 { 1 } else { k };
    let share = 1.0 / fans as f64;
    let mut deg = 0;
    for apex in 0..fans {
        for i in 1..k - 1 {
            let t = [apex, (apex + i) % k, (apex + i + 1) % k];
            let p = [
                positions[face[t[0]] as usize],
                positions[face[t[1]] as usize],
                positions[face[t[2]] as usize],
            ];
            let (cot, vor, area, d) = triangle_terms(p);
            deg += d as usize;
            for q in 0..3 {
                let (a, b) = (t[(q + 1) % 3], t[(q + 2) % 3]);
                let slot = index[a * k + b];
                if slot != usize::MAX {
                    w[slot] += share * cot[q];
                }
                c[t[q]][0] += share * area / 3.0;
                c[t[q]][1] += share * vor[q];
                c[t[q]][2] += share * area;
            }
        }
    }
    deg
}

/// A fully assembled operator: `L = diag(scale)⁻¹ · stiffness`.
#[derive(Debug, Clone)]
pub struct Operator {
    pub kind: OperatorKind,
    pub stiffness: Csr,
    pub scale: Vec<f64>,
    /// Vertices whose scale is degenerate (no area, no weight): the smoother keeps them fixed.
    pub locked: Vec<bool>,
    pub degenerate_triangles: usize,
}

impl Operator {
    /// The row operator `L = diag(scale)⁻¹ S` as a matrix (locked rows are zero).
    pub fn row_matrix(&self) -> Csr {
        let inv: Vec<f64> =
            self.scale.iter().zip(&self.locked).map(|(&d, &l)| if l { 0.0 } else { 1.0 / d }).collect();
        self.stiffness.scale_rows(&inv)
    }
}

/// Chooses the stencil layout an operator needs.
pub fn layout_for(kind: OperatorKind, faces: &Faces) -> PairLayout {
    if kind == OperatorKind::Uniform || faces.all_triangles() {
        PairLayout::Edges
    } else {
        PairLayout::AllPairs
    }
}

/// Assembles operator `kind` on a stencil built for it (see [`layout_for`]).
pub fn assemble(
    positions: &[Point3],
    faces: &Faces,
    stencil: &Stencil,
    kind: OperatorKind,
    mass: MassKind,
) -> Operator {
    let (stiffness, scale, degenerate) = if kind == OperatorKind::Uniform {
        let s = stencil.uniform_stiffness();
        let d = s.diagonal();
        (s, d, 0)
    } else {
        let t = face_terms(positions, faces, stencil);
        let s = stencil.stiffness(&t.pair_w);
        let d = match kind {
            OperatorKind::Cotan => match mass {
                MassKind::Barycentric => t.mass_barycentric,
                MassKind::Voronoi => t.mass_voronoi,
            },
            OperatorKind::Tqlbo => t.ring_area,
            _ => s.diagonal(),
        };
        (s, d, t.degenerate_triangles)
    };
    let locked = lock_degenerate(&scale);
    Operator { kind, stiffness, scale, locked, degenerate_triangles: degenerate }
}

/// Convenience: assembles on a fresh stencil.
pub fn operator(positions: &[Point3], faces: &Faces, kind: OperatorKind, mass: MassKind) -> Result<Operator> {
    let st = Stencil::new(faces, positions.len(), layout_for(kind, faces))?;
    Ok(assemble(positions, faces, &st, kind, mass))
}

/// Vertices whose scale is not positive or below `LOCK_RELATIVE` × the mean positive scale.
fn lock_degenerate(scale: &[f64]) -> Vec<bool> {
    let (sum, cnt) = scale.iter().filter(|d| **d > 0.0).fold((0.0, 0usize), |(s, c), d| (s + d, c + 1));
    let mean = if cnt > 0 { sum / cnt as f64 } else { 0.0 };
    scale.iter().map(|&d| !(d > LOCK_RELATIVE * mean) || !d.is_finite()).collect()
}

/// The cotangent stiffness of a triangle or polygon mesh (`−S` is libigl's `cotmatrix`).
pub fn cotan_stiffness(positions: &[Point3], faces: &Faces) -> Result<Csr> {
    let st = Stencil::new(faces, positions.len(), layout_for(OperatorKind::Cotan, faces))?;
    Ok(st.stiffness(&face_terms(positions, faces, &st).pair_w))
}

/// Lumped mass per vertex.
pub fn mass(positions: &[Point3], faces: &Faces, kind: MassKind) -> Result<Vec<f64>> {
    let st = Stencil::new(faces, positions.len(), layout_for(OperatorKind::Cotan, faces))?;
    let t = face_terms(positions, faces, &st);
    Ok(match kind {
        MassKind::Barycentric => t.mass_barycentric,
        MassKind::Voronoi => t.mass_voronoi,
    })
}

/// Boundary curve rows of eq. 4-3 (corrected): for each boundary vertex, `(j, B_ij)` for its
/// boundary neighbours; the diagonal is 2. Edges shorter than `min_len` are skipped (a vertex left
/// with no usable boundary edge gets no row and is treated as fixed by the caller).
pub fn boundary_curve_rows(
    stencil: &Stencil,
    positions: &[Point3],
    min_len: f64,
) -> Vec<Option<Vec<(usize, f64)>>> {
    let boundary = stencil.boundary_vertices();
    (0..stencil.n)
        .map(|i| {
            if !boundary[i] {
                return None;
            }
            let nb: Vec<(usize, f64)> = stencil
                .boundary_neighbours(i)
                .filter_map(|j| {
                    let l = dist(positions[i], positions[j]);
                    (l > min_len).then(|| (j, 1.0 / l))
                })
                .collect();
            let e: f64 = nb.iter().map(|x| x.1).sum();
            if nb.is_empty() || !(e > 0.0) {
                return Some(Vec::new());
            }
            Some(nb.into_iter().map(|(j, w)| (j, -2.0 * w / e)).collect())
        })
        .collect()
}

/// Mean edge length over the stencil's edge slots (the mesh's length scale).
pub fn mean_edge_length(stencil: &Stencil, positions: &[Point3]) -> f64 {
    let p = &stencil.pattern;
    let (mut s, mut c) = (0.0, 0usize);
    for i in 0..stencil.n {
        for k in p.row_ptr[i] as usize..p.row_ptr[i + 1] as usize {
            let j = p.col[k] as usize;
            if j > i && stencil.edge_mult[k] > 0 {
                s += dist(positions[i], positions[j]);
                c += 1;
            }
        }
    }
    if c > 0 {
        s / c as f64
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests;

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
mod stencil;
mod terms;

use serde::{Deserialize, Serialize};

pub use csr::Csr;
pub use stencil::{PairLayout, Stencil};
pub use terms::{face_terms, FaceTerms};

use crate::error::Result;
use crate::geometry::dist;
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

/// Relative shape threshold below which a triangle's cotangents are dropped (see module docs).
pub const DEGENERATE_SHAPE: f64 = 1e-10;
/// A vertex whose scale is below this fraction of the mean scale is locked.
pub const LOCK_RELATIVE: f64 = 1e-12;

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

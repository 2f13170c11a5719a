//! The spherical overlay when the two embeddings share points exactly.
//!
//! [`metamesh::overlay`] decides every corner by orientation tests with a consistent tie rule,
//! which is enough when the inputs are in general position, but not when an A-vertex sits
//! exactly on a B-vertex or a B-edge: then two corners of one polygon coincide and their order
//! is arbitrary. That is the normal case, not an accident: feature alignment moves each pair of
//! feature vertices onto the same point, a mesh morphed to itself has identical embeddings, and
//! symmetric coarse shapes (tetrahedron vs octahedron) put vertices on each other's arcs. The
//! sweep found all three falling back to the barycentric transfer (last frame off by up to 13 %
//! of the diagonal).
//!
//! Remedy: identical embeddings need no overlay (A's triangulation carries both shapes exactly);
//! otherwise, if the overlay fails, B's embedding is rotated rigidly by a tiny angle about a
//! fixed generic axis (a rotation keeps it fold-free) and the overlay is built again. The shapes
//! are carried by barycentric coordinates inside faces, so both end frames are still reproduced
//! exactly; only the pairing moves by the angle (feature pairs then meet up to ~angle × the local
//! stretch of the map, reported as `overlay_perturbation`).

use crate::error::{Error, Result};
use crate::geometry::{add, cross, dot, normalize, scale};
use crate::job::Progress;
use crate::mesh::Point3;

use super::metamesh::{self, Layer, OverlayReport};

/// Rotation angles tried after the exact overlay failed, smallest first. 1e-6 rad keeps feature
/// pairs together to ~1e-6 of the diagonal; near-parallel arcs of near-identical embeddings need
/// the crossing (precision ~1e-16/angle) to be far below the sliver width (~angle × edge), hence
/// the larger ones.
const ANGLES: [f64; 3] = [1e-6, 1e-5, 1e-4];

/// Rodrigues rotation of `p` about the unit `axis` by `angle`.
fn rotate(p: Point3, axis: Point3, angle: f64) -> Point3 {
    let (s, c) = angle.sin_cos();
    let kxp = cross(axis, p);
    add(add(scale(p, c), scale(kxp, s)), scale(axis, dot(axis, p) * (1.0 - c)))
}

/// The overlay of A and B, robust to shared points. Returns the overlay, its report and the
/// rotation angle applied to B's sphere (0 when none was needed).
pub fn overlay(a: &Layer, b: &Layer, progress: &Progress) -> Result<(Layer, OverlayReport, f64)> {
    if a.sphere == b.sphere && a.tris == b.tris {
        // Identical embeddings: every face of A is a face of B.
        let mut shapes = a.shapes.clone();
        shapes.extend(b.shapes.iter().cloned());
        let rep =
            OverlayReport { vertices: a.sphere.len(), faces: a.tris.len(), crossings: 0, empty_pairs: 0 };
        return Ok((Layer { sphere: a.sphere.clone(), tris: a.tris.clone(), shapes }, rep, 0.0));
    }
    let first = match metamesh::overlay(a, b, progress) {
        Ok((o, r)) => return Ok((o, r, 0.0)),
        Err(Error::Numerical { message, .. }) => message,
        Err(e) => return Err(e),
    };
    let axis = normalize([0.4123, -0.7311, 0.5437]);
    for angle in ANGLES {
        let rotated = Layer {
            sphere: b.sphere.iter().map(|&p| normalize(rotate(p, axis, angle))).collect(),
            tris: b.tris.clone(),
            shapes: b.shapes.clone(),
        };
        match metamesh::overlay(a, &rotated, progress) {
            Ok((o, r)) => return Ok((o, r, angle)),
            Err(Error::Numerical { .. }) => continue,
            Err(e) => return Err(e),
        }
    }
    Err(Error::numerical(
        "metamesh",
        format!("{first} (also after rotating the target's embedding by up to 1e-4 rad)"),
    ))
}

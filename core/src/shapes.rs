//! Analytic shapes for tests and benchmarks: their true geometry is known independently of any
//! code under test (a sphere's radius, a plane's normal, a grid's spacing).

use std::collections::HashMap;

use crate::geometry::{normalize, scale};
use crate::mesh::{Faces, Mesh, Point3};

/// Icosahedron subdivided `levels` times, vertices projected on the sphere of `radius` about the
/// origin. V = 10·4^levels + 2, F = 20·4^levels, outward-oriented, closed, genus 0.
pub fn icosphere(levels: u32, radius: f64) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<Point3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| normalize(p))
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        tris = split_triangles(&mut pos, &tris, |p| normalize(p));
    }
    let pos = pos.into_iter().map(|p| scale(p, radius)).collect();
    Mesh::from_triangles(pos, &tris)
}

/// The unit icosphere of `levels` with the faces around its north pole removed: those whose
/// centroid is above z = cos(`deg`) (a hole of one boundary loop for repair's hole filling).
/// Returns the mesh (all vertices kept) and the removed area.
pub fn icosphere_without_cap(levels: u32, deg: f64) -> (Mesh, f64) {
    let m = icosphere(levels, 1.0);
    let cos = deg.to_radians().cos();
    let mut removed = 0.0;
    let mut faces = Faces::new();
    for f in m.faces.iter() {
        let p: Vec<Point3> = f.iter().map(|&v| m.positions[v as usize]).collect();
        if (p[0][2] + p[1][2] + p[2][2]) / 3.0 > cos {
            removed += crate::geometry::triangle_area(p[0], p[1], p[2]);
        } else {
            faces.push(f, 0);
        }
    }
    (Mesh::new(m.positions, faces), removed)
}

/// One 1→4 midpoint subdivision of every triangle; `place` maps each new midpoint (e.g. onto a
/// sphere). Shared edges get one midpoint, so a closed mesh stays closed.
fn split_triangles(
    pos: &mut Vec<Point3>,
    tris: &[[u32; 3]],
    place: impl Fn(Point3) -> Point3,
) -> Vec<[u32; 3]> {
    let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 3 / 2);
    let mut midpoint = |a: u32, b: u32, pos: &mut Vec<Point3>| -> u32 {
        let key = (a.min(b), a.max(b));
        *mid.entry(key).or_insert_with(|| {
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            pos.push(place([(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0, (pa[2] + pb[2]) / 2.0]));
            (pos.len() - 1) as u32
        })
    };
    let mut out = Vec::with_capacity(tris.len() * 4);
    for &[a, b, c] in tris {
        let ab = midpoint(a, b, pos);
        let bc = midpoint(b, c, pos);
        let ca = midpoint(c, a, pos);
        out.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    out
}

/// Midpoint (1→4) subdivision of a triangle mesh `levels` times, geometry unchanged (new vertices
/// on the old edges). Used to make million-vertex benchmark inputs from real scans.
/// Non-triangle faces are fan-triangulated first.
pub fn subdivide_midpoint(mesh: &Mesh, levels: u32) -> Mesh {
    let mut pos = mesh.positions.clone();
    let mut tris = fan_triangles(&mesh.faces);
    for _ in 0..levels {
        tris = split_triangles(&mut pos, &tris, |p| p);
    }
    Mesh::from_triangles(pos, &tris)
}

/// Faces as triangles (see [`Faces::triangles`]: fans from the first corner unless that fan would
/// reuse an existing edge).
pub fn fan_triangles(faces: &Faces) -> Vec<[u32; 3]> {
    faces.triangles()
}

/// A planar grid in z = 0 of `nx × ny` cells with spacing `h`, as quads (`quads = true`) or as
/// triangles (each cell split along the diagonal from its lower-left corner). Vertex (i, j) has
/// index `j * (nx + 1) + i` and position (i·h, j·h, 0). Faces are oriented with normal +z.
pub fn grid(nx: usize, ny: usize, h: f64, quads: bool) -> Mesh {
    parallelogram_grid(nx, ny, [h, 0.0, 0.0], [0.0, h, 0.0], quads)
}

/// Like [`grid`] but with cell edge vectors `u` and `v` (a sheared grid gives parallelogram cells).
pub fn parallelogram_grid(nx: usize, ny: usize, u: Point3, v: Point3, quads: bool) -> Mesh {
    let mut pos = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let (fi, fj) = (i as f64, j as f64);
            pos.push([fi * u[0] + fj * v[0], fi * u[1] + fj * v[1], fi * u[2] + fj * v[2]]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut faces = Faces::with_capacity(nx * ny * 2, nx * ny * 6);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            push_quad(&mut faces, [a, b, c, d], quads);
        }
    }
    Mesh::new(pos, faces)
}

/// Pushes the quad `q` (counter-clockwise), or its two triangles split along the diagonal q0–q2.
fn push_quad(faces: &mut Faces, q: [u32; 4], quads: bool) {
    if quads {
        faces.push(&q, 0);
    } else {
        faces.push(&[q[0], q[1], q[2]], 0);
        faces.push(&[q[0], q[2], q[3]], 0);
    }
}

/// Equilateral triangle grid of `nx × ny` vertices with edge length `h` (rows offset by h/2):
/// every interior vertex has valence 6 and all angles are 60°.
pub fn triangle_grid(nx: usize, ny: usize, h: f64) -> Mesh {
    let dy = h * 3f64.sqrt() / 2.0;
    let mut pos = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        let off = if j % 2 == 1 { h / 2.0 } else { 0.0 };
        for i in 0..nx {
            pos.push([i as f64 * h + off, j as f64 * dy, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * nx + i) as u32;
    let mut tris = Vec::new();
    for j in 0..ny.saturating_sub(1) {
        for i in 0..nx.saturating_sub(1) {
            if j % 2 == 0 {
                tris.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                tris.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            }
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// Torus about the z axis with major radius `r_major`, minor `r_minor`, `nu × nv` quads
/// (triangulated when `quads` is false). Closed, genus 1, outward-oriented.
pub fn torus(nu: usize, nv: usize, r_major: f64, r_minor: f64, quads: bool) -> Mesh {
    let mut pos = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = i as f64 / nu as f64 * std::f64::consts::TAU;
        for j in 0..nv {
            let v = j as f64 / nv as f64 * std::f64::consts::TAU;
            let r = r_major + r_minor * v.cos();
            pos.push([r * u.cos(), r * u.sin(), r_minor * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut faces = Faces::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            push_quad(&mut faces, [a, b, c, d], quads);
        }
    }
    Mesh::new(pos, faces)
}

/// Regular tetrahedron with vertices at alternate corners of the cube [−1, 1]³ (circumradius √3),
/// outward-oriented.
pub fn tetrahedron() -> Mesh {
    let pos = vec![[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]];
    Mesh::from_triangles(pos, &[[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
}

/// The cube [−1, 1]³ as 12 triangles on its 8 corners (corner `i` has x, y, z = ±1 by bits 0, 1,
/// 2 of `i`), outward-oriented.
pub fn cube() -> Mesh {
    let pos: Vec<Point3> = (0..8)
        .map(|i| {
            [(i & 1) as f64 * 2.0 - 1.0, ((i >> 1) & 1) as f64 * 2.0 - 1.0, ((i >> 2) & 1) as f64 * 2.0 - 1.0]
        })
        .collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let tris: Vec<[u32; 3]> = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    Mesh::from_triangles(pos, &tris)
}

/// Regular octahedron with vertices ±eᵢ (on the unit sphere), outward-oriented.
pub fn octahedron() -> Mesh {
    let pos = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let tris = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    Mesh::from_triangles(pos, &tris)
}

/// The upper unit hemisphere by polar rings: a pole fan, `rings` rings of `seg` vertices at
/// polar angles (π/2)·i/rings, odd rings turned by half a segment; the last ring lies on the
/// equator and is the boundary. Faces oriented outwards; 1 + rings·seg vertices.
pub fn hemisphere(rings: usize, seg: usize) -> Mesh {
    let mut pos = vec![[0.0, 0.0, 1.0]];
    for i in 1..=rings {
        let phi = std::f64::consts::FRAC_PI_2 * i as f64 / rings as f64;
        for j in 0..seg {
            let th = std::f64::consts::TAU * (j as f64 + 0.5 * (i % 2) as f64) / seg as f64;
            pos.push([phi.sin() * th.cos(), phi.sin() * th.sin(), phi.cos()]);
        }
    }
    let id = |i: usize, j: usize| (1 + (i - 1) * seg + j % seg) as u32;
    let mut tris = Vec::new();
    for j in 0..seg {
        tris.push([0, id(1, j), id(1, j + 1)]);
    }
    for i in 1..rings {
        for j in 0..seg {
            let (a, b) = (id(i, j), id(i, j + 1));
            let (c, d) = (id(i + 1, j), id(i + 1, j + 1));
            tris.push([a, c, d]);
            tris.push([a, d, b]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{norm, signed_volume};

    #[test]
    fn icosphere_counts_radius_and_volume() {
        let m = icosphere(3, 2.0);
        assert_eq!(m.vertex_count(), 10 * 64 + 2);
        assert_eq!(m.face_count(), 20 * 64);
        assert!(m.positions.iter().all(|p| (norm(*p) - 2.0).abs() < 1e-12));
        let v = signed_volume(&m.positions, &m.faces);
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        // Inscribed polyhedron: slightly less than the sphere, and outward-oriented (positive).
        assert!(v > 0.97 * exact && v < exact, "{v} vs {exact}");
    }

    #[test]
    fn subdivision_keeps_shape_and_counts() {
        let m = icosphere(1, 1.0);
        let s = subdivide_midpoint(&m, 2);
        assert_eq!(s.face_count(), m.face_count() * 16);
        // Euler: V - E + F = 2 and E = 3F/2 for a closed triangle mesh.
        assert_eq!(s.vertex_count() as i64 - 3 * s.face_count() as i64 / 2 + s.face_count() as i64, 2);
        let (v0, v1) = (signed_volume(&m.positions, &m.faces), signed_volume(&s.positions, &s.faces));
        assert!((v0 - v1).abs() < 1e-12);
    }

    #[test]
    fn torus_is_genus_one_by_euler() {
        let t = torus(12, 8, 2.0, 0.5, true);
        let (v, f) = (t.vertex_count() as i64, t.face_count() as i64);
        assert_eq!(v - 2 * f + f, 0); // quads: E = 2F
        assert!(signed_volume(&t.positions, &t.faces) > 0.0);
    }

    #[test]
    fn grid_indexing() {
        let g = grid(3, 2, 0.5, true);
        assert_eq!(g.vertex_count(), 12);
        assert_eq!(g.face_count(), 6);
        assert_eq!(g.positions[4 + 2], [1.0, 0.5, 0.0]);
        let t = triangle_grid(4, 3, 1.0);
        assert_eq!(t.face_count(), 2 * 3 * 2);
    }

    #[test]
    fn platonic_solids_and_hemisphere_have_their_volumes_and_counts() {
        // Tetrahedron in the cube [−1, 1]³: the cube (8) minus four corner pyramids (4/3 each).
        assert!((signed_volume(&tetrahedron().positions, &tetrahedron().faces) - 8.0 / 3.0).abs() < 1e-12);
        // Octahedron |x|+|y|+|z| ≤ 1: 4/3, positive (outward).
        assert!((signed_volume(&octahedron().positions, &octahedron().faces) - 4.0 / 3.0).abs() < 1e-12);
        // Cube [−1, 1]³: volume 8, outward; 8 corners, 12 triangles, each corner at (±1, ±1, ±1).
        let c = cube();
        assert_eq!((c.vertex_count(), c.face_count()), (8, 12));
        assert!(c.positions.iter().all(|p| p.iter().all(|x| x.abs() == 1.0)));
        assert!((signed_volume(&c.positions, &c.faces) - 8.0).abs() < 1e-12);
        let h = hemisphere(10, 24);
        assert_eq!(h.vertex_count(), 1 + 10 * 24);
        assert_eq!(h.face_count(), 24 + 2 * 9 * 24);
        assert!(h.positions.iter().all(|p| (norm(*p) - 1.0).abs() < 1e-12 && p[2] >= -1e-15));
        // Outward: every face normal points away from the origin.
        for f in h.faces.iter() {
            let (a, b, c) =
                (h.positions[f[0] as usize], h.positions[f[1] as usize], h.positions[f[2] as usize]);
            let n = crate::geometry::cross(crate::geometry::sub(b, a), crate::geometry::sub(c, a));
            assert!(crate::geometry::dot(n, a) > 0.0);
        }
    }
}

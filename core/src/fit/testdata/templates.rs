//! Templates beyond the icosphere: an open cylinder, a paraboloid with a square hole, an n-gon
//! sphere, and edits of a mesh (holes cut, two meshes as one, a zero-area face).

use crate::geometry::{norm, sub};
use crate::mesh::{Faces, Mesh, Point3};
use crate::shapes::icosphere;

/// An open cylinder (no caps) of radius `r` about the z axis from z = 0 to z = `h`, `nu` vertices
/// around and `nv` rings, triangulated, outward-oriented, two boundary loops.
pub fn open_cylinder(nu: usize, nv: usize, r: f64, h: f64) -> Mesh {
    let mut pos = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let t = std::f64::consts::TAU * i as f64 / nu as f64;
            pos.push([r * t.cos(), r * t.sin(), h * j as f64 / (nv - 1) as f64]);
        }
    }
    let id = |i: usize, j: usize| (j * nu + i % nu) as u32;
    let mut tris = Vec::new();
    for j in 0..nv - 1 {
        for i in 0..nu {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// The paraboloid z = a (x² + y²) over [−1, 1]², an `n × n` grid of cells with the cells whose
/// centre has max(|x|, |y|) < `hole` removed (a square hole), triangulated, normals +z-ish.
pub fn paraboloid_with_hole(n: usize, a: f64, hole: f64) -> Mesh {
    let h = 2.0 / n as f64;
    let mut pos = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (-1.0 + i as f64 * h, -1.0 + j as f64 * h);
            pos.push([x, y, a * (x * x + y * y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (cx, cy) = (-1.0 + (i as f64 + 0.5) * h, -1.0 + (j as f64 + 0.5) * h);
            if cx.abs().max(cy.abs()) < hole {
                continue;
            }
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// A closed UV sphere of radius `r` with `nu` segments and `nv` rings whose poles are single
/// `nu`-gons (cut at latitude ±(90° − 90°/nv)) and whose sides are quads: an n-gon template.
pub fn ngon_sphere(nu: usize, nv: usize, r: f64) -> Mesh {
    let mut pos = Vec::new();
    for j in 0..nv {
        let lat = -std::f64::consts::PI / 2.0 + std::f64::consts::PI * (j as f64 + 0.5) / nv as f64;
        for i in 0..nu {
            let t = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
            pos.push([r * lat.cos() * t.cos(), r * lat.cos() * t.sin(), r * lat.sin()]);
        }
    }
    let id = |i: usize, j: usize| (j * nu + i % nu) as u32;
    let mut faces = Faces::new();
    let bottom: Vec<u32> = (0..nu).rev().map(|i| id(i, 0)).collect();
    faces.push(&bottom, 0);
    for j in 0..nv - 1 {
        for i in 0..nu {
            faces.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)], 0);
        }
    }
    let top: Vec<u32> = (0..nu).map(|i| id(i, nv - 1)).collect();
    faces.push(&top, 0);
    Mesh::new(pos, faces)
}

/// `m` without the faces whose centroid is within `radius` of one of `centres`.
pub fn with_holes(m: &Mesh, centres: &[Point3], radius: f64) -> Mesh {
    let mut out = m.clone();
    let pos = m.positions.clone();
    let faces = m.faces.clone();
    out.faces.retain(|i| {
        let f = faces.get(i);
        let c = f.iter().fold([0.0; 3], |a, &v| {
            let p = pos[v as usize];
            [a[0] + p[0], a[1] + p[1], a[2] + p[2]]
        });
        let c = [c[0] / f.len() as f64, c[1] / f.len() as f64, c[2] / f.len() as f64];
        centres.iter().all(|&q| norm(sub(c, q)) > radius)
    });
    out
}

/// Two meshes as one (the second's indices shifted).
pub fn disjoint_union(a: &Mesh, b: &Mesh) -> Mesh {
    let mut pos = a.positions.clone();
    pos.extend_from_slice(&b.positions);
    let n = a.positions.len() as u32;
    let mut faces = a.faces.clone();
    for f in b.faces.iter() {
        let g: Vec<u32> = f.iter().map(|&v| v + n).collect();
        faces.push(&g, 0);
    }
    Mesh::new(pos, faces)
}

/// The icosphere with one edge split by a vertex on it and a zero-area face filling the split
/// on one side, plus an unreferenced duplicate of vertex 0: closed, manifold, consistently
/// oriented, but with a degenerate face.
pub fn with_zero_area_face(levels: u32) -> Mesh {
    let m = icosphere(levels, 1.0);
    let tris = m.faces.triangles();
    let (a, b, c) = (tris[0][0], tris[0][1], tris[0][2]);
    // The face across a-b (holding b→a) is untouched: the new face (mid, a, b) takes its place
    // along that edge, and (a, mid, c), (mid, b, c) replace face 0.
    let mut pos = m.positions.clone();
    let pa = pos[a as usize];
    let pb = pos[b as usize];
    pos.push([(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0, (pa[2] + pb[2]) / 2.0]);
    let mid = (pos.len() - 1) as u32;
    pos.push(pos[0]);
    let mut out = vec![[a, mid, c], [mid, b, c], [mid, a, b]];
    out.extend_from_slice(&tris[1..]);
    Mesh::from_triangles(pos, &out)
}

/// A closed UV sphere of radius `r` about the origin: `nu` segments, `nv` rings, triangle fans
/// at the poles (pole valence `nu`); 2·nu·(nv − 1) faces. `staggered` turns every other ring by
/// half a segment.
pub fn uv_sphere(nu: usize, nv: usize, r: f64, staggered: bool) -> Mesh {
    use std::f64::consts::{FRAC_PI_2, PI};
    let stagger = if staggered { 0.5 } else { 0.0 };
    let mut pos = vec![[0.0, 0.0, -r]];
    for j in 1..nv {
        let lat = -FRAC_PI_2 + PI * j as f64 / nv as f64;
        for i in 0..nu {
            let t = 2.0 * PI * (i as f64 + stagger * (j % 2) as f64) / nu as f64;
            pos.push([r * lat.cos() * t.cos(), r * lat.cos() * t.sin(), r * lat.sin()]);
        }
    }
    pos.push([0.0, 0.0, r]);
    let top = (pos.len() - 1) as u32;
    let id = |i: usize, j: usize| (1 + (j - 1) * nu + i % nu) as u32;
    let mut tris = Vec::new();
    for i in 0..nu {
        tris.push([0, id(i + 1, 1), id(i, 1)]);
        tris.push([top, id(i, nv - 1), id(i + 1, nv - 1)]);
    }
    for j in 1..nv.saturating_sub(1) {
        for i in 0..nu {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// A staggered UV sphere ([`uv_sphere`]). With many segments and few rings every face is a
/// needle (nu = 512, nv = 6: ~0.012 wide, ~0.52 tall): a template of long thin triangles, like
/// a CAD tessellation.
pub fn needle_sphere(nu: usize, nv: usize, r: f64) -> Mesh {
    uv_sphere(nu, nv, r, true)
}

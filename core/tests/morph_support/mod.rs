//! Helpers shared by the `morph_*` integration tests: loading the shared meshes and the
//! brute-force measures the tests compare the morph's results against.
// Each test crate uses a different subset.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use meshwork_core::geometry::{cross, dot, norm, sub};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::spatial::closest_on_triangle;

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("core has a parent").to_path_buf()
}

pub fn load(name: &str) -> Mesh {
    let p = root().join("../shared/meshes").join(name);
    let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    meshwork_core::io::read(&bytes, &Default::default()).expect("readable").mesh
}

pub fn bbox_diag(p: &[Point3]) -> f64 {
    meshwork_core::geometry::Aabb::of(p).expect("non-empty").diagonal()
}

/// Max over `pts` of the distance to the nearest triangle of (pos, tris), by brute force.
pub fn max_dist_brute(pts: &[Point3], pos: &[Point3], tris: &[[u32; 3]]) -> f64 {
    pts.iter().map(|&p| dist_brute(p, pos, tris)).fold(0.0, f64::max)
}

/// Distance from `p` to the nearest triangle of (pos, tris), by brute force.
pub fn dist_brute(p: Point3, pos: &[Point3], tris: &[[u32; 3]]) -> f64 {
    tris.iter()
        .map(|t| {
            norm(sub(
                p,
                closest_on_triangle(p, &[pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]]),
            ))
        })
        .fold(f64::INFINITY, f64::min)
}

/// Symmetric vertex-to-surface distance between `a` and `b` (each one's vertices to the other's
/// triangles, by brute force), relative to `a`'s bounding-box diagonal.
pub fn relative_distance_brute(a: &Mesh, b: &Mesh) -> f64 {
    let (ta, tb) =
        (meshwork_core::shapes::fan_triangles(&a.faces), meshwork_core::shapes::fan_triangles(&b.faces));
    max_dist_brute(&a.positions, &b.positions, &tb).max(max_dist_brute(&b.positions, &a.positions, &ta))
        / bbox_diag(&a.positions)
}

/// The Khronos glTF validator's report on `file` (`tests/gltf-validator/validate.mjs`; needs Node.js
/// and `npm ci --prefix tests/gltf-validator`).
pub fn khronos_report(file: &Path) -> serde_json::Value {
    let res = std::process::Command::new("node")
        .arg(root().join("tests/gltf-validator/validate.mjs"))
        .arg(file)
        .output()
        .expect("node (install Node.js or set MESHWORK_SKIP_VALIDATOR=1)");
    serde_json::from_slice(&res.stdout).unwrap_or_else(|_| {
        panic!(
            "validator output: {} {}",
            String::from_utf8_lossy(&res.stdout),
            String::from_utf8_lossy(&res.stderr)
        )
    })
}

/// Area of the spherical triangle (a, b, c) on the unit sphere (Van Oosterom–Strackee), signed.
pub fn spherical_area(a: Point3, b: Point3, c: Point3) -> f64 {
    let num = dot(a, cross(b, c));
    let den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
    2.0 * num.atan2(den)
}

/// The unit icosphere of `levels` scaled by `axes`: an ellipsoid with the sphere's connectivity.
pub fn ellipsoid(levels: u32, axes: Point3) -> Mesh {
    let mut m = meshwork_core::shapes::icosphere(levels, 1.0);
    for p in &mut m.positions {
        *p = [p[0] * axes[0], p[1] * axes[1], p[2] * axes[2]];
    }
    m
}

/// An n×n grid on [−1, 1]² pushed radially onto the unit disk (square rings → circles), z = 0.
pub fn disk(n: usize) -> Mesh {
    let mut m = meshwork_core::shapes::grid(n, n, 2.0 / n as f64, false);
    for p in &mut m.positions {
        let (x, y) = (p[0] - 1.0, p[1] - 1.0);
        let r = x.abs().max(y.abs());
        let l = x.hypot(y);
        let f = if l > 0.0 { r / l } else { 0.0 };
        *p = [x * f, y * f, 0.0];
    }
    m
}

/// The vertex of `m` farthest along direction `d` (feature pairs at the tips of a shape).
pub fn extreme_vertex(m: &Mesh, d: Point3) -> u32 {
    (0..m.positions.len())
        .max_by(|&i, &j| dot(m.positions[i], d).total_cmp(&dot(m.positions[j], d)))
        .expect("a mesh with vertices") as u32
}

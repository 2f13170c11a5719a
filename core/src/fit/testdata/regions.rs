//! The exact count of the regions a set of planes cuts a triangle surface into (the truth for
//! plane-section networks).
//!
//! Why exact: the count on a subdivided copy ([`super::plane_regions`]) leaves out every face a
//! plane cuts, so a neck narrower than a face splits a region and a region smaller than a face
//! vanishes; on the shared meshes it moved by up to 7 between subdivision levels (homer: 22, 23,
//! 27, 20 at levels 1–4), more than the fit's own misses it was meant to judge.

use std::collections::HashMap;

use crate::geometry::{add, dot, norm as length, scale, sub, triangle_cross};
use crate::mesh::{Mesh, Point3};
use crate::shapes::fan_triangles;

/// A plane `dot(normal, x) = offset`.
type Plane = (Point3, f64);

/// Side code of a point: bit k set when it is on the positive side of plane k.
fn code_of(p: Point3, planes: &[Plane]) -> u64 {
    planes.iter().enumerate().fold(0u64, |c, (k, (n, o))| c | (((dot(*n, p) - o) > 0.0) as u64) << k)
}

/// The cells of triangle `t` (convex polygons, one per side code), as their side codes. A cell
/// whose area is below `1e-12` of the triangle's is left out (a plane through a corner).
fn cell_codes(t: [Point3; 3], planes: &[Plane]) -> Vec<u64> {
    let area = length(triangle_cross(t[0], t[1], t[2]));
    let mut cells: Vec<(Vec<Point3>, u64)> = vec![(t.to_vec(), 0)];
    for (k, &(n, o)) in planes.iter().enumerate() {
        let mut next = Vec::with_capacity(cells.len() + 1);
        for (poly, code) in cells {
            let (pos, neg) = clip(&poly, n, o);
            if polygon_area(&pos) > 1e-12 * area {
                next.push((pos, code | 1 << k));
            }
            if polygon_area(&neg) > 1e-12 * area {
                next.push((neg, code));
            }
        }
        cells = next;
    }
    cells.into_iter().map(|(_, c)| c).collect()
}

/// The parts of convex polygon `poly` on the positive (`> 0`) and the other side of a plane.
fn clip(poly: &[Point3], n: Point3, o: f64) -> (Vec<Point3>, Vec<Point3>) {
    let (mut pos, mut neg) = (Vec::new(), Vec::new());
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = (dot(n, a) - o, dot(n, b) - o);
        if da > 0.0 {
            pos.push(a);
        } else {
            neg.push(a);
        }
        if (da > 0.0) != (db > 0.0) {
            let x = add(a, scale(sub(b, a), da / (da - db)));
            pos.push(x);
            neg.push(x);
        }
    }
    (pos, neg)
}

/// Twice the area of a planar polygon (zero for fewer than three points).
fn polygon_area(poly: &[Point3]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let s = (1..poly.len() - 1).fold([0.0; 3], |s, i| add(s, triangle_cross(poly[0], poly[i], poly[i + 1])));
    length(s)
}

/// The side codes along segment `a`–`b`, one per piece of positive length between the crossings.
fn edge_codes(a: Point3, b: Point3, planes: &[Plane]) -> Vec<u64> {
    let mut ts: Vec<f64> = vec![0.0, 1.0];
    for &(n, o) in planes {
        let (da, db) = (dot(n, a) - o, dot(n, b) - o);
        if (da > 0.0) != (db > 0.0) {
            ts.push(da / (da - db));
        }
    }
    ts.sort_by(f64::total_cmp);
    ts.windows(2)
        .filter(|w| w[1] - w[0] > 1e-12)
        .map(|w| code_of(add(a, scale(sub(b, a), 0.5 * (w[0] + w[1]))), planes))
        .collect()
}

/// Regions of the surface of `m` minus the planes, counted exactly: every triangle is cut into
/// convex cells (one per side code: a triangle is convex, so the cells of one code are one
/// polygon), and cells of two triangles on an edge join when they share a piece of that edge of
/// positive length. At most 64 planes (more are ignored).
pub fn exact_plane_regions(m: &Mesh, planes: &[(Point3, f64)]) -> usize {
    let planes = &planes[..planes.len().min(64)];
    let tris = fan_triangles(&m.faces);
    let p = |v: u32| m.positions[v as usize];
    let mut cell: HashMap<(usize, u64), usize> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        for c in cell_codes([p(t[0]), p(t[1]), p(t[2])], planes) {
            let id = cell.len();
            cell.entry((f, c)).or_insert(id);
        }
    }
    let mut parent: Vec<usize> = (0..cell.len()).collect();
    let mut edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    for (&(a, b), faces) in &edge {
        if faces.len() < 2 {
            continue;
        }
        for c in edge_codes(p(a), p(b), planes) {
            let ids: Vec<usize> = faces.iter().filter_map(|&f| cell.get(&(f, c)).copied()).collect();
            for w in ids.windows(2) {
                union(&mut parent, w[0], w[1]);
            }
        }
    }
    (0..parent.len()).filter(|&i| find(&mut parent, i) == i).count()
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb)] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{icosphere, subdivide_midpoint};

    /// The three coordinate planes cut a sphere into its 8 octants, however coarse the sphere.
    #[test]
    fn coordinate_planes_cut_a_sphere_into_octants() {
        let planes = [([1.0, 0.0, 0.0], 0.0), ([0.0, 1.0, 0.0], 0.0), ([0.0, 0.0, 1.0], 0.0)];
        for level in 0..3 {
            assert_eq!(exact_plane_regions(&icosphere(level, 1.0), &planes), 8, "level {level}");
        }
    }

    /// Two parallel planes 0.02 apart near the sphere's top: a cap, a thin band and the rest (3),
    /// even on an icosphere whose faces are far larger than the band.
    #[test]
    fn a_band_narrower_than_a_face_is_one_region() {
        let planes = [([0.0, 0.0, 1.0], 0.5), ([0.0, 0.0, 1.0], 0.52)];
        let s = icosphere(2, 1.0);
        assert_eq!(exact_plane_regions(&s, &planes), 3);
        // A cap around a vertex, far smaller than its faces: a plane just under the vertex (on
        // the unit sphere) and perpendicular to its direction.
        let v = s.positions[0];
        let d = length(v) - 1e-3;
        assert_eq!(exact_plane_regions(&s, &[(scale(v, 1.0 / length(v)), d)]), 2);
        // The subdivided copy's count misses that cap (every face around the vertex is cut).
        let n = scale(v, 1.0 / length(v));
        assert_eq!(super::super::plane_regions(&subdivide_midpoint(&s, 1), &[(n, d)]), 1);
    }

    /// A plane missing the surface leaves one region; a torus-like ring is not needed: a plane
    /// through two separate spheres cuts each in two (4).
    #[test]
    fn pieces_are_counted_apart() {
        let a = icosphere(2, 1.0);
        let mut m = a.clone();
        let base = m.positions.len() as u32;
        m.positions.extend(a.positions.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        let mut faces = m.faces.clone();
        for i in 0..a.faces.len() {
            let g: Vec<u32> = a.faces.get(i).iter().map(|&v| v + base).collect();
            faces.push(&g, 0);
        }
        m.faces = faces;
        assert_eq!(exact_plane_regions(&m, &[([0.0, 0.0, 1.0], 5.0)]), 2);
        assert_eq!(exact_plane_regions(&m, &[([0.0, 0.0, 1.0], 0.1)]), 4);
    }
}

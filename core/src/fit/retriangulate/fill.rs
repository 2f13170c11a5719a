//! The clear-out region's re-filling (Fig. 3.3): the strip of faces a walk crossed is replaced by
//! the segment's edge and a greedy smallest-angle ear cutting of the polygons on either side,
//! with the same number of faces.

use crate::geometry::{add, cross, dot, normalize, scale, sub};
use crate::mesh::Point3;

use super::super::trimesh::{IntMap, TriMesh};

/// Replaces the strip `faces` between u and `end` by the edge u–end and an ear-cut filling of the
/// polygons on either side. On failure the mesh is left as it was.
pub(super) fn retriangulate(
    mesh: &mut TriMesh,
    u: u32,
    end: u32,
    faces: &[u32],
    crossed: &[(u32, u32)],
) -> bool {
    let mut left: Vec<u32> = Vec::new();
    let mut right: Vec<u32> = Vec::new();
    for &(l, r) in crossed {
        if left.last() != Some(&l) {
            left.push(l);
        }
        if right.last() != Some(&r) {
            right.push(r);
        }
    }
    let mut all: Vec<u32> = left.iter().chain(&right).copied().collect();
    all.push(u);
    all.push(end);
    let n_all = all.len();
    all.sort_unstable();
    all.dedup();
    if all.len() != n_all || mesh.has_edge(u, end) {
        return false; // the strip wraps around a vertex: not a simple region
    }
    let mut nr = [0.0; 3];
    for &f in faces {
        nr = add(nr, mesh.face_normal(f));
    }
    let nr = normalize(nr);
    let e1 = normalize(sub(mesh.pos[end as usize], mesh.pos[u as usize]));
    let e1 = normalize(sub(e1, scale(nr, dot(e1, nr))));
    let e2 = cross(nr, e1);
    if e1 == [0.0; 3] || nr == [0.0; 3] {
        return false;
    }
    let mut left_poly = vec![u, end];
    left_poly.extend(left.iter().rev());
    let mut right_poly = vec![end, u];
    right_poly.extend(right.iter());
    let saved: Vec<[u32; 3]> = faces.iter().map(|&f| mesh.tris[f as usize]).collect();
    for &f in faces {
        mesh.remove_face(f);
    }
    let origin = mesh.pos[u as usize];
    let new = ear_cut(mesh, &left_poly, origin, e1, e2).and_then(|mut a| {
        ear_cut(mesh, &right_poly, origin, e1, e2).map(|b| {
            a.extend(b);
            a
        })
    });
    let mut added = Vec::new();
    let ok = match new {
        Some(tris) if tris.len() == faces.len() => {
            let mut ok = true;
            for t in tris {
                match mesh.add_face(t) {
                    Ok(f) => added.push(f),
                    Err(()) => {
                        ok = false;
                        break;
                    }
                }
            }
            ok
        }
        _ => false,
    };
    if !ok {
        for f in added {
            mesh.remove_face(f);
        }
        for t in saved {
            let _ = mesh.add_face(t);
        }
    }
    ok
}

/// Greedy ear cutting of a CCW polygon (in the e1/e2 frame), smallest angle first (Fig. 3.3).
/// Refuses ears whose new diagonal already exists as a mesh edge.
fn ear_cut(mesh: &TriMesh, poly: &[u32], origin: Point3, e1: Point3, e2: Point3) -> Option<Vec<[u32; 3]>> {
    let p2: Vec<[f64; 2]> = poly
        .iter()
        .map(|&v| {
            let d = sub(mesh.pos[v as usize], origin);
            [dot(d, e1), dot(d, e2)]
        })
        .collect();
    let scale2 = p2.iter().fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs())).powi(2).max(1e-300);
    let mut idx: Vec<usize> = (0..poly.len()).collect();
    let mut out = Vec::with_capacity(poly.len().saturating_sub(2));
    let mut diagonals: IntMap<(u32, u32), ()> = IntMap::default();
    let cross2 =
        |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    while idx.len() > 3 {
        let n = idx.len();
        let mut best: Option<(usize, f64)> = None;
        for k in 0..n {
            let (ip, ic, inx) = (idx[(k + n - 1) % n], idx[k], idx[(k + 1) % n]);
            let (pp, pc, pn) = (p2[ip], p2[ic], p2[inx]);
            let area = cross2(pp, pc, pn);
            if area <= 1e-12 * scale2 {
                continue; // reflex or flat corner
            }
            let inside = idx.iter().any(|&j| {
                j != ip && j != ic && j != inx && {
                    let q = p2[j];
                    cross2(pp, pc, q) >= 0.0 && cross2(pc, pn, q) >= 0.0 && cross2(pn, pp, q) >= 0.0
                }
            });
            if inside {
                continue;
            }
            let (vp, vn) = (poly[ip], poly[inx]);
            if mesh.has_edge(vp, vn) || diagonals.contains_key(&(vp.min(vn), vp.max(vn))) {
                continue;
            }
            let u = [pp[0] - pc[0], pp[1] - pc[1]];
            let v = [pn[0] - pc[0], pn[1] - pc[1]];
            let angle = (u[0] * v[1] - u[1] * v[0]).abs().atan2(u[0] * v[0] + u[1] * v[1]);
            if best.is_none_or(|b| angle < b.1) {
                best = Some((k, angle));
            }
        }
        let (k, _) = best?;
        let (ip, ic, inx) = (idx[(k + n - 1) % n], idx[k], idx[(k + 1) % n]);
        out.push([poly[ip], poly[ic], poly[inx]]);
        diagonals.insert((poly[ip].min(poly[inx]), poly[ip].max(poly[inx])), ());
        idx.remove(k);
    }
    if idx.len() == 3 {
        if cross2(p2[idx[0]], p2[idx[1]], p2[idx[2]]) <= 0.0 {
            return None;
        }
        out.push([poly[idx[0]], poly[idx[1]], poly[idx[2]]]);
    }
    Some(out)
}

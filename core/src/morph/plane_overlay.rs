//! The 2-D overlay of two triangulations of the same convex polygon (the planar metamesh).
//!
//! The same construction as the spherical [`super::metamesh::overlay`] (every overlay face is
//! the intersection of one face of A with one face of B, its corners labelled so neighbouring
//! polygons agree), with the one thing the plane adds: both disks carry the *same* boundary
//! vertices ([`super::planar::with_common_boundary`]), which coincide exactly. They get one
//! shared label `S(j)`; such a vertex is a corner of A-face ∩ B-face exactly when it is a corner
//! of both (on a strictly convex polygon a boundary vertex belongs to no other face), and an
//! A-edge never "crosses" a B-edge that shares a boundary vertex with it.
//!
//! Positions are lifted plane points (x, y, 1) (see [`super::planar`]). Each overlay face lies
//! in one face of each input, so its corners carried to the 3D surfaces by barycentric or edge
//! parameters reproduce both inputs exactly.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::geometry::{add, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::correspond::{bary_on_chord, interpolate, Locator};
use super::face_pairs::{walk_face_pairs, PolygonFans};
use super::metamesh::{Layer, OverlayReport};
// Side/inside tests on lifted plane points are the spherical overlay's (one canonical-direction rule).
use super::metamesh::{canon, inside, left, lerp};
use super::planar::lift;

/// A disk triangulation with shapes, and each vertex's common-boundary index (`u32::MAX` inside).
#[derive(Clone, Debug)]
pub struct DiskLayer {
    pub layer: Layer,
    pub bnd: Vec<u32>,
}

#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Label {
    A(u32),
    B(u32),
    S(u32),
    X(u32, u32, u32, u32),
}

/// Parameters (λ on a0→a1, μ on b0→b1) where two plane segments meet.
fn segment_params(a0: Point3, a1: Point3, b0: Point3, b1: Point3) -> (f64, f64) {
    let (da, db, w) = (sub(a1, a0), sub(b1, b0), sub(b0, a0));
    let den = da[0] * db[1] - da[1] * db[0];
    if den == 0.0 {
        return (0.5, 0.5);
    }
    let l = (w[0] * db[1] - w[1] * db[0]) / den;
    let m = (w[0] * da[1] - w[1] * da[0]) / den;
    (l.clamp(0.0, 1.0), m.clamp(0.0, 1.0))
}

/// The overlay of two disks with a common boundary. Errors if the result is not a disk whose
/// boundary is exactly the common boundary.
pub fn overlay(a: &DiskLayer, b: &DiskLayer, progress: &Progress) -> Result<(DiskLayer, OverlayReport)> {
    let (sa, sb) = (&a.layer.sphere[..], &b.layer.sphere[..]);
    let nbr_b = super::trimesh::TriMesh { pos: sb.to_vec(), tris: b.layer.tris.clone() }.face_neighbours();
    let mut loc = Locator::new(sb, &b.layer.tris, nbr_b.clone());
    let nbnd = common_boundary_size(a, b)?;
    let ka = a.layer.shapes.len();
    let mut fans = PolygonFans::with_capacity((sa.len() + sb.len()) * 3);
    let mut plane: Vec<Point3> = Vec::new();
    let mut bnd: Vec<u32> = Vec::new();
    let mut shapes: Vec<Vec<Point3>> = vec![Vec::new(); ka + b.layer.shapes.len()];
    let mut rep = OverlayReport::default();
    let mut corners: Vec<Corner> = Vec::with_capacity(12);
    let centre =
        |ta: [u32; 3]| scale(add(add(sa[ta[0] as usize], sa[ta[1] as usize]), sa[ta[2] as usize]), 1.0 / 3.0);
    rep.empty_pairs = walk_face_pairs(&a.layer.tris, &nbr_b, &mut loc, progress, centre, |fa, fb| {
        let (ta, tb) = (a.layer.tris[fa], b.layer.tris[fb as usize]);
        pair_corners(a, ta, b, tb, &mut corners);
        if corners.len() < 3 {
            return corners.len();
        }
        // Convex polygon: sort the corners counter-clockwise about their mean.
        let n = corners.len() as f64;
        let c = corners.iter().fold([0.0; 3], |s, x| add(s, x.1));
        let (cx, cy) = (c[0] / n, c[1] / n);
        corners.sort_by(|x, y| {
            let ax = (x.1[1] - cy).atan2(x.1[0] - cx);
            let ay = (y.1[1] - cy).atan2(y.1[0] - cx);
            ax.total_cmp(&ay)
        });
        fans.add(
            &corners,
            |x| x.0,
            |&(label, p, wa, wb)| {
                plane.push(p);
                bnd.push(if let Label::S(j) = label { j } else { u32::MAX });
                for k in 0..ka {
                    shapes[k].push(interpolate(&a.layer.shapes[k], ta, wa));
                }
                for k in 0..b.layer.shapes.len() {
                    shapes[ka + k].push(interpolate(&b.layer.shapes[k], tb, wb));
                }
                if matches!(label, Label::X(..)) {
                    rep.crossings += 1;
                }
            },
        );
        corners.len()
    })?;
    rep.vertices = plane.len();
    rep.faces = fans.tris.len();
    check_disk(&fans.tris, &bnd, nbnd)?;
    Ok((DiskLayer { layer: Layer { sphere: plane, tris: fans.tris, shapes }, bnd }, rep))
}

/// A corner of an overlay polygon with its barycentric coordinates in the A-face and the B-face
/// (for the shapes).
type Corner = (Label, Point3, [f64; 3], [f64; 3]);

/// The number of common boundary vertices; an error if A and B do not have the same ones.
fn common_boundary_size(a: &DiskLayer, b: &DiskLayer) -> Result<usize> {
    let nbnd =
        a.bnd.iter().chain(&b.bnd).filter(|&&j| j != u32::MAX).map(|&j| j as usize + 1).max().unwrap_or(0);
    // Whether each common boundary index has a vertex in a disk.
    let present = |d: &DiskLayer| {
        let mut has = vec![false; nbnd];
        for &j in d.bnd.iter().filter(|&&j| j != u32::MAX) {
            has[j as usize] = true;
        }
        has
    };
    if present(a) != present(b) {
        return Err(Error::Internal("planar overlay: the disks' boundaries differ".into()));
    }
    Ok(nbnd)
}

/// The corners of the intersection of A-face `ta` and B-face `tb` (unordered): shared boundary
/// vertices of both, interior A-vertices inside the B-face and B-vertices inside the A-face, and
/// crossings of edges that share no boundary vertex.
fn pair_corners(a: &DiskLayer, ta: [u32; 3], b: &DiskLayer, tb: [u32; 3], corners: &mut Vec<Corner>) {
    let (sa, sb) = (&a.layer.sphere[..], &b.layer.sphere[..]);
    corners.clear();
    let bary_a = |p: Point3| bary_on_chord(sa[ta[0] as usize], sa[ta[1] as usize], sa[ta[2] as usize], p);
    let bary_b = |p: Point3| bary_on_chord(sb[tb[0] as usize], sb[tb[1] as usize], sb[tb[2] as usize], p);
    let unit = |k: usize| {
        let mut w = [0.0; 3];
        w[k] = 1.0;
        w
    };
    for (i, &v) in ta.iter().enumerate() {
        let j = a.bnd[v as usize];
        if j != u32::MAX {
            if let Some(k) = tb.iter().position(|&w| b.bnd[w as usize] == j) {
                corners.push((Label::S(j), sa[v as usize], unit(i), unit(k)));
            }
        } else if inside(sb, tb, sa[v as usize]) {
            corners.push((Label::A(v), sa[v as usize], unit(i), bary_b(sa[v as usize])));
        }
    }
    for (k, &w) in tb.iter().enumerate() {
        if b.bnd[w as usize] == u32::MAX && inside(sa, ta, sb[w as usize]) {
            corners.push((Label::B(w), sb[w as usize], bary_a(sb[w as usize]), unit(k)));
        }
    }
    let shares_bnd = |a0: u32, a1: u32, b0: u32, b1: u32| {
        let (x, y) = (a.bnd[a0 as usize], a.bnd[a1 as usize]);
        let (u, v) = (b.bnd[b0 as usize], b.bnd[b1 as usize]);
        (x != u32::MAX && (x == u || x == v)) || (y != u32::MAX && (y == u || y == v))
    };
    for i in 0..3 {
        let (a0, a1) = canon(ta[i], ta[(i + 1) % 3]);
        for j in 0..3 {
            let (b0, b1) = canon(tb[j], tb[(j + 1) % 3]);
            if shares_bnd(a0, a1, b0, b1) {
                continue;
            }
            let (pa0, pa1, pb0, pb1) = (sa[a0 as usize], sa[a1 as usize], sb[b0 as usize], sb[b1 as usize]);
            if left(sa, a0, a1, pb0) != left(sa, a0, a1, pb1)
                && left(sb, b0, b1, pa0) != left(sb, b0, b1, pa1)
            {
                let (l, m) = segment_params(pa0, pa1, pb0, pb1);
                let p = lerp(pa0, pa1, l);
                // Edge parameters as barycentrics of the two faces.
                let mut wa = [0.0; 3];
                wa[ta.iter().position(|&x| x == a0).unwrap_or(0)] = 1.0 - l;
                wa[ta.iter().position(|&x| x == a1).unwrap_or(0)] += l;
                let mut wb = [0.0; 3];
                wb[tb.iter().position(|&x| x == b0).unwrap_or(0)] = 1.0 - m;
                wb[tb.iter().position(|&x| x == b1).unwrap_or(0)] += m;
                corners.push((Label::X(a0, a1, b0, b1), lift(p[0], p[1]), wa, wb));
            }
        }
    }
}

/// Every interior half-edge paired once with its reverse; the unpaired ones are exactly the
/// common boundary's edges; every vertex used.
fn check_disk(tris: &[[u32; 3]], bnd: &[u32], nbnd: usize) -> Result<()> {
    let mut half: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 3);
    for t in tris {
        for k in 0..3 {
            *half.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    let mut bad = 0;
    let mut open = 0;
    for (&(u, v), &c) in &half {
        if c != 1 {
            bad += 1;
        } else if !half.contains_key(&(v, u)) {
            let (ju, jv) = (bnd[u as usize], bnd[v as usize]);
            if ju == u32::MAX || jv == u32::MAX || (ju as usize + 1) % nbnd != jv as usize {
                bad += 1;
            } else {
                open += 1;
            }
        }
    }
    let mut used = vec![false; bnd.len()];
    for t in tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let unused = used.iter().filter(|&&u| !u).count();
    if bad > 0 || open != nbnd || unused > 0 {
        return Err(Error::numerical(
            "metamesh",
            format!(
                "planar overlay is not a disk on the common boundary ({bad} bad half-edges, {open} of {nbnd} \
                 boundary edges, {unused} unused vertices)"
            ),
        ));
    }
    Ok(())
}

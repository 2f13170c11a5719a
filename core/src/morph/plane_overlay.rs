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
use super::metamesh::{Layer, OverlayReport};
// Side/inside tests on lifted plane points are the spherical overlay's (one canonical-direction rule).
use super::metamesh::{inside, left};
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

fn canon(u: u32, v: u32) -> (u32, u32) {
    (u.min(v), u.max(v))
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

fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    add(a, scale(sub(b, a), t))
}

/// The overlay of two disks with a common boundary. Errors if the result is not a disk whose
/// boundary is exactly the common boundary.
pub fn overlay(a: &DiskLayer, b: &DiskLayer, progress: &Progress) -> Result<(DiskLayer, OverlayReport)> {
    let (sa, sb) = (&a.layer.sphere[..], &b.layer.sphere[..]);
    let nbr_b = super::trimesh::TriMesh { pos: sb.to_vec(), tris: b.layer.tris.clone() }.face_neighbours();
    let mut loc = Locator::new(sb, &b.layer.tris, nbr_b.clone());
    // Common boundary index → vertex in A and in B.
    let nbnd =
        a.bnd.iter().chain(&b.bnd).filter(|&&j| j != u32::MAX).map(|&j| j as usize + 1).max().unwrap_or(0);
    let mut a_of = vec![u32::MAX; nbnd];
    let mut b_of = vec![u32::MAX; nbnd];
    for (v, &j) in a.bnd.iter().enumerate() {
        if j != u32::MAX {
            a_of[j as usize] = v as u32;
        }
    }
    for (v, &j) in b.bnd.iter().enumerate() {
        if j != u32::MAX {
            b_of[j as usize] = v as u32;
        }
    }
    if a_of.iter().zip(&b_of).any(|(&x, &y)| (x == u32::MAX) != (y == u32::MAX)) {
        return Err(Error::Internal("planar overlay: the disks' boundaries differ".into()));
    }
    let ka = a.layer.shapes.len();
    let mut ids: HashMap<Label, u32> = HashMap::with_capacity((sa.len() + sb.len()) * 3);
    let mut plane: Vec<Point3> = Vec::new();
    let mut bnd: Vec<u32> = Vec::new();
    let mut shapes: Vec<Vec<Point3>> = vec![Vec::new(); ka + b.layer.shapes.len()];
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut rep = OverlayReport::default();
    let mut hint = 0u32;
    let mut corners: Vec<(Label, Point3, [f64; 3], [f64; 3])> = Vec::with_capacity(12);
    let (mut queue, mut seen): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    let shares_bnd = |a0: u32, a1: u32, b0: u32, b1: u32| {
        let (x, y) = (a.bnd[a0 as usize], a.bnd[a1 as usize]);
        let (u, v) = (b.bnd[b0 as usize], b.bnd[b1 as usize]);
        (x != u32::MAX && (x == u || x == v)) || (y != u32::MAX && (y == u || y == v))
    };
    for (fa, &ta) in a.layer.tris.iter().enumerate() {
        if fa % 8192 == 0 {
            progress.fraction(fa as f64 / a.layer.tris.len() as f64)?;
        }
        let c3 = scale(add(add(sa[ta[0] as usize], sa[ta[1] as usize]), sa[ta[2] as usize]), 1.0 / 3.0);
        let seed = loc.locate(c3, hint);
        hint = seed;
        queue.clear();
        seen.clear();
        queue.push(seed);
        seen.push(seed);
        let mut qi = 0;
        while qi < queue.len() {
            let fb = queue[qi];
            qi += 1;
            let tb = b.layer.tris[fb as usize];
            corners.clear();
            // Corners are kept with their barycentric coordinates in ta and tb (for the shapes).
            let bary_a =
                |p: Point3| bary_on_chord(sa[ta[0] as usize], sa[ta[1] as usize], sa[ta[2] as usize], p);
            let bary_b =
                |p: Point3| bary_on_chord(sb[tb[0] as usize], sb[tb[1] as usize], sb[tb[2] as usize], p);
            for (i, &v) in ta.iter().enumerate() {
                let j = a.bnd[v as usize];
                let mut wa = [0.0; 3];
                wa[i] = 1.0;
                if j != u32::MAX {
                    if let Some(k) = tb.iter().position(|&w| b.bnd[w as usize] == j) {
                        let mut wb = [0.0; 3];
                        wb[k] = 1.0;
                        corners.push((Label::S(j), sa[v as usize], wa, wb));
                    }
                } else if inside(sb, tb, sa[v as usize]) {
                    corners.push((Label::A(v), sa[v as usize], wa, bary_b(sa[v as usize])));
                }
            }
            for (k, &w) in tb.iter().enumerate() {
                if b.bnd[w as usize] == u32::MAX && inside(sa, ta, sb[w as usize]) {
                    let mut wb = [0.0; 3];
                    wb[k] = 1.0;
                    corners.push((Label::B(w), sb[w as usize], bary_a(sb[w as usize]), wb));
                }
            }
            for i in 0..3 {
                let (a0, a1) = canon(ta[i], ta[(i + 1) % 3]);
                for j in 0..3 {
                    let (b0, b1) = canon(tb[j], tb[(j + 1) % 3]);
                    if shares_bnd(a0, a1, b0, b1) {
                        continue;
                    }
                    let (pa0, pa1, pb0, pb1) =
                        (sa[a0 as usize], sa[a1 as usize], sb[b0 as usize], sb[b1 as usize]);
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
            let nonempty = corners.len() >= 3;
            if nonempty || qi == 1 {
                for &g in &nbr_b[fb as usize] {
                    if g != u32::MAX && !seen.contains(&g) {
                        seen.push(g);
                        queue.push(g);
                    }
                }
            }
            if !nonempty {
                if !corners.is_empty() {
                    rep.empty_pairs += 1;
                }
                continue;
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
            let mut poly: Vec<u32> = Vec::with_capacity(corners.len());
            for &(label, p, wa, wb) in corners.iter() {
                let id = *ids.entry(label).or_insert_with(|| {
                    let id = plane.len() as u32;
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
                    id
                });
                poly.push(id);
            }
            for k in 1..poly.len() - 1 {
                tris.push([poly[0], poly[k], poly[k + 1]]);
            }
        }
    }
    rep.vertices = plane.len();
    rep.faces = tris.len();
    check_disk(&tris, &bnd, nbnd)?;
    Ok((DiskLayer { layer: Layer { sphere: plane, tris, shapes }, bnd }, rep))
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

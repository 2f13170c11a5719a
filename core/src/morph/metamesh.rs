//! The metamesh: a true overlay of two spherical triangulations (seed 002 §6.1, the Kent/Alexa
//! supermesh, here built face pair by face pair instead of by edge walking).
//!
//! Every face of the overlay is the intersection of one face of A with one face of B: a convex
//! spherical polygon whose corners are A-vertices inside the B-face, B-vertices inside the
//! A-face, and crossings of an A-edge with a B-edge. Each corner is decided by orientation tests
//! of one edge against one vertex, evaluated once in a canonical edge direction, so neighbouring
//! polygons agree on their shared corners and the result is a closed manifold (checked; on a
//! failure the caller falls back and reports it). Because every overlay face lies inside one face
//! of each input, its corners carried to either input's 3D surface (by barycentric or edge
//! parameters on the chord triangles) reproduce that input exactly: frame 0 *is* the source and
//! the last frame *is* the target, up to floating point.
//!
//! Overlays chain: the result is again a spherical triangulation carrying one 3D shape per input,
//! which is how 3+ inputs are merged (multi-morph).

use crate::error::{Error, Result};
use crate::geometry::{add, cross, dot, normalize, scale, sub};
use crate::hash::IntMap;
use crate::job::Progress;
use crate::mesh::Point3;

use super::correspond::{bary_on_chord, interpolate, Locator};
use super::face_pairs::{walk_face_pairs, PolygonFans};
use super::param::orient;

/// A spherical triangulation carrying one 3D position per vertex for each input shape.
#[derive(Clone, Debug)]
pub struct Layer {
    pub sphere: Vec<Point3>,
    pub tris: Vec<[u32; 3]>,
    /// `shapes[k][v]`: vertex v on input k's surface.
    pub shapes: Vec<Vec<Point3>>,
}

#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Label {
    A(u32),
    B(u32),
    /// A-edge (a0 < a1) crossing B-edge (b0 < b1).
    X(u32, u32, u32, u32),
}

/// Which side of the canonical (low → high index) great circle through `u`, `v` the point lies
/// on; exactly antisymmetric in (u, v), and a point exactly on the circle counts as left of the
/// canonical direction, so every point is on exactly one side.
#[inline]
pub(super) fn left(s: &[Point3], u: u32, v: u32, p: Point3) -> bool {
    if u < v {
        orient(s[u as usize], s[v as usize], p) >= 0.0
    } else {
        !(orient(s[v as usize], s[u as usize], p) >= 0.0)
    }
}

#[inline]
pub(super) fn inside(s: &[Point3], t: [u32; 3], p: Point3) -> bool {
    left(s, t[0], t[1], p) && left(s, t[1], t[2], p) && left(s, t[2], t[0], p)
}

/// Whether A-edge (a0, a1) and B-edge (b0, b1) (both canonical, low < high) cross.
/// When each arc straddles the other's great circle, the circles meet at ±x (x = n_a × n_b) and
/// each arc (< 180°) passes through the one on its own midpoint's side: they cross iff that is
/// the same point. (Comparing the two midpoints directly is only right for short arcs; the
/// arcs of a coarse embedding, e.g. a tetrahedron's 109°, got it wrong: found by the sweep.)
#[inline]
fn crosses(sa: &[Point3], a0: u32, a1: u32, sb: &[Point3], b0: u32, b1: u32) -> bool {
    let (pa0, pa1, pb0, pb1) = (sa[a0 as usize], sa[a1 as usize], sb[b0 as usize], sb[b1 as usize]);
    left(sa, a0, a1, pb0) != left(sa, a0, a1, pb1) && left(sb, b0, b1, pa0) != left(sb, b0, b1, pa1) && {
        let x = cross(cross(pa0, pa1), cross(pb0, pb1));
        (dot(x, add(pa0, pa1)) > 0.0) == (dot(x, add(pb0, pb1)) > 0.0)
    }
}

/// Where the great arcs (a0, a1) and (b0, b1) meet, on the side of the arcs.
fn crossing_point(a0: Point3, a1: Point3, b0: Point3, b1: Point3) -> Point3 {
    let p = normalize(cross(cross(a0, a1), cross(b0, b1)));
    if dot(p, add(a0, a1)) < 0.0 {
        scale(p, -1.0)
    } else {
        p
    }
}

/// Parameter λ of the point where the ray through `p` meets the chord a0→a1 (p on their great circle).
fn chord_param(a0: Point3, a1: Point3, p: Point3) -> f64 {
    let n = cross(a0, a1);
    let alpha = dot(cross(p, a1), n);
    let beta = dot(cross(a0, p), n);
    let s = alpha + beta;
    if s.abs() <= 0.0 {
        0.5
    } else {
        (beta / s).clamp(0.0, 1.0)
    }
}

/// A number in [0, 4) increasing with the angle of (x, y) like atan2 does, without trigonometry
/// (the "diamond angle"): enough to order a polygon's corners around its centre.
#[inline]
fn pseudo_angle(x: f64, y: f64) -> f64 {
    let s = x.abs() + y.abs();
    if s == 0.0 {
        return 0.0;
    }
    let r = y / s;
    if x >= 0.0 {
        if y >= 0.0 {
            r
        } else {
            4.0 + r
        }
    } else {
        2.0 - r
    }
}

/// f64 with a total order, as a sort key. `PartialOrd` agrees with `Ord` (a derived one would
/// not: the sort compares through it, and clippy refuses the mismatch).
#[derive(PartialEq)]
struct Angle(f64);
impl Eq for Angle {}
impl PartialOrd for Angle {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Angle {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

pub(super) fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    add(a, scale(sub(b, a), t))
}

pub(super) fn canon(u: u32, v: u32) -> (u32, u32) {
    (u.min(v), u.max(v))
}

/// Overlay statistics for the report.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct OverlayReport {
    pub vertices: usize,
    pub faces: usize,
    pub crossings: usize,
    /// Face pairs whose intersection came out with fewer than 3 corners (touching only).
    pub empty_pairs: usize,
}

/// The overlay of A and B (see the module docs). Errors if the result is not a closed manifold.
pub fn overlay(a: &Layer, b: &Layer, progress: &Progress) -> Result<(Layer, OverlayReport)> {
    let nbr_b = super::trimesh::TriMesh { pos: b.sphere.clone(), tris: b.tris.clone() }.face_neighbours();
    let mut loc = Locator::new(&b.sphere, &b.tris, nbr_b.clone());
    let mut fans = PolygonFans::with_capacity((a.sphere.len() + b.sphere.len()) * 3);
    let mut sphere: Vec<Point3> = Vec::new();
    let ka = a.shapes.len();
    let mut shapes: Vec<Vec<Point3>> = vec![Vec::new(); ka + b.shapes.len()];
    let mut rep = OverlayReport::default();
    let mut corners: Vec<(Label, Point3)> = Vec::with_capacity(12);
    let (sa, sb) = (&a.sphere[..], &b.sphere[..]);
    let centre =
        |ta: [u32; 3]| normalize(add(add(sa[ta[0] as usize], sa[ta[1] as usize]), sa[ta[2] as usize]));
    rep.empty_pairs = walk_face_pairs(&a.tris, &nbr_b, &mut loc, progress, centre, |fa, fb| {
        let (ta, tb) = (a.tris[fa], b.tris[fb as usize]);
        pair_corners(sa, ta, sb, tb, &mut corners);
        if corners.len() < 3 {
            return corners.len();
        }
        // Order the corners around the polygon's centre (it is convex). The angular sort goes
        // counter-clockwise about c (e1 × e2 = c), the faces' orientation.
        let c = normalize(corners.iter().fold([0.0; 3], |s, x| add(s, x.1)));
        let e1 =
            normalize(if c[0].abs() < 0.9 { cross(c, [1.0, 0.0, 0.0]) } else { cross(c, [0.0, 1.0, 0.0]) });
        let e2 = cross(c, e1);
        corners.sort_by_cached_key(|x| Angle(pseudo_angle(dot(x.1, e1), dot(x.1, e2))));
        fans.add(
            &corners,
            |x| x.0,
            |&(label, p)| {
                sphere.push(p);
                push_shapes(&mut shapes, ka, a, b, label, p, fa as u32, fb);
                if matches!(label, Label::X(..)) {
                    rep.crossings += 1;
                }
            },
        );
        corners.len()
    })?;
    rep.vertices = sphere.len();
    rep.faces = fans.tris.len();
    let layer = Layer { sphere, tris: fans.tris, shapes };
    check_closed_manifold(&layer.tris, layer.sphere.len())?;
    Ok((layer, rep))
}

/// The corners of the intersection of A-face `ta` and B-face `tb` (unordered): A-vertices inside
/// the B-face, B-vertices inside the A-face, A-edges crossing B-edges.
fn pair_corners(
    sa: &[Point3],
    ta: [u32; 3],
    sb: &[Point3],
    tb: [u32; 3],
    corners: &mut Vec<(Label, Point3)>,
) {
    corners.clear();
    for &v in &ta {
        if inside(sb, tb, sa[v as usize]) {
            corners.push((Label::A(v), sa[v as usize]));
        }
    }
    for &v in &tb {
        if inside(sa, ta, sb[v as usize]) {
            corners.push((Label::B(v), sb[v as usize]));
        }
    }
    for i in 0..3 {
        let (a0, a1) = canon(ta[i], ta[(i + 1) % 3]);
        for j in 0..3 {
            let (b0, b1) = canon(tb[j], tb[(j + 1) % 3]);
            if crosses(sa, a0, a1, sb, b0, b1) {
                let p = crossing_point(sa[a0 as usize], sa[a1 as usize], sb[b0 as usize], sb[b1 as usize]);
                corners.push((Label::X(a0, a1, b0, b1), p));
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn push_shapes(
    shapes: &mut [Vec<Point3>],
    ka: usize,
    a: &Layer,
    b: &Layer,
    label: Label,
    p: Point3,
    fa: u32,
    fb: u32,
) {
    let ta = a.tris[fa as usize];
    let tb = b.tris[fb as usize];
    let (sa, sb) = (&a.sphere, &b.sphere);
    match label {
        Label::A(v) => {
            for k in 0..ka {
                shapes[k].push(a.shapes[k][v as usize]);
            }
            let w = bary_on_chord(sb[tb[0] as usize], sb[tb[1] as usize], sb[tb[2] as usize], p);
            for k in 0..b.shapes.len() {
                shapes[ka + k].push(interpolate(&b.shapes[k], tb, w));
            }
        }
        Label::B(v) => {
            let w = bary_on_chord(sa[ta[0] as usize], sa[ta[1] as usize], sa[ta[2] as usize], p);
            for k in 0..ka {
                shapes[k].push(interpolate(&a.shapes[k], ta, w));
            }
            for k in 0..b.shapes.len() {
                shapes[ka + k].push(b.shapes[k][v as usize]);
            }
        }
        Label::X(a0, a1, b0, b1) => {
            let la = chord_param(sa[a0 as usize], sa[a1 as usize], p);
            let lb = chord_param(sb[b0 as usize], sb[b1 as usize], p);
            for k in 0..ka {
                shapes[k].push(lerp(a.shapes[k][a0 as usize], a.shapes[k][a1 as usize], la));
            }
            for k in 0..b.shapes.len() {
                shapes[ka + k].push(lerp(b.shapes[k][b0 as usize], b.shapes[k][b1 as usize], lb));
            }
        }
    }
}

/// Every directed edge must appear once, together with its reverse.
fn check_closed_manifold(tris: &[[u32; 3]], nv: usize) -> Result<()> {
    let mut half: IntMap<(u32, u32), u32> =
        IntMap::with_capacity_and_hasher(tris.len() * 3, Default::default());
    for t in tris {
        for k in 0..3 {
            *half.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    let bad = half.iter().filter(|(&(u, v), &c)| c != 1 || half.get(&(v, u)) != Some(&1)).count();
    let used = {
        let mut u = vec![false; nv];
        for t in tris {
            for &v in t {
                u[v as usize] = true;
            }
        }
        u.iter().filter(|&&x| x).count()
    };
    if bad > 0 || used != nv {
        return Err(Error::numerical(
            "metamesh",
            format!(
                "overlay is not a closed manifold ({bad} unmatched half-edges, {} unused vertices)",
                nv - used
            ),
        ));
    }
    Ok(())
}

/// The simpler correspondence (seed 003 §2.5 "simple morph", seed 002 Zhu & Pang): A's
/// connectivity, each A-vertex carried onto every B-shape by barycentric coordinates in the B-face
/// containing it. Frame 0 is exact; the others only sample B's surface at A's vertices.
pub fn transfer(a: &Layer, b: &Layer, progress: &Progress) -> Result<Layer> {
    let nbr_b = super::trimesh::TriMesh { pos: b.sphere.clone(), tris: b.tris.clone() }.face_neighbours();
    let mut loc = Locator::new(&b.sphere, &b.tris, nbr_b);
    let mut shapes = a.shapes.clone();
    let mut extra: Vec<Vec<Point3>> = vec![Vec::with_capacity(a.sphere.len()); b.shapes.len()];
    let mut hint = 0;
    for (i, &p) in a.sphere.iter().enumerate() {
        if i % 8192 == 0 {
            progress.fraction(i as f64 / a.sphere.len() as f64)?;
        }
        let f = loc.locate(p, hint);
        hint = f;
        let w = loc.barycentric(f, p);
        for k in 0..b.shapes.len() {
            extra[k].push(interpolate(&b.shapes[k], b.tris[f as usize], w));
        }
    }
    shapes.extend(extra);
    Ok(Layer { sphere: a.sphere.clone(), tris: a.tris.clone(), shapes })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pseudo_angle_orders_directions_like_atan2() {
        // 720 directions around the circle, from just past −π: the pseudo-angle must sort them
        // in the same cyclic order as the angle itself (one wrap, at the positive x axis).
        let angles: Vec<f64> =
            (1..=720).map(|k| -std::f64::consts::PI + k as f64 * std::f64::consts::PI / 360.0).collect();
        let key = |a: f64| {
            let p = pseudo_angle(a.cos(), a.sin());
            assert!((0.0..4.0).contains(&p), "{a}: {p}");
            p
        };
        for w in angles.windows(2) {
            let (ka, kb) = (key(w[0]), key(w[1]));
            // Increasing, except across angle 0 where the pseudo-angle wraps from ~4 to 0.
            let crosses_zero = w[0] < 0.0 && w[1] >= 0.0;
            assert!(kb > ka || crosses_zero, "{} → {}: {ka} → {kb}", w[0], w[1]);
        }
        assert_eq!(pseudo_angle(1.0, 0.0), 0.0);
        assert_eq!(pseudo_angle(0.0, 1.0), 1.0);
        assert_eq!(pseudo_angle(-1.0, 0.0), 2.0);
        assert_eq!(pseudo_angle(0.0, -1.0), 3.0);
    }
}

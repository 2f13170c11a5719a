//! Seed 002's adaptive pseudo-metamesh (§6.2): start from the *target* embedding, split every
//! triangle holding more than one source vertex 1-to-4 (edge midpoints) until each holds at most
//! one (or a depth cap is reached), make the result conforming (red–green closure: a triangle with
//! two or more split neighbours is split 1-to-4 too, one with a single hanging midpoint is halved),
//! then give every vertex a source position by point location in the source embedding.
//!
//! Target positions of midpoints are the 3D midpoints of their edge (eq. VI.17), so the last frame
//! lies exactly on the target's faces; the first frame only samples the source surface at the
//! metamesh vertices, which is why the thesis calls it "pseudo" (the job reports both Hausdorff
//! distances). Works on both domains: on the sphere midpoints are re-normalised; in the plane
//! (lifted points (x, y, 1)) they are plain averages.

use std::collections::HashMap;

use crate::error::Result;
use crate::geometry::{add, normalize, scale};
use crate::job::Progress;
use crate::mesh::Point3;

use super::correspond::{interpolate, Locator};
use super::metamesh::Layer;
use super::param::orient;
use super::trimesh::TriMesh;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    Sphere,
    Plane,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PseudoReport {
    pub vertices: usize,
    pub faces: usize,
    /// 1-to-4 splits to separate source vertices, and for conformity.
    pub red_splits: usize,
    /// Triangles halved at a single hanging midpoint.
    pub green_splits: usize,
    /// Triangles still holding more than one source vertex at the depth cap.
    pub crowded_at_depth_cap: usize,
}

fn midpoint(d: Domain, a: Point3, b: Point3) -> Point3 {
    match d {
        Domain::Sphere => normalize(add(a, b)),
        Domain::Plane => scale(add(a, b), 0.5),
    }
}

struct Builder {
    dom: Domain,
    pts: Vec<Point3>,
    /// Target shapes (3D) per vertex: midpoints average their edge's ends.
    shapes: Vec<Vec<Point3>>,
    mid: HashMap<(u32, u32), u32>,
}

impl Builder {
    fn midpoint(&mut self, u: u32, v: u32) -> u32 {
        let key = (u.min(v), u.max(v));
        if let Some(&m) = self.mid.get(&key) {
            return m;
        }
        let m = self.pts.len() as u32;
        let p = midpoint(self.dom, self.pts[u as usize], self.pts[v as usize]);
        self.pts.push(p);
        for s in &mut self.shapes {
            let q = scale(add(s[u as usize], s[v as usize]), 0.5);
            s.push(q);
        }
        self.mid.insert(key, m);
        m
    }
    fn has_mid(&self, u: u32, v: u32) -> Option<u32> {
        self.mid.get(&(u.min(v), u.max(v))).copied()
    }
    fn red(&mut self, t: [u32; 3]) -> [[u32; 3]; 4] {
        let ab = self.midpoint(t[0], t[1]);
        let bc = self.midpoint(t[1], t[2]);
        let ca = self.midpoint(t[2], t[0]);
        [[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]
    }
}

fn inside(p: &[Point3], t: [u32; 3], q: Point3) -> bool {
    orient(p[t[0] as usize], p[t[1] as usize], q) >= 0.0
        && orient(p[t[1] as usize], p[t[2] as usize], q) >= 0.0
        && orient(p[t[2] as usize], p[t[0] as usize], q) >= 0.0
}

/// The pseudo-metamesh of `source` (its vertices are separated) on `target`'s embedding.
/// Shapes of the result: the source's, then the target's (as [`super::metamesh::overlay`]).
pub fn pseudo(
    source: &Layer,
    target: &Layer,
    dom: Domain,
    max_depth: u32,
    progress: &Progress,
) -> Result<(Layer, PseudoReport)> {
    let mut rep = PseudoReport::default();
    let nbr_t = TriMesh { pos: target.sphere.clone(), tris: target.tris.clone() }.face_neighbours();
    // Source vertices per target face.
    let mut bucket: Vec<Vec<u32>> = vec![Vec::new(); target.tris.len()];
    {
        let mut loc = Locator::new(&target.sphere, &target.tris, nbr_t);
        let mut hint = 0;
        for (i, &p) in source.sphere.iter().enumerate() {
            if i % 8192 == 0 {
                progress.fraction(0.3 * i as f64 / source.sphere.len().max(1) as f64)?;
            }
            let f = loc.locate(p, hint);
            hint = f;
            bucket[f as usize].push(i as u32);
        }
    }
    let mut b =
        Builder { dom, pts: target.sphere.clone(), shapes: target.shapes.clone(), mid: HashMap::new() };
    // Leaves: (triangle, depth, source vertices inside).
    let mut leaves: Vec<([u32; 3], u32)> = Vec::with_capacity(target.tris.len() * 2);
    let mut work: Vec<([u32; 3], u32, Vec<u32>)> =
        target.tris.iter().zip(bucket).map(|(&t, v)| (t, 0, v)).collect();
    while let Some((t, depth, pts)) = work.pop() {
        if pts.len() <= 1 {
            leaves.push((t, depth));
            continue;
        }
        if depth >= max_depth {
            rep.crowded_at_depth_cap += 1;
            leaves.push((t, depth));
            continue;
        }
        progress.check()?;
        let kids = b.red(t);
        rep.red_splits += 1;
        let mut kid_pts: [Vec<u32>; 4] = Default::default();
        for &v in &pts {
            let q = source.sphere[v as usize];
            // First child containing it (the middle one last); boundary ties go to the first.
            let k = (0..4).find(|&k| inside(&b.pts, kids[k], q)).unwrap_or(3);
            kid_pts[k].push(v);
        }
        for (k, kp) in kid_pts.into_iter().enumerate() {
            work.push((kids[k], depth + 1, kp));
        }
    }
    // Red closure: split leaves with ≥ 2 split edges, or with a split edge whose halves are split
    // again (two levels of hanging nodes), until none is left.
    loop {
        progress.check()?;
        let mut changed = false;
        let mut next: Vec<([u32; 3], u32)> = Vec::with_capacity(leaves.len());
        for &(t, d) in &leaves {
            let mut hanging = 0;
            let mut deep = false;
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                if let Some(m) = b.has_mid(u, v) {
                    hanging += 1;
                    if b.has_mid(u, m).is_some() || b.has_mid(m, v).is_some() {
                        deep = true;
                    }
                }
            }
            if hanging >= 2 || deep {
                rep.red_splits += 1;
                for kid in b.red(t) {
                    next.push((kid, d + 1));
                }
                changed = true;
            } else {
                next.push((t, d));
            }
        }
        leaves = next;
        if !changed {
            break;
        }
    }
    // Green: halve at the single hanging midpoint.
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(leaves.len() + leaves.len() / 4);
    for &(t, _) in &leaves {
        let mut done = false;
        for k in 0..3 {
            let (u, v, w) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            if let Some(m) = b.has_mid(u, v) {
                tris.push([u, m, w]);
                tris.push([m, v, w]);
                rep.green_splits += 1;
                done = true;
                break;
            }
        }
        if !done {
            tris.push(t);
        }
    }
    // Source positions by location in the source embedding.
    let nbr_s = TriMesh { pos: source.sphere.clone(), tris: source.tris.clone() }.face_neighbours();
    let mut loc = Locator::new(&source.sphere, &source.tris, nbr_s);
    let mut src_shapes: Vec<Vec<Point3>> = vec![Vec::with_capacity(b.pts.len()); source.shapes.len()];
    let mut hint = 0;
    for (i, &p) in b.pts.iter().enumerate() {
        if i % 8192 == 0 {
            progress.fraction(0.5 + 0.5 * i as f64 / b.pts.len() as f64)?;
        }
        let f = loc.locate(p, hint);
        hint = f;
        let w = loc.barycentric(f, p);
        for (k, s) in src_shapes.iter_mut().enumerate() {
            s.push(interpolate(&source.shapes[k], source.tris[f as usize], w));
        }
    }
    rep.vertices = b.pts.len();
    rep.faces = tris.len();
    src_shapes.extend(b.shapes);
    Ok((Layer { sphere: b.pts, tris, shapes: src_shapes }, rep))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    fn sphere_layer(levels: u32, rot: f64) -> Layer {
        let m = shapes::icosphere(levels, 1.0);
        let (t, _, _) = TriMesh::from_mesh(&m);
        let (s, c) = rot.sin_cos();
        let sphere: Vec<Point3> =
            t.pos.iter().map(|p| normalize([c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])).collect();
        Layer { sphere: sphere.clone(), tris: t.tris.clone(), shapes: vec![sphere] }
    }

    #[test]
    fn result_is_a_closed_conforming_mesh_separating_the_source_vertices() {
        let src = sphere_layer(3, 0.1);
        let tgt = sphere_layer(1, 0.0);
        let (l, rep) = pseudo(&src, &tgt, Domain::Sphere, 8, &Progress::new()).unwrap();
        assert!(rep.red_splits > 0 && rep.crowded_at_depth_cap == 0, "{rep:?}");
        // Closed and conforming: every directed edge has its reverse, exactly once.
        let mut half = std::collections::HashMap::new();
        for t in &l.tris {
            for k in 0..3 {
                *half.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(u, v), &c) in &half {
            assert_eq!(c, 1);
            assert_eq!(half.get(&(v, u)), Some(&1), "hanging edge {u}-{v}");
        }
        // Euler: V − E + F = 2.
        assert_eq!(l.sphere.len() as i64 - half.len() as i64 / 2 + l.tris.len() as i64, 2);
        // No face holds two source vertices.
        for t in &l.tris {
            let n = src.sphere.iter().filter(|&&q| {
                orient(l.sphere[t[0] as usize], l.sphere[t[1] as usize], q) > 1e-12
                    && orient(l.sphere[t[1] as usize], l.sphere[t[2] as usize], q) > 1e-12
                    && orient(l.sphere[t[2] as usize], l.sphere[t[0] as usize], q) > 1e-12
            });
            assert!(n.count() <= 1);
        }
        // Target shape of a midpoint is the 3D midpoint of its edge: on the target's chord
        // triangles, so inside the unit sphere; source shape is on the source's chord triangles.
        assert_eq!(l.shapes.len(), 2);
        for p in &l.shapes[1] {
            assert!(crate::geometry::norm(*p) <= 1.0 + 1e-12);
        }
    }
}

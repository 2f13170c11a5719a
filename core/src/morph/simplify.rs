//! Simplification by recorded, invertible half-edge collapses (seed 002 §2 step 2, QSlim-style
//! quadric error metric restricted to edges). A half-edge collapse `vt → vs` deletes `vt` and
//! keeps `vs` where it is, so undoing it (a vertex split) only has to place `vt` again: that is
//! what the spherical parameterisation does on the way back up (Praun–Hoppe style).
//!
//! Every collapse passes the link condition (the only common neighbours of the two endpoints are
//! the two vertices opposite the edge), so the surface stays a closed genus-0 manifold; in strict
//! mode it also refuses collapses that fold a face over in 3D or create a high-valence vertex.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::error::{Error, Result};
use crate::geometry::{cross, dot, norm, normalize, sub};
use crate::job::Progress;
use crate::mesh::Point3;

/// The neighbours of one vertex, on the stack up to valence 32.
pub struct Ring {
    n: usize,
    small: [u32; 32],
    big: Vec<u32>,
}

impl std::ops::Deref for Ring {
    type Target = [u32];
    fn deref(&self) -> &[u32] {
        if self.n <= 32 {
            &self.small[..self.n]
        } else {
            &self.big
        }
    }
}

/// One collapse `vt → vs`, enough to undo it exactly.
#[derive(Clone, Debug)]
pub struct Collapse {
    pub vt: u32,
    pub vs: u32,
    /// The two faces that disappeared (they contained both endpoints).
    pub removed: [u32; 2],
    /// Range in [`Hierarchy::changed`] of the faces whose `vt` corner became `vs`.
    changed: (u32, u32),
}

/// A mesh under progressive simplification, with its undo stack.
pub struct Hierarchy {
    pub pos: Vec<Point3>,
    pub tris: Vec<[u32; 3]>,
    pub face_alive: Vec<bool>,
    pub vertex_alive: Vec<bool>,
    /// Alive faces around each alive vertex.
    pub vf: Vec<Vec<u32>>,
    pub records: Vec<Collapse>,
    changed: Vec<u32>,
    quadrics: Vec<[f64; 10]>,
    pub alive_vertices: usize,
}

fn plane_quadric(a: Point3, b: Point3, c: Point3) -> [f64; 10] {
    let n = cross(sub(b, a), sub(c, a));
    let area2 = norm(n);
    if area2 == 0.0 {
        return [0.0; 10];
    }
    let n = normalize(n);
    let d = -dot(n, a);
    let w = area2 * 0.5;
    let p = [n[0], n[1], n[2], d];
    let mut q = [0.0; 10];
    let mut k = 0;
    for i in 0..4 {
        for j in i..4 {
            q[k] = w * p[i] * p[j];
            k += 1;
        }
    }
    q
}

/// 4√3·area / Σ edge²: 1 for an equilateral triangle, 0 for a degenerate one.
fn shape(q: [Point3; 3]) -> f64 {
    let l2 = dot(sub(q[1], q[0]), sub(q[1], q[0]))
        + dot(sub(q[2], q[1]), sub(q[2], q[1]))
        + dot(sub(q[0], q[2]), sub(q[0], q[2]));
    if l2 <= 0.0 {
        return 0.0;
    }
    2.0 * 3f64.sqrt() * norm(cross(sub(q[1], q[0]), sub(q[2], q[0]))) / l2
}

fn quadric_eval(q: &[f64; 10], v: Point3) -> f64 {
    let x = [v[0], v[1], v[2], 1.0];
    let mut s = 0.0;
    let mut k = 0;
    for i in 0..4 {
        for j in i..4 {
            let f = if i == j { 1.0 } else { 2.0 };
            s += f * q[k] * x[i] * x[j];
            k += 1;
        }
    }
    s
}

#[derive(PartialEq)]
struct Cost(f64);
impl PartialOrd for Cost {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Eq for Cost {}
impl Ord for Cost {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

impl Hierarchy {
    pub fn new(pos: &[Point3], tris: &[[u32; 3]]) -> Hierarchy {
        let mut vf = vec![Vec::new(); pos.len()];
        let mut quadrics = vec![[0.0; 10]; pos.len()];
        for (fi, t) in tris.iter().enumerate() {
            let q = plane_quadric(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
            for &v in t {
                vf[v as usize].push(fi as u32);
                for k in 0..10 {
                    quadrics[v as usize][k] += q[k];
                }
            }
        }
        Hierarchy {
            pos: pos.to_vec(),
            tris: tris.to_vec(),
            face_alive: vec![true; tris.len()],
            vertex_alive: vec![true; pos.len()],
            vf,
            records: Vec::new(),
            changed: Vec::new(),
            quadrics,
            alive_vertices: pos.len(),
        }
    }

    /// Neighbours of an alive vertex (unique, in no particular order): the vertex after `v` in
    /// each of its faces, which lists every neighbour exactly once on a closed manifold (an
    /// invariant here: every collapse passes the link condition). No allocation for valences
    /// ≤ 32: this is called for every candidate collapse.
    pub fn neighbours(&self, v: u32) -> Ring {
        let faces = &self.vf[v as usize];
        let next = |&f: &u32| {
            let t = self.tris[f as usize];
            if t[0] == v {
                t[1]
            } else if t[1] == v {
                t[2]
            } else {
                t[0]
            }
        };
        let mut r = Ring { n: faces.len(), small: [0; 32], big: Vec::new() };
        if faces.len() <= 32 {
            for (k, f) in faces.iter().enumerate() {
                r.small[k] = next(f);
            }
        } else {
            r.big = faces.iter().map(next).collect();
        }
        r
    }

    fn cost(&self, vt: u32, vs: u32) -> f64 {
        let (t, s) = (vt as usize, vs as usize);
        let mut q = self.quadrics[s];
        for k in 0..10 {
            q[k] += self.quadrics[t][k];
        }
        let e = sub(self.pos[t], self.pos[s]);
        // The small length term orders collapses on flat regions (zero quadric error) shortest
        // first, which keeps the coarse mesh well shaped.
        quadric_eval(&q, self.pos[s]).max(0.0) + 1e-3 * dot(e, e)
    }

    /// Whether `vt → vs` keeps a closed manifold (and, in strict mode, a fold-free 3D surface).
    fn can_collapse(&self, vt: u32, vs: u32, strict: bool) -> bool {
        if !self.vertex_alive[vt as usize] || !self.vertex_alive[vs as usize] || self.alive_vertices <= 4 {
            return false;
        }
        let nt = self.neighbours(vt);
        if !nt.contains(&vs) {
            return false;
        }
        let ns = self.neighbours(vs);
        let common = nt.iter().filter(|v| ns.contains(v)).count();
        if common != 2 {
            return false;
        }
        if strict {
            // Keep valences moderate: high valences make thin spherical triangles.
            if ns.len() + nt.len() - 4 > 14 {
                return false;
            }
            let ps = self.pos[vs as usize];
            for &f in &self.vf[vt as usize] {
                let t = self.tris[f as usize];
                if t.contains(&vs) {
                    continue;
                }
                let p = t.map(|v| self.pos[v as usize]);
                let before = cross(sub(p[1], p[0]), sub(p[2], p[0]));
                let q = t.map(|v| if v == vt { ps } else { self.pos[v as usize] });
                let after = cross(sub(q[1], q[0]), sub(q[2], q[0]));
                let (nb, na) = (norm(before), norm(after));
                if na <= 1e-12 * nb.max(1e-300) || dot(before, after) < 0.3 * nb * na {
                    return false;
                }
                // Refuse new slivers (but accept faces no worse than a sliver already there).
                if shape(q) < 0.05f64.min(0.5 * shape(p)) {
                    return false;
                }
            }
        }
        true
    }

    fn collapse(&mut self, vt: u32, vs: u32) {
        let start = self.changed.len() as u32;
        let mut removed = [u32::MAX; 2];
        let faces = std::mem::take(&mut self.vf[vt as usize]);
        let mut r = 0;
        for &f in &faces {
            let t = self.tris[f as usize];
            if t.contains(&vs) {
                if r < 2 {
                    removed[r] = f;
                }
                r += 1;
                self.face_alive[f as usize] = false;
                for &w in &t {
                    if w != vt {
                        self.vf[w as usize].retain(|&g| g != f);
                    }
                }
            } else {
                for c in self.tris[f as usize].iter_mut() {
                    if *c == vt {
                        *c = vs;
                    }
                }
                self.changed.push(f);
                self.vf[vs as usize].push(f);
            }
        }
        let end = self.changed.len() as u32;
        self.vertex_alive[vt as usize] = false;
        self.alive_vertices -= 1;
        for k in 0..10 {
            let q = self.quadrics[vt as usize][k];
            self.quadrics[vs as usize][k] += q;
        }
        self.records.push(Collapse { vt, vs, removed, changed: (start, end) });
    }

    /// Collapses `rec` again right after [`Hierarchy::split_last`] returned it (the mesh is then
    /// exactly as before the split): lets the parameterisation improve the neighbourhood of
    /// `vs` and retry a split that found no valid position.
    pub fn redo(&mut self, rec: &Collapse) {
        self.collapse(rec.vt, rec.vs);
    }

    /// Undoes the last collapse (a vertex split); returns it. Quadrics are not restored (they are
    /// only used while simplifying).
    pub fn split_last(&mut self) -> Option<Collapse> {
        let rec = self.records.pop()?;
        let (vt, vs) = (rec.vt, rec.vs);
        let changed: Vec<u32> = self.changed[rec.changed.0 as usize..rec.changed.1 as usize].to_vec();
        self.changed.truncate(rec.changed.0 as usize);
        let mut faces = Vec::with_capacity(changed.len() + 2);
        for &f in &changed {
            for c in self.tris[f as usize].iter_mut() {
                if *c == vs {
                    *c = vt;
                }
            }
            faces.push(f);
        }
        self.vf[vs as usize].retain(|g| !changed.contains(g));
        for &f in &rec.removed {
            if f == u32::MAX {
                continue;
            }
            self.face_alive[f as usize] = true;
            faces.push(f);
            for &w in &self.tris[f as usize] {
                if w != vt {
                    self.vf[w as usize].push(f);
                }
            }
        }
        self.vf[vt as usize] = faces;
        self.vertex_alive[vt as usize] = true;
        self.alive_vertices += 1;
        Some(rec)
    }

    /// The cheapest collapse `vt → w` over the neighbours w of `vt` that passes the checks, and
    /// whether it is also the cheapest of all (allowed or not).
    fn best_allowed(&self, vt: u32, strict: bool) -> Option<(f64, u32, bool)> {
        let mut c: Vec<(f64, u32)> = self.neighbours(vt).iter().map(|&w| (self.cost(vt, w), w)).collect();
        c.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        c.iter()
            .enumerate()
            .find(|(_, &(_, w))| self.can_collapse(vt, w, strict))
            .map(|(i, &(k, w))| (k, w, i == 0))
    }

    /// The cheapest collapse out of `vt` (allowed or not), as (cost, other end): the key of its
    /// heap entry.
    fn best_of(&self, vt: u32) -> (f64, u32) {
        self.neighbours(vt).iter().map(|&w| (self.cost(vt, w), w)).fold((f64::INFINITY, u32::MAX), |a, b| {
            if b.0 < a.0 {
                b
            } else {
                a
            }
        })
    }

    /// Collapses cheapest-first until `target` vertices remain or nothing more may collapse.
    ///
    /// One heap entry per vertex (its cheapest outgoing collapse), not one per half-edge: the heap
    /// stays V entries instead of growing to millions, which is what made simplification the
    /// slowest step (cache misses in the sift-down). Entries are invalidated by a per-vertex stamp
    /// whenever a collapse changes the vertex's quadric or ring.
    pub fn simplify(&mut self, target: usize, strict: bool, progress: &Progress) -> Result<()> {
        let target = target.max(4);
        if self.alive_vertices <= target {
            return Ok(());
        }
        let n = self.pos.len();
        let mut stamp = vec![0u32; n];
        // best[v]: v's cheapest collapse (cost, other end); live[v]: the key of v's valid heap
        // entry, NaN when v has none (dropped because nothing was allowed).
        let mut best = vec![(f64::INFINITY, u32::MAX); n];
        let mut live = vec![f64::NAN; n];
        let mut heap: BinaryHeap<Reverse<(Cost, u32, u32)>> = BinaryHeap::with_capacity(n);
        for v in 0..n as u32 {
            if self.vertex_alive[v as usize] {
                best[v as usize] = self.best_of(v);
                live[v as usize] = best[v as usize].0;
                heap.push(Reverse((Cost(live[v as usize]), v, 0)));
            }
        }
        let start = self.alive_vertices;
        let mut iter = 0usize;
        while self.alive_vertices > target {
            let Some(Reverse((Cost(key), vt, st))) = heap.pop() else { break };
            iter += 1;
            if iter % 4096 == 0 {
                progress.fraction((start - self.alive_vertices) as f64 / (start - target) as f64)?;
            }
            if !self.vertex_alive[vt as usize] || stamp[vt as usize] != st {
                continue;
            }
            // Nothing allowed now: dropped until a collapse nearby changes the vertex's ring.
            let Some((cost, vs, cheapest)) = self.best_allowed(vt, strict) else {
                live[vt as usize] = f64::NAN;
                continue;
            };
            if !cheapest && cost > key {
                // The cheapest collapse is refused: queue the vertex again at its allowed cost.
                heap.push(Reverse((Cost(cost), vt, st)));
                live[vt as usize] = cost;
                continue;
            }
            self.collapse(vt, vs);
            // The quadric of vs grew: its collapses are recomputed. Of each neighbour w's
            // collapses only w → vs changed cost (and w → vt is gone), so w's best is updated
            // from that one edge unless it pointed at vt or vs. An entry is (re)queued when the
            // key changes or w had none (its ring changed, so something may be allowed now).
            let b = self.best_of(vs);
            best[vs as usize] = b;
            stamp[vs as usize] += 1;
            live[vs as usize] = b.0;
            heap.push(Reverse((Cost(b.0), vs, stamp[vs as usize])));
            for w in self.neighbours(vs).iter().copied() {
                let wi = w as usize;
                let old = best[wi];
                let b = if old.1 == vs || old.1 == vt {
                    self.best_of(w)
                } else {
                    let c = self.cost(w, vs);
                    if c < old.0 {
                        (c, vs)
                    } else {
                        old
                    }
                };
                best[wi] = b;
                if live[wi] != b.0 {
                    stamp[wi] += 1;
                    live[wi] = b.0;
                    heap.push(Reverse((Cost(b.0), w, stamp[wi])));
                }
            }
        }
        if !strict && self.alive_vertices > target {
            return Err(Error::numerical(
                "simplify",
                format!("no collapsible edge left at {} vertices (target {target})", self.alive_vertices),
            ));
        }
        Ok(())
    }

    /// The current (simplified) mesh with compact indices; `map[new] = old vertex id`.
    pub fn current(&self) -> (Vec<u32>, Vec<[u32; 3]>) {
        let mut old_to_new = vec![u32::MAX; self.pos.len()];
        let mut map = Vec::with_capacity(self.alive_vertices);
        for (v, &a) in self.vertex_alive.iter().enumerate() {
            if a {
                old_to_new[v] = map.len() as u32;
                map.push(v as u32);
            }
        }
        let tris = self
            .tris
            .iter()
            .zip(&self.face_alive)
            .filter(|(_, &a)| a)
            .map(|(t, _)| t.map(|v| old_to_new[v as usize]))
            .collect();
        (map, tris)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::morph::trimesh::{topology, TriMesh};

    #[test]
    fn collapse_to_tetrahedron_and_split_back_restores_the_mesh() {
        let m = crate::shapes::icosphere(2, 1.0);
        let tris = crate::shapes::fan_triangles(&m.faces);
        let mut h = Hierarchy::new(&m.positions, &tris);
        h.simplify(100, true, &Progress::new()).unwrap();
        assert_eq!(h.alive_vertices, 100);
        h.simplify(4, false, &Progress::new()).unwrap();
        assert_eq!(h.alive_vertices, 4);
        let (map, t) = h.current();
        let small = TriMesh { pos: map.iter().map(|&v| m.positions[v as usize]).collect(), tris: t };
        let info = topology(&small);
        assert_eq!((info.vertices, info.faces, info.genus), (4, 4, Some(0)));
        while h.split_last().is_some() {}
        assert_eq!(h.tris, tris);
        assert!(h.face_alive.iter().all(|&a| a));
    }
}

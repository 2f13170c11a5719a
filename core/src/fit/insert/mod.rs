//! Local refinement at the curve points: every curve vertex gets a template vertex of its own by
//! splitting the template at the curve vertex's closest point on the (coarsely aligned) surface.
//!
//! This is the seed's remedy for curves denser than the template (§2.1/§2.3: "subdivide locally so
//! there are enough vertices") taken to its finest form. Matching curve vertices to the nearest
//! *existing* template vertex (the seed's rule, kept as `correspondence = "nearest_vertex"`)
//! displaces each matched vertex tangentially by up to half an edge, in directions that jitter from
//! one curve vertex to the next. Where curve vertices are as dense as the template edges, or denser,
//! that jitter folds faces, makes neighbouring curve vertices swap order on the surface and lets
//! curve chains cross (measured on homer: 97% of segments as edges, merged regions). Splitting at
//! the foot point instead makes every fine-RBF displacement the (small, nearly normal) distance from
//! the surface to the curve, one curve vertex per template vertex by construction, whatever the
//! density.
//!
//! Rules: a foot within `VERTEX_SNAP` (barycentric) of a free template vertex reuses it; within
//! `EDGE_SNAP` of an edge it splits that edge (both faces, no T-junction); otherwise it splits its
//! face 1→3. Both snaps avoid slivers but move the curve vertex's pre-image, so they are allowed
//! only within a quarter of the curve's local segment length (dense curves get exact feet). A foot at an already claimed vertex is nudged towards the centre of its face so no
//! two RBF centres coincide. Feature points go first so they get the exact vertex at crossings.

use serde::Serialize;

use crate::error::{Error, Result};
use crate::geometry::{add, dist, dot, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;
use crate::spatial::closest_on_triangle;

use super::curves::CurveNetwork;
use super::kdtree::KdTree;
use super::trimesh::TriMesh;

pub mod coincident;
pub mod order;
pub mod pileup;
pub mod walk;

/// A foot whose largest barycentric coordinate is above 1 − this reuses that vertex.
const VERTEX_SNAP: f64 = 0.3;
/// A foot whose smallest barycentric coordinate is below this splits the opposite edge.
const EDGE_SNAP: f64 = 0.3;

#[derive(Debug, Clone, Default, Serialize)]
pub struct InsertStats {
    /// Curve vertices matched to an existing template vertex (feet within the vertex snap).
    pub reused_vertices: usize,
    /// Curve vertices inserted on a template edge (edge split 2 → 4 faces).
    pub edge_splits: usize,
    /// Curve vertices inserted inside a face (1 → 3 faces).
    pub face_splits: usize,
    /// Feet moved off an already claimed vertex.
    pub nudged: usize,
    /// Curve ends (network degree 1) matched on the template boundary (see [`super::ends`]).
    pub ends_on_boundary: usize,
    /// Curve points whose foot was searched along their curve ([`walk`]) and differs from their
    /// closest point (which was on a part of the template the curve does not pass).
    pub walked_feet: usize,
    /// Curve points whose foot was shared with another's (piled at a convex corner or crease)
    /// and was spread over the faces there ([`pileup`]).
    pub spread_feet: usize,
    /// Segments whose feet step out of the curve's order ([`order`]) with plain closest points,
    /// and with the walked feet used.
    pub out_of_order_closest: usize,
    pub out_of_order: usize,
    /// Segments whose feet are more than [`order::MAX_STRETCH`] × the segment apart.
    pub stretched: usize,
    /// Distance from each curve vertex to its template vertex before the fine deformation.
    pub distance_max: f64,
    pub distance_mean: f64,
}

pub struct Inserted {
    pub vertex_of_point: Vec<u32>,
    /// For each output vertex: the template face (of the input `tris`) and barycentric coordinates it
    /// was created at, for vertices added here (attribute interpolation); `None` for old vertices.
    pub created_in: Vec<Option<(u32, [f64; 3])>>,
    pub stats: InsertStats,
}

/// Inserts every curve vertex not fixed by a user pair. `fixed` = (curve point, template vertex).
/// Curve ends within `end_snap` (a distance) of the template boundary are inserted on the
/// boundary. Feet follow their curve ([`walk`]). `search` is the closest-point search on this
/// `pos`/`tris` when the caller has one (the refinement's), else one is built. On return
/// `pos`/`tris` are the refined template.
pub fn insert_curve_points(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &CurveNetwork,
    fixed: &[(u32, u32)],
    end_snap: f64,
    search: Option<FootSearch>,
    progress: &Progress,
) -> Result<Inserted> {
    let n = net.points.len();
    let vf = vertex_faces(pos.len(), tris);
    let search = match search {
        Some(s) => s,
        None => FootSearch::new_polled(pos, tris, progress)?,
    };
    let mut feet = search.into_all_feet(&net.points)?;
    let on_rim = super::ends::boundary_feet(pos, tris, net, end_snap);
    for b in &on_rim {
        feet[b.point_index as usize] = (b.face, b.foot, b.distance);
    }
    let mut vop = vec![u32::MAX; n];
    // Anchors keep their own feet: feature points, curve ends, user pairs, ends on the rim.
    let mut anchor: Vec<bool> = net.degree.iter().map(|&d| d != 2).collect();
    for &(p, v) in fixed {
        vop[p as usize] = v;
        anchor[p as usize] = true;
    }
    for b in &on_rim {
        anchor[b.point_index as usize] = true;
    }
    let foot_points = |feet: &[(u32, Point3, f64)]| feet.iter().map(|f| f.1).collect::<Vec<_>>();
    let out_of_order_closest = order::out_of_order_segments(net, &foot_points(&feet));
    let walked = walk::walk_feet(pos, tris, &vf, net, &mut feet, &anchor, progress)?;
    // Feet piled at one point (beyond a convex corner) would become coincident RBF centres.
    let mut keep = vec![false; n];
    for &(p, _) in fixed {
        keep[p as usize] = true;
    }
    for b in &on_rim {
        keep[b.point_index as usize] = true;
    }
    let spread = pileup::spread_piled_feet(pos, tris, &vf, &net.points, &mut feet, &keep);
    let out_of_order = order::out_of_order_segments(net, &foot_points(&feet));
    let stretched = order::stretched_segments(net, &foot_points(&feet));
    let spacing = shortest_segments(net);
    let mut queue: Vec<u32> = (0..n as u32).filter(|&p| vop[p as usize] == u32::MAX).collect();
    queue.sort_by(|&a, &b| {
        net.is_feature(b).cmp(&net.is_feature(a)).then(feet[a as usize].2.total_cmp(&feet[b as usize].2))
    });
    let mut ins = Inserter::new(std::mem::take(pos), tris, &vf, &feet, fixed)?;
    drop(vf);
    ins.stats.ends_on_boundary = on_rim.len();
    for (k, &p) in queue.iter().enumerate() {
        if k % 1024 == 0 {
            progress.fraction(k as f64 / n.max(1) as f64)?;
        }
        vop[p as usize] = ins.at_foot(p, feet[p as usize], 0.25 * spacing[p as usize])?;
    }
    ins.stats.walked_feet = walked;
    ins.stats.spread_feet = spread;
    ins.stats.out_of_order_closest = out_of_order_closest;
    ins.stats.out_of_order = out_of_order;
    ins.stats.stretched = stretched;
    let d: Vec<f64> = (0..n).map(|p| dist(net.points[p], ins.mesh.pos[vop[p] as usize])).collect();
    ins.stats.distance_max = d.iter().cloned().fold(0.0, f64::max);
    ins.stats.distance_mean = d.iter().sum::<f64>() / n.max(1) as f64;
    let (created_in, stats) = ins.finish(pos, tris);
    Ok(Inserted { vertex_of_point: vop, created_in, stats })
}

/// Faces around each vertex (the approach and the field refinement use it too).
pub(super) fn vertex_faces(nv: usize, tris: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(f as u32);
        }
    }
    vf
}

/// Shortest segment at each curve point: a snap may move the point's template vertex by at most
/// a quarter of it, or dense curves would swap order on the surface (the refinement uses it too).
pub(super) fn shortest_segments(net: &CurveNetwork) -> Vec<f64> {
    let mut spacing = vec![f64::INFINITY; net.points.len()];
    for s in &net.segments {
        let l = dist(net.points[s[0] as usize], net.points[s[1] as usize]);
        for &p in s {
            spacing[p as usize] = spacing[p as usize].min(l);
        }
    }
    spacing
}

const NONE: u32 = u32::MAX;

/// The template being refined: an editable mesh of the faces that can change (local ids), with
/// the faces that tile each local template face and every new vertex's origin.
struct Inserter {
    mesh: TriMesh,
    /// Template face of each local face, and the local face of each template face (or NONE).
    local: Vec<u32>,
    local_of: Vec<u32>,
    /// Faces of the mesh that tile each local template face (children of splits keep the origin).
    kids: Vec<Vec<u32>>,
    origin: Vec<u32>,
    created_in: Vec<Option<(u32, [f64; 3])>>,
    claimed: Vec<bool>,
    stats: InsertStats,
}

impl Inserter {
    /// Only the feet faces and their edge neighbours are editable: this keeps the step
    /// proportional to the curve, not to the template.
    fn new(
        pos: Vec<Point3>,
        tris: &[[u32; 3]],
        vf: &[Vec<u32>],
        feet: &[(u32, Point3, f64)],
        fixed: &[(u32, u32)],
    ) -> Result<Self> {
        let nv0 = pos.len();
        let mut local_of = vec![NONE; tris.len()];
        let mut local: Vec<u32> = Vec::new();
        for &(f, _, _) in feet {
            let t = tris[f as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for &g in &vf[a as usize] {
                    if local_of[g as usize] == NONE && tris[g as usize].contains(&b) {
                        local_of[g as usize] = local.len() as u32;
                        local.push(g);
                    }
                }
            }
        }
        let local_tris: Vec<[u32; 3]> = local.iter().map(|&f| tris[f as usize]).collect();
        let mesh = TriMesh::new(pos, local_tris)?;
        let mut claimed = vec![false; nv0];
        for &(_, v) in fixed {
            claimed[v as usize] = true;
        }
        Ok(Inserter {
            kids: (0..mesh.tris.len() as u32).map(|f| vec![f]).collect(),
            origin: (0..mesh.tris.len() as u32).collect(),
            mesh,
            local,
            local_of,
            created_in: vec![None; nv0],
            claimed,
            stats: InsertStats::default(),
        })
    }

    /// Inserts curve point `p` at its foot (template face, point, distance): reuses a free vertex
    /// or splits an edge within `max_move` of the foot, else splits the face there.
    fn at_foot(&mut self, p: u32, (tf_template, mut x, _): (u32, Point3, f64), max_move: f64) -> Result<u32> {
        let tf = self.local_of[tf_template as usize];
        let mut nudges = 0;
        let v = loop {
            let (c, l) = locate(&self.mesh, &self.kids[tf as usize], x)
                .ok_or_else(|| Error::Internal(format!("curve point {p}: foot not found in its face")))?;
            let t = self.mesh.tris[c as usize];
            let (imax, lmax) = argmax(l);
            let (imin, lmin) = argmin(l);
            if lmax > 1.0 - VERTEX_SNAP {
                let v = t[imax];
                if !self.claimed[v as usize] && dist(self.mesh.pos[v as usize], x) <= max_move {
                    self.stats.reused_vertices += 1;
                    break v;
                }
                if lmax > 1.0 - 1e-6 || nudges > 0 {
                    // The exact foot is a claimed vertex: move it into the face (a few % of the face).
                    nudges += 1;
                    self.stats.nudged += (nudges == 1) as usize;
                    let p3 = |i: usize| self.mesh.pos[t[i] as usize];
                    let centroid = scale(add(add(p3(0), p3(1)), p3(2)), 1.0 / 3.0);
                    x = add(scale(x, 0.8), scale(centroid, 0.2));
                    if nudges > 8 {
                        // Only a degenerate neighbourhood (zero-area faces) leaves no room: the
                        // centroid pull above always frees an inner point of a proper face.
                        return Err(Error::InvalidMesh {
                            location: crate::error::Location::Face(tf_template as usize),
                            message: format!(
                                "the template is degenerate here (zero-area faces): curve point {p} has no \
                                 free place to be inserted near its closest point; repair or remesh the template"
                            ),
                        });
                    }
                    continue;
                }
            }
            // On the edge opposite imin: the point of that edge at the same ratio.
            let (a, b) = (t[(imin + 1) % 3], t[(imin + 2) % 3]);
            let (la, lb) = (l[(imin + 1) % 3], l[(imin + 2) % 3]);
            let s = lb / (la + lb);
            let xe = add(scale(self.mesh.pos[a as usize], 1.0 - s), scale(self.mesh.pos[b as usize], s));
            break if lmin < EDGE_SNAP && (lmin == 0.0 || dist(xe, x) <= max_move) {
                self.stats.edge_splits += 1;
                self.split_edge_at(a, b, xe)
            } else {
                self.stats.face_splits += 1;
                let m = split_face(&mut self.mesh, c, x, &mut self.kids, &mut self.origin);
                self.created(m, tf);
                m
            };
        };
        self.claimed[v as usize] = true;
        Ok(v)
    }

    /// Splits edge (a, b) at `x` (on it), recording where the new vertex was made.
    fn split_edge_at(&mut self, a: u32, b: u32, x: Point3) -> u32 {
        let f = self.mesh.face_with_edge(a, b).or_else(|| self.mesh.face_with_edge(b, a));
        let org = f.map_or(0, |f| self.origin[f as usize]);
        let m = split_edge(&mut self.mesh, a, b, x, &mut self.kids, &mut self.origin);
        self.created(m, org);
        m
    }

    /// Records new vertex `m`, made inside local template face `tf`.
    fn created(&mut self, m: u32, tf: u32) {
        let tpos = tri_pos(&self.mesh, tf);
        self.created_in.push(Some((self.local[tf as usize], barycentric(self.mesh.pos[m as usize], &tpos))));
        self.claimed.push(false);
    }

    /// The refined template back into `pos`/`tris` (the faces never edited, then the local mesh).
    fn finish(
        self,
        pos: &mut Vec<Point3>,
        tris: &mut Vec<[u32; 3]>,
    ) -> (Vec<Option<(u32, [f64; 3])>>, InsertStats) {
        let local_of = &self.local_of;
        let mut out: Vec<[u32; 3]> =
            tris.iter().enumerate().filter(|(f, _)| local_of[*f] == NONE).map(|(_, t)| *t).collect();
        out.extend(self.mesh.live_triangles());
        *tris = out;
        *pos = self.mesh.pos;
        (self.created_in, self.stats)
    }
}

/// A curve point's foot: (template face, closest point, distance).
pub type Foot = (u32, Point3, f64);

/// Closest point of each curve point on the template: (face, point, distance), exact (a BVH over
/// the faces). The faces around the nearest template *vertex* are not enough: on a coarse template
/// or one in pieces, the nearest vertex can belong to another piece that passes close by (raw
/// suzanne: a curve on the head, 0.05 from an eye whose vertices are nearer than any head vertex,
/// got its foot on the eye, and its segments could not be made edges). One BVH build per call:
/// build a [`FootSearch`] to query one template several times.
pub(crate) fn feet(pos: &[Point3], tris: &[[u32; 3]], points: &[Point3], which: &[u32]) -> Result<Vec<Foot>> {
    FootSearch::new(pos, tris)?.feet(points, which)
}

/// The exact closest-point search on one template (its BVH), kept so the refinement's density
/// check and the insertion share it: building it over the 190k faces of the headline's template
/// costs more than the 2k queries.
pub struct FootSearch {
    bvh: crate::spatial::Bvh,
    /// The feet of every curve point in order (as [`FootSearch::feet`] of all gives them), when
    /// already found on this template.
    all: Option<Vec<Foot>>,
}

impl FootSearch {
    pub fn new(pos: &[Point3], tris: &[[u32; 3]]) -> Result<FootSearch> {
        Self::new_polled(pos, tris, &Progress::new())
    }

    /// [`FootSearch::new`] polling `progress` while the BVH is built (~40 ms on 190k faces at
    /// load 1: the longest step of the fine stage without a poll after the RBF factorisation).
    pub fn new_polled(pos: &[Point3], tris: &[[u32; 3]], progress: &Progress) -> Result<FootSearch> {
        if tris.is_empty() {
            return Err(Error::params("template", "the template has no faces"));
        }
        let bvh = crate::spatial::Bvh::new_polled(pos, &crate::mesh::Faces::from_triangles(tris), progress)?;
        Ok(FootSearch { bvh, all: None })
    }

    /// Feet of `points[i]` for `i` in `which`, in that order. Each query starts from the previous
    /// answer (the result does not depend on it except between exactly equidistant faces).
    pub fn feet(&self, points: &[Point3], which: &[u32]) -> Result<Vec<Foot>> {
        let mut out = Vec::with_capacity(which.len());
        let mut hint = 0u32;
        for &i in which {
            let p = points[i as usize];
            let (c, slot) =
                self.bvh.closest_hinted(p, hint).ok_or_else(|| Error::Internal("empty template".into()))?;
            hint = slot;
            out.push((c.face, c.point, c.dist2.sqrt()));
        }
        Ok(out)
    }

    /// Feet of all `points` in order, found once per template (kept for [`Self::into_all_feet`]).
    pub fn all_feet(&mut self, points: &[Point3]) -> Result<&[Foot]> {
        let all = match self.all.take() {
            Some(all) => all,
            None => self.feet(points, &(0..points.len() as u32).collect::<Vec<_>>())?,
        };
        Ok(self.all.insert(all))
    }

    /// [`Self::all_feet`], handed over.
    pub fn into_all_feet(mut self, points: &[Point3]) -> Result<Vec<Foot>> {
        self.all_feet(points)?;
        Ok(self.all.unwrap_or_default())
    }
}

/// Closest point of each curve point near the template's nearest vertex: (face, point, distance)
/// over the faces of that vertex's two-ring. Exact for points near a reasonably fine surface in
/// one piece, and cheap (no BVH build per call): used by the approach levels ([`super::approach`]),
/// which only steer the template and run several times. The insertion uses the exact [`feet`].
pub(crate) fn feet_near_vertex(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    points: &[Point3],
    which: &[u32],
) -> Result<Vec<(u32, Point3, f64)>> {
    let tree = KdTree::new(pos);
    let mut out = Vec::with_capacity(which.len());
    let mut cand: Vec<u32> = Vec::new();
    for &i in which {
        let p = points[i as usize];
        let (v, _) = tree.nearest(p).ok_or_else(|| Error::Internal("empty template".into()))?;
        cand.clear();
        for &f in &vf[v as usize] {
            for &w in &tris[f as usize] {
                cand.extend_from_slice(&vf[w as usize]);
            }
        }
        cand.sort_unstable();
        cand.dedup();
        let mut best: Option<(u32, Point3, f64)> = None;
        for &f in &cand {
            let t = tris[f as usize];
            let q = closest_on_triangle(p, &[pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]]);
            let d = dist(p, q);
            if best.is_none_or(|b| d < b.2) {
                best = Some((f, q, d));
            }
        }
        out.push(best.ok_or_else(|| {
            Error::params("template", format!("template vertex {v} (nearest to curve point {i}) has no face"))
        })?);
    }
    Ok(out)
}

fn tri_pos(mesh: &TriMesh, f: u32) -> [Point3; 3] {
    let t = mesh.tris[f as usize];
    [mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize]]
}

/// Barycentric coordinates of `x` (in or near the triangle's plane) in `t`.
pub fn barycentric(x: Point3, t: &[Point3; 3]) -> [f64; 3] {
    let (e0, e1, d) = (sub(t[1], t[0]), sub(t[2], t[0]), sub(x, t[0]));
    let (a, b, c) = (dot(e0, e0), dot(e0, e1), dot(e1, e1));
    let (p, q) = (dot(d, e0), dot(d, e1));
    let den = a * c - b * b;
    if den <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let l1 = (c * p - b * q) / den;
    let l2 = (a * q - b * p) / den;
    [1.0 - l1 - l2, l1, l2]
}

/// The live child face containing `x` (largest smallest-coordinate) and its coordinates.
fn locate(mesh: &TriMesh, kids: &[u32], x: Point3) -> Option<(u32, [f64; 3])> {
    let mut best: Option<(u32, [f64; 3], f64)> = None;
    for &c in kids {
        if !mesh.alive[c as usize] {
            continue;
        }
        let l = barycentric(x, &tri_pos(mesh, c));
        let m = argmin(l).1;
        if best.is_none_or(|b| m > b.2) {
            best = Some((c, l, m));
        }
    }
    let (c, l, _) = best?;
    // Clamp tiny negative round-off so the split point stays in the face.
    let l = [l[0].max(0.0), l[1].max(0.0), l[2].max(0.0)];
    let s = l[0] + l[1] + l[2];
    Some((c, [l[0] / s, l[1] / s, l[2] / s]))
}

fn argmax(l: [f64; 3]) -> (usize, f64) {
    (0..3).map(|i| (i, l[i])).fold((0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a })
}

fn argmin(l: [f64; 3]) -> (usize, f64) {
    (0..3).map(|i| (i, l[i])).fold((0, f64::MAX), |a, b| if b.1 < a.1 { b } else { a })
}

fn add_child(mesh: &mut TriMesh, t: [u32; 3], org: u32, kids: &mut [Vec<u32>], origin: &mut Vec<u32>) {
    // The removed face freed these directed edges, so adding cannot collide.
    if let Ok(f) = mesh.add_face(t) {
        origin.push(org);
        kids[org as usize].push(f);
    }
}

/// Splits face `c` at `x` into three.
fn split_face(mesh: &mut TriMesh, c: u32, x: Point3, kids: &mut [Vec<u32>], origin: &mut Vec<u32>) -> u32 {
    let t = mesh.tris[c as usize];
    let org = origin[c as usize];
    mesh.remove_face(c);
    let m = mesh.add_vertex(x);
    for k in 0..3 {
        add_child(mesh, [t[k], t[(k + 1) % 3], m], org, kids, origin);
    }
    m
}

/// Splits the edge (a, b) at `x` and both faces on it (one on a boundary).
fn split_edge(
    mesh: &mut TriMesh,
    a: u32,
    b: u32,
    x: Point3,
    kids: &mut [Vec<u32>],
    origin: &mut Vec<u32>,
) -> u32 {
    let faces: Vec<u32> =
        [mesh.face_with_edge(a, b), mesh.face_with_edge(b, a)].into_iter().flatten().collect();
    let m = mesh.add_vertex(x);
    // In face order (a hash map here made the new face ids, and so the whole fit, vary run to run).
    let mut split: Vec<([u32; 3], u32)> = Vec::with_capacity(2);
    for f in faces {
        split.push((mesh.tris[f as usize], origin[f as usize]));
        mesh.remove_face(f);
    }
    for (t, org) in split {
        // Rotate so the split edge is (t[0], t[1]).
        let k = (0..3)
            .find(|&k| (t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a))
            .unwrap_or(0);
        let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        add_child(mesh, [p, m, r], org, kids, origin);
        add_child(mesh, [m, q, r], org, kids, origin);
    }
    m
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The fine stage's closest-point search builds a BVH over the whole approached template
    /// (~40 ms on the headline's 190k faces, before without a poll): the build polls as the
    /// BVH's own polled build does and stops at a cancel. The count's bounds by hand: median
    /// splits of 20,480 triangles down to leaves of ≤ 4 touch every triangle on 14 levels
    /// (20,480 / 2¹³ = 2.5), 286,720 in all, a poll per ≥ 32,768 of it (and < 32,768 + 20,480).
    #[test]
    fn the_foot_search_build_polls_and_stops_at_a_cancel() {
        let m = crate::shapes::icosphere(5, 1.0);
        let tris = m.faces.triangles();
        assert_eq!(tris.len(), 20_480);
        let p = Progress::new();
        FootSearch::new_polled(&m.positions, &tris, &p).unwrap();
        assert!((5..=8).contains(&p.checks()), "{} polls", p.checks());
        let q = Progress::new();
        crate::spatial::Bvh::new_polled(&m.positions, &m.faces, &q).unwrap();
        assert_eq!(p.checks(), q.checks());
        let p = Progress::new();
        p.cancel_at_check(3);
        assert!(matches!(FootSearch::new_polled(&m.positions, &tris, &p), Err(Error::Cancelled)));
        assert_eq!(p.checks(), 3);
    }

    /// The insertion's polls, counted by hand: its search's BVH build (as counted above), one per
    /// 256 walks (a closed run of 1,000 segments: walks 256, 512, 768) and one per 1,024 queued
    /// points (1,000 points: k = 0). The code before made only the last one: the build and the
    /// walks ran without a poll.
    #[test]
    fn the_insertion_polls_in_its_search_walks_and_queue() {
        let m = crate::shapes::icosphere(5, 1.0);
        let n = 1000;
        let pts: Vec<Point3> = (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * (k as f64 + 0.3) / n as f64;
                [1.01 * t.cos(), 1.01 * t.sin(), 0.05]
            })
            .collect();
        let mut ring: Vec<u32> = (0..n as u32).collect();
        ring.push(0);
        let curves = crate::mesh::Mesh { positions: pts, curves: vec![ring], ..Default::default() };
        let net = CurveNetwork::from_mesh(&curves, 1e-9).unwrap();
        assert_eq!(net.points.len(), n);
        assert_eq!(net.polylines.iter().map(|l| l.len() - 1).sum::<usize>(), n, "the case: 1,000 segments");
        let bvh = Progress::new();
        crate::spatial::Bvh::new_polled(&m.positions, &m.faces, &bvh).unwrap();
        let (mut pos, mut tris) = (m.positions.clone(), m.faces.triangles());
        let p = Progress::new();
        insert_curve_points(&mut pos, &mut tris, &net, &[], 0.0, None, &p).unwrap();
        assert_eq!(p.checks(), bvh.checks() + 3 + 1);
    }

    #[test]
    fn splits_face_edge_and_reuses_vertex() {
        // Unit square of two triangles; curve points: one near the centre of face 1, one over the
        // boundary edge 0–1, one next to vertex 3. Hand truth: 1→3 split (+2 faces), boundary edge
        // split (+1 face), reuse.
        let mut pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let mut tris = vec![[0, 1, 2], [0, 2, 3]];
        let pts = vec![[0.33, 0.66, 0.1], [0.5, 0.0, -0.05], [0.01, 0.98, 0.0]];
        let mesh =
            crate::mesh::Mesh { positions: pts.clone(), curves: vec![vec![0, 1, 2]], ..Default::default() };
        let net = CurveNetwork::from_mesh(&mesh, 1e-9).unwrap();
        let ins = insert_curve_points(&mut pos, &mut tris, &net, &[], 0.0, None, &Progress::new()).unwrap();
        assert_eq!(ins.stats.face_splits, 1);
        assert_eq!(ins.stats.edge_splits, 1);
        assert_eq!(ins.stats.reused_vertices, 1);
        assert_eq!(tris.len(), 2 + 2 + 1);
        assert_eq!(pos.len(), 6);
        let vop = &ins.vertex_of_point;
        assert!(dist(pos[vop[0] as usize], [0.33, 0.66, 0.0]) < 1e-12);
        assert_eq!(pos[vop[1] as usize], [0.5, 0.0, 0.0]);
        assert_eq!(vop[2], 3);
        // The square's area is unchanged and every face keeps the +z orientation.
        let mut area = 0.0;
        for t in &tris {
            let c =
                crate::geometry::triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
            assert!(c[2] > 0.0, "{t:?}");
            area += c[2] / 2.0;
        }
        assert!((area - 1.0).abs() < 1e-12);
        // New vertices know where they were made: face 1 at (0.33, 0.66) has coordinates (0.34, 0.33, 0.33).
        let (f, l) = ins.created_in[vop[0] as usize].unwrap();
        assert_eq!(f, 1);
        for (a, b) in l.iter().zip([0.34, 0.33, 0.33]) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    /// Two parallel unit squares, z = 0 (facing −z) and z = 0.1 (facing +z), 8 × 8 cells of two
    /// triangles each, not connected: a thin plate whose sheets are closer than a curve may be to
    /// either (also the approach's walk tests).
    pub(crate) fn two_sheet_plate() -> (Vec<Point3>, Vec<[u32; 3]>) {
        let n = 8;
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for (sheet, z) in [0.0, 0.1].into_iter().enumerate() {
            let base = pos.len() as u32;
            for j in 0..=n {
                for i in 0..=n {
                    pos.push([i as f64 / n as f64, j as f64 / n as f64, z]);
                }
            }
            let id = |i: u32, j: u32| base + j * (n + 1) + i;
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                    // The lower sheet faces −z, the upper +z (the outside of a thin plate).
                    if sheet == 0 {
                        tris.extend([[a, c, b], [a, d, c]]);
                    } else {
                        tris.extend([[a, b, c], [a, c, d]]);
                    }
                }
            }
        }
        (pos, tris)
    }

    /// Two sheets 0.1 apart (z = 0 and z = 0.1, unit squares split into 8 × 8 × 2 triangles, not
    /// connected) and a curve along x over the lower one at z = 0.03, except two points that
    /// bulge to z = 0.07: closer to the upper sheet (0.03) than to the lower (0.07). Hand truth:
    /// the curve runs along the lower sheet, so every curve vertex is inserted there (z = 0), in
    /// x order. Plain closest points put the two bulging points on the upper sheet.
    #[test]
    fn feet_follow_their_curve_instead_of_jumping_to_a_nearby_sheet() {
        let (mut pos, mut tris) = two_sheet_plate();
        let pts: Vec<Point3> = (1..=9)
            .map(|k| {
                let z = if k == 5 || k == 6 { 0.07 } else { 0.03 };
                [0.1 * k as f64 - 0.03, 0.45, z]
            })
            .collect();
        let curves = crate::mesh::Mesh {
            positions: pts.clone(),
            curves: vec![(0..9).collect()],
            ..Default::default()
        };
        let net = CurveNetwork::from_mesh(&curves, 1e-9).unwrap();
        // The case this test is for: the bulging points' plain closest points are on the upper sheet.
        let closest = feet(&pos, &tris, &pts, &[4, 5]).unwrap();
        assert!(closest.iter().all(|f| (f.1[2] - 0.1).abs() < 1e-12));
        let ins = insert_curve_points(&mut pos, &mut tris, &net, &[], 0.0, None, &Progress::new()).unwrap();
        assert_eq!(ins.stats.walked_feet, 2);
        let mut last_x = f64::NEG_INFINITY;
        for (p, &v) in ins.vertex_of_point.iter().enumerate() {
            let x = pos[v as usize];
            assert_eq!(x[2], 0.0, "curve point {p} inserted on the upper sheet");
            assert!(x[0] > last_x, "curve point {p} out of order");
            last_x = x[0];
        }
        assert_eq!(ins.stats.out_of_order, 0);
    }
}

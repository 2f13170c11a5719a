//! The template's orientation carried through the fit's smooth maps: the reference the report's
//! `flipped_faces` is measured against.
//!
//! Why: the fit moves the template by a chain of smooth maps of space (the alignment's similarity
//! and warp, the coarse RBF through user pairs, the approach levels, the fine RBF). A face is
//! turned over *relative to the template* when its normal opposes the template's normal pushed
//! forward by those maps. Comparing with the template's own normals is wrong (a bend or a twist
//! legitimately turns parts by more than 90°), and comparing with the surface one stage earlier
//! (what the report did before, against the fine-deformed mesh) cannot see a fold any earlier map
//! made: on the bent thin cases of `sweep_unseen` the report said 250 / 105 / 12 where 2,231 /
//! 1,969 / 404 faces were turned against the analytic normal (docs/benchmarks.md, fit-thin,
//! session 12).
//!
//! The pushed-forward normal of a map with Jacobian J is the covector J⁻ᵀ·n = cof(J)·n / det J.
//! Where det J > 0 it is the normal of the image of a small face (cof(J)·n); where det J ≤ 0 the
//! map turns space inside out there, and the image of a face points *against* it (the identity
//! (Ja)×(Jb) = cof(J)(a×b) holds for any J, so the image face's normal is cof(J)·n even then).
//! So one test, output normal against J⁻ᵀ·n, counts both the faces the discrete mesh folded
//! against its maps and the faces the maps themselves turned over; the second kind is also counted
//! on its own ([`Orientation::inverted`]).
//!
//! Each working vertex carries the composite Jacobian and its place on the template (a vertex, a
//! face, an edge). Vertices the fit adds lie on older faces or edges (insertions at feet,
//! subdivision midpoints, refinement splits, re-triangulation splits): each takes the blend of its
//! parents' Jacobians (the maps are smooth) and the template face or edge its parents share, its
//! parents being the lineage the fit keeps for UVs. A face is compared with the normal of the
//! template face its corners share, so an untouched or subdivided template face is compared with
//! its own normal (vertex normals are ambiguous at creases and thin fins).

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::error::Result;
use crate::geometry::{add, cross, dot, normalize, scale, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::rbf::Rbf;

/// A 3×3 Jacobian: `j[r][c]` = ∂(output r)/∂(input c).
pub type Jacobian = [[f64; 3]; 3];

/// The identity map's Jacobian.
pub const IDENTITY: Jacobian = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Where on the template a working vertex lies (for the template normal there).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Place {
    /// A template vertex.
    Vertex(u32),
    /// Inside (or on the border of) one template face.
    Face(u32),
    /// On the edge between two template faces.
    Edge(u32, u32),
    /// Across several template faces (a split of a segment between two of them).
    Across,
}

/// A map whose Jacobians were summed in single precision ([`Orientation::push_field`]): what it
/// takes to evaluate them again exactly.
#[derive(Clone)]
enum Step {
    /// x ↦ x + step · field(x), from the positions `before` it.
    Field { field: Arc<Rbf>, step: f64, before: Vec<Point3> },
    /// An exact map after a bounded one: its Jacobian per vertex.
    Exact(Vec<Jacobian>),
}

/// From the first bounded map on, what re-evaluating a vertex's composite Jacobian exactly takes:
/// the composite before that map, every map since, and the lineage of the vertices added since.
#[derive(Clone)]
struct Replay {
    origin: Vec<Jacobian>,
    steps: Vec<Step>,
    /// Per vertex added after `origin`: its parents and how many `steps` it had then.
    added: Vec<([(u32, f64); 3], usize)>,
    /// False once a rollback removed a vertex older than the first bounded map (no caller does):
    /// faces the bounds leave open are then decided by their approximate Jacobians.
    valid: bool,
}

/// Per working vertex of the fit: the composite Jacobian of every map applied so far, a bound on
/// its error, and where on the template the vertex lies.
#[derive(Clone)]
pub struct Orientation {
    jacobians: Vec<Jacobian>,
    /// Frobenius-norm bound on each Jacobian's error (0 while every map was exact).
    errors: Vec<f64>,
    places: Vec<Place>,
    /// The template's unit face normals and area-weighted vertex normals.
    face_normals: Vec<Point3>,
    vertex_normals: Vec<Point3>,
    /// Template faces around each template vertex (CSR).
    vf_start: Vec<u32>,
    vf: Vec<u32>,
    /// Vertices with an index below this are the template's; vertex `base + i` has `parents[i]`.
    base: usize,
    replay: Option<Replay>,
    /// Each vertex's index when the maps were pushed (identity until [`Orientation::renumbered`]).
    working: Option<Vec<u32>>,
}

/// `cof(J)·n` and `det J`: with the columns a, b, c of J, cof(J) = [b×c, c×a, a×b].
pub fn cofactor_times(j: &Jacobian, n: Point3) -> (Point3, f64) {
    let col = |k: usize| [j[0][k], j[1][k], j[2][k]];
    let (a, b, c) = (col(0), col(1), col(2));
    let (bc, ca, ab) = (cross(b, c), cross(c, a), cross(a, b));
    let v = add(add(scale(bc, n[0]), scale(ca, n[1])), scale(ab, n[2]));
    (v, dot(a, bc))
}

/// The unit covector J⁻ᵀ·n (the normal n pushed forward), zero where it vanishes.
pub fn push_normal(j: &Jacobian, n: Point3) -> Point3 {
    let (c, det) = cofactor_times(j, n);
    normalize(if det > 0.0 { c } else { scale(c, -1.0) })
}

/// `a · b` for 3×3 matrices.
pub fn mat_mul(a: &Jacobian, b: &Jacobian) -> Jacobian {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

fn det(j: &Jacobian) -> f64 {
    cofactor_times(j, [0.0; 3]).1
}

fn frobenius(j: &Jacobian) -> f64 {
    j.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

/// I + step · g: the Jacobian of x ↦ x + step · s(x) from the field's gradient g.
fn field_step(g: &Jacobian, step: f64) -> Jacobian {
    std::array::from_fn(|r| std::array::from_fn(|c| step * g[r][c] + if r == c { 1.0 } else { 0.0 }))
}

/// One corner of a face: its pushed-forward normal and how far the Jacobian's error bound `e`
/// could move it (2, the most a unit vector can move, where the sign of det J or the direction is
/// open). Bounds for ‖ΔJ‖_F ≤ e: cof(J)·n = (J·a)×(J·b) for orthonormal a, b with a×b = n, so it
/// moves by at most 2(‖J‖ + e)e; det J, a triple product of columns, by at most 3(‖J‖ + e)²e;
/// and a unit vector c/|c| by at most 2|Δc|/|c|.
fn corner(j: &Jacobian, e: f64, n: Point3) -> (Point3, f64) {
    let (c, d) = cofactor_times(j, n);
    let unit = normalize(if d > 0.0 { c } else { scale(c, -1.0) });
    if e == 0.0 || dot(n, n) == 0.0 {
        return (unit, 0.0);
    }
    let f = frobenius(j) + e;
    let (dc, dd, len) = (2.0 * f * e, 3.0 * f * f * e, dot(c, c).sqrt());
    let open = !(d.abs() > dd && len > 2.0 * dc);
    (unit, if open { 2.0 } else { 2.0 * dc / len })
}

/// A face's orientation against its reference: decided either way, or left open by the bounds.
#[derive(Clone, Copy, PartialEq)]
enum Decision {
    Against,
    With,
    Open,
}

impl Orientation {
    /// The template (positions, triangles), no map applied yet.
    pub fn new(template_pos: &[Point3], template_tris: &[[u32; 3]]) -> Orientation {
        let nv = template_pos.len();
        let mut vf_start = vec![0u32; nv + 1];
        for t in template_tris {
            for &v in t {
                vf_start[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            vf_start[v + 1] += vf_start[v];
        }
        let mut fill = vf_start.clone();
        let mut vf = vec![0u32; vf_start[nv] as usize];
        for (f, t) in template_tris.iter().enumerate() {
            for &v in t {
                vf[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        Orientation {
            jacobians: vec![IDENTITY; nv],
            errors: vec![0.0; nv],
            places: (0..nv as u32).map(Place::Vertex).collect(),
            face_normals: template_tris
                .iter()
                .map(|t| {
                    normalize(triangle_cross(
                        template_pos[t[0] as usize],
                        template_pos[t[1] as usize],
                        template_pos[t[2] as usize],
                    ))
                })
                .collect(),
            vertex_normals: super::report::vertex_normals(template_pos, template_tris),
            vf_start,
            vf,
            base: nv,
            replay: None,
            working: None,
        }
    }

    /// The template faces a place touches.
    fn faces_of(&self, p: Place) -> &[u32] {
        match p {
            Place::Vertex(v) => {
                &self.vf[self.vf_start[v as usize] as usize..self.vf_start[v as usize + 1] as usize]
            }
            Place::Face(_) | Place::Edge(..) | Place::Across => &[],
        }
    }

    /// Whether template face `f` is at place `p`.
    fn touches(&self, p: Place, f: u32) -> bool {
        match p {
            Place::Vertex(_) => self.faces_of(p).contains(&f),
            Place::Face(g) => g == f,
            Place::Edge(g, h) => g == f || h == f,
            Place::Across => false,
        }
    }

    /// The first template face common to all three places (in the first place's order), without
    /// allocating: this runs for every output face.
    fn shared_face(&self, places: [Place; 3]) -> Option<u32> {
        let pair;
        let candidates: &[u32] = match places[0] {
            Place::Vertex(_) => self.faces_of(places[0]),
            Place::Face(f) => {
                pair = [f, f];
                &pair[..1]
            }
            Place::Edge(f, g) => {
                pair = [f, g];
                &pair
            }
            Place::Across => return None,
        };
        candidates.iter().copied().find(|&f| self.touches(places[1], f) && self.touches(places[2], f))
    }

    /// The template faces common to all `places` (small lists: a vertex's faces at most).
    fn common_faces(&self, places: impl Iterator<Item = Place>) -> Option<Vec<u32>> {
        let mut common: Option<Vec<u32>> = None;
        for p in places {
            let own: Vec<u32> = match p {
                Place::Vertex(_) => self.faces_of(p).to_vec(),
                Place::Face(f) => vec![f],
                Place::Edge(f, g) => vec![f, g],
                Place::Across => return Some(Vec::new()),
            };
            common = Some(match common {
                None => own,
                Some(mut c) => {
                    c.retain(|f| own.contains(f));
                    c
                }
            });
        }
        common
    }

    /// Extends the arrays to the vertices added since the last call: `parents[i]` are the weighted
    /// older vertices of vertex `base + i`. A rolled-back addition (a smaller `parents`) is
    /// dropped again.
    pub fn sync(&mut self, parents: &[[(u32, f64); 3]]) {
        let want = self.base + parents.len();
        if want < self.jacobians.len() {
            self.jacobians.truncate(want);
            self.errors.truncate(want);
            self.places.truncate(want);
            if let Some(r) = self.replay.as_mut() {
                match want.checked_sub(r.origin.len()) {
                    Some(k) => r.added.truncate(k),
                    None => r.valid = false,
                }
            }
        }
        for p in &parents[self.jacobians.len() - self.base..] {
            let used = || p.iter().filter(|x| x.1 > 0.0);
            // The composite map is smooth: its Jacobian between two vertices is their blend (and
            // the blend's error at most the blend of the errors, the weights being positive).
            let mut j = [[0.0; 3]; 3];
            let mut e = 0.0;
            for &(v, w) in used() {
                let jv = &self.jacobians[v as usize];
                for r in 0..3 {
                    for c in 0..3 {
                        j[r][c] += w * jv[r][c];
                    }
                }
                e += w * self.errors[v as usize];
            }
            let first = used().next().map(|x| self.places[x.0 as usize]);
            let place = if used().all(|x| Some(self.places[x.0 as usize]) == first) {
                first.unwrap_or(Place::Across)
            } else {
                match self.common_faces(used().map(|x| self.places[x.0 as usize])).as_deref() {
                    Some([f]) => Place::Face(*f),
                    Some([f, g]) => Place::Edge(*f, *g),
                    Some([f, ..]) => Place::Face(*f),
                    _ => Place::Across,
                }
            };
            self.jacobians.push(j);
            self.errors.push(e);
            self.places.push(place);
            if let Some(r) = self.replay.as_mut() {
                r.added.push((*p, r.steps.len()));
            }
        }
    }

    pub fn len(&self) -> usize {
        self.jacobians.len()
    }

    pub fn is_empty(&self) -> bool {
        self.jacobians.is_empty()
    }

    /// Composes every vertex's Jacobian with a map whose Jacobian at the vertex's position before
    /// the map is `jacobian(v, before[v])`. `before` covers every vertex ([`Orientation::sync`]
    /// first); returns how many vertices this map inverts (det J ≤ 0).
    pub fn push(&mut self, before: &[Point3], jacobian: impl Fn(usize, Point3) -> Jacobian + Sync) -> usize {
        debug_assert_eq!(before.len(), self.jacobians.len());
        let n = before.len().min(self.jacobians.len());
        let steps: Vec<Jacobian> = before[..n].par_iter().enumerate().map(|(v, &p)| jacobian(v, p)).collect();
        let inverted = self.apply(&steps, |_| 0.0);
        if let Some(r) = self.replay.as_mut() {
            r.steps.push(Step::Exact(steps));
        }
        inverted
    }

    /// Composes every vertex's Jacobian with the map x ↦ x + step · field(x), the field's
    /// gradients summed in single precision with error bounds ([`Rbf::gradients_bounded`]): the
    /// fit's RBF maps, ~100k vertices × ~2k centres each. Keeps what the count needs to evaluate
    /// them again exactly where a face's decision is open. Returns how many vertices the map
    /// inverts by the single-precision values.
    pub fn push_field(
        &mut self,
        before: &[Point3],
        field: Arc<Rbf>,
        step: f64,
        progress: &Progress,
    ) -> Result<usize> {
        let n = before.len().min(self.jacobians.len());
        let grads = field.gradients_bounded(&before[..n], progress)?;
        let steps: Vec<Jacobian> = grads.par_iter().map(|(g, _)| field_step(g, step)).collect();
        if self.replay.is_none() {
            self.replay = Some(Replay {
                origin: self.jacobians.clone(),
                steps: Vec::new(),
                added: Vec::new(),
                valid: true,
            });
        }
        let inverted = self.apply(&steps, |v| step.abs() * grads[v].1);
        if let Some(r) = self.replay.as_mut() {
            r.steps.push(Step::Field { field, step, before: before[..n].to_vec() });
        }
        Ok(inverted)
    }

    /// Multiplies every vertex's Jacobian by its step on the left; `bound(v)`: the step's error
    /// bound (‖ΔĴ'‖ ≤ b‖Ĵ‖ + (‖Ŝ‖ + b)·e for Ĵ' = Ŝ·Ĵ). Returns the steps with det ≤ 0.
    fn apply(&mut self, steps: &[Jacobian], bound: impl Fn(usize) -> f64 + Sync) -> usize {
        self.jacobians
            .par_iter_mut()
            .zip(self.errors.par_iter_mut())
            .zip(steps.par_iter())
            .enumerate()
            .map(|(v, ((j, e), s))| {
                let b = bound(v);
                *e = b * frobenius(j) + (frobenius(s) + b) * *e;
                *j = mat_mul(s, j);
                let d = det(s);
                (d <= 0.0 || !d.is_finite()) as usize
            })
            .sum()
    }

    /// The template's normal at a place (a vertex's area-weighted normal, a face's normal, the
    /// mean of an edge's two faces; across faces: none, the face's other corners decide).
    fn template_normal(&self, p: Place) -> Point3 {
        match p {
            Place::Vertex(v) => self.vertex_normals[v as usize],
            Place::Face(f) => self.face_normals[f as usize],
            Place::Edge(f, g) => normalize(add(self.face_normals[f as usize], self.face_normals[g as usize])),
            Place::Across => [0.0; 3],
        }
    }

    /// The template normal each corner of a face carries: the normal of the template face its
    /// corners share, at every corner (no vertex normal, which is ambiguous at a crease or a thin
    /// fin: 21 of suzanne's 968 faces oppose their own corners' vertex normals), else its own
    /// place's.
    fn corner_normals(&self, t: &[u32; 3]) -> [Point3; 3] {
        let places = t.map(|v| self.places[v as usize]);
        match self.shared_face(places) {
            Some(f) => [self.face_normals[f as usize]; 3],
            None => places.map(|p| self.template_normal(p)),
        }
    }

    /// A face against its reference, the sum over its corners of the template's normal pushed
    /// forward, with each corner's Jacobian and error bound from `jac`: open when the bounds
    /// could change the sign.
    fn decide(&self, pos: &[Point3], t: &[u32; 3], jac: impl Fn(u32) -> (Jacobian, f64)) -> Decision {
        let n = normalize(triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]));
        if dot(n, n) == 0.0 {
            // A zero-area face has no normal to oppose anything (counted elsewhere: `degenerate`).
            return Decision::With;
        }
        let normals = self.corner_normals(t);
        let (mut r, mut slack) = ([0.0; 3], 0.0);
        for (k, &v) in t.iter().enumerate() {
            let (j, e) = jac(v);
            let (unit, moves) = corner(&j, e, normals[k]);
            r = add(r, unit);
            slack += moves;
        }
        let d = dot(n, r);
        if slack > 0.0 && d.abs() <= slack {
            Decision::Open
        } else if d < 0.0 {
            Decision::Against
        } else {
            Decision::With
        }
    }

    /// Faces whose normal opposes their reference ([`Orientation::decide`]); those the error
    /// bounds leave open are decided again with exact Jacobians ([`Orientation::exact`]).
    pub fn faces_against(&self, pos: &[Point3], tris: &[[u32; 3]]) -> usize {
        let stored = |v: u32| (self.jacobians[v as usize], self.errors[v as usize]);
        let decided: Vec<Decision> = tris.par_iter().map(|t| self.decide(pos, t, stored)).collect();
        let mut against = decided.iter().filter(|&&d| d == Decision::Against).count();
        let open: Vec<&[u32; 3]> =
            tris.iter().zip(&decided).filter(|x| *x.1 == Decision::Open).map(|x| x.0).collect();
        if !open.is_empty() {
            let exact = self.exact_at(open.iter().flat_map(|t| t.iter().copied()));
            for t in open {
                let d = self.decide(pos, t, |v| exact(v));
                // Without a replay (none is lost in the fit) the approximate sign decides.
                let d = if d == Decision::Open { self.decide(pos, t, |v| (stored(v).0, 0.0)) } else { d };
                against += (d == Decision::Against) as usize;
            }
        }
        against
    }

    /// Faces with at least two corners where the composite map turns space inside out (det J ≤ 0),
    /// corners whose sign the bound leaves open decided with exact Jacobians.
    pub fn faces_inverted(&self, tris: &[[u32; 3]]) -> usize {
        // Per vertex: Some(inverted) when decided, None when open.
        let sign = |j: &Jacobian, e: f64| {
            let d = det(j);
            let f = frobenius(j) + e;
            (e == 0.0 || d.abs() > 3.0 * f * f * e).then_some(!(d > 0.0))
        };
        let per: Vec<Option<bool>> =
            self.jacobians.par_iter().zip(&self.errors).map(|(j, &e)| sign(j, e)).collect();
        let open: Vec<u32> = (0..per.len() as u32).filter(|&v| per[v as usize].is_none()).collect();
        let exact = self.exact_at(open.iter().copied());
        let inverted = |v: u32| match per[v as usize] {
            Some(b) => b,
            None => !(det(&exact(v).0) > 0.0),
        };
        tris.iter().filter(|t| t.iter().filter(|&&v| inverted(v)).count() >= 2).count()
    }

    /// Exact Jacobians (error 0) at `vertices`, replayed from the first bounded map (in parallel,
    /// each vertex with its own memo: lineages rarely overlap); the stored approximation (with its
    /// bound) where no replay is kept.
    fn exact_at(&self, vertices: impl Iterator<Item = u32>) -> impl Fn(u32) -> (Jacobian, f64) + '_ {
        let mut wanted: Vec<u32> = vertices.collect();
        wanted.sort_unstable();
        wanted.dedup();
        let replay = self.replay.as_ref().filter(|r| r.valid);
        let found: HashMap<u32, (Jacobian, f64)> = wanted
            .par_iter()
            .map(|&v| {
                let stored = (self.jacobians[v as usize], self.errors[v as usize]);
                let exact = replay.and_then(|r| {
                    let w = self.working.as_ref().map_or(v, |m| m[v as usize]);
                    replay_jacobian(r, w, r.steps.len(), &mut HashMap::new()).map(|j| (j, 0.0))
                });
                (v, exact.unwrap_or(stored))
            })
            .collect();
        move |v| found.get(&v).copied().unwrap_or((self.jacobians[v as usize], self.errors[v as usize]))
    }

    /// The same, with only the vertices `keep` keeps (a renumbering after removals).
    pub fn renumbered(mut self, keep: &super::compact::Renumber) -> Orientation {
        let working: Vec<u32> = match &self.working {
            Some(w) => w.clone(),
            None => (0..self.jacobians.len() as u32).collect(),
        };
        self.working = Some(keep.vec(&working));
        self.jacobians = keep.vec(&self.jacobians);
        self.errors = keep.vec(&self.errors);
        self.places = keep.vec(&self.places);
        self
    }
}

/// Working vertex `v`'s composite Jacobian after the first `upto` steps of the replay, in f64:
/// its origin (or its parents' blend when it was added), times each step since. None when the
/// lineage does not reach (a vertex the replay does not know).
fn replay_jacobian(
    r: &Replay,
    v: u32,
    upto: usize,
    memo: &mut HashMap<(u32, usize), Jacobian>,
) -> Option<Jacobian> {
    if let Some(j) = memo.get(&(v, upto)) {
        return Some(*j);
    }
    let (mut j, from) = match r.origin.get(v as usize) {
        Some(j) => (*j, 0),
        None => {
            let &(parents, epoch) = r.added.get(v as usize - r.origin.len())?;
            let mut j = [[0.0; 3]; 3];
            for &(p, w) in parents.iter().filter(|x| x.1 > 0.0) {
                let jp = replay_jacobian(r, p, epoch, memo)?;
                for row in 0..3 {
                    for c in 0..3 {
                        j[row][c] += w * jp[row][c];
                    }
                }
            }
            (j, epoch)
        }
    };
    for step in &r.steps[from.min(upto)..upto] {
        let s = match step {
            Step::Field { field, step, before } => {
                field_step(&field.gradient(*before.get(v as usize)?), *step)
            }
            Step::Exact(per_vertex) => *per_vertex.get(v as usize)?,
        };
        j = mat_mul(&s, &j);
    }
    memo.insert((v, upto), j);
    Some(j)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::norm;

    fn sphere() -> (Vec<Point3>, Vec<[u32; 3]>) {
        let m = crate::shapes::icosphere(3, 1.0);
        let tris = m.faces.triangles();
        (m.positions, tris)
    }

    /// Rotation by `angle` about the unit `axis` (Rodrigues).
    fn rotation(axis: Point3, angle: f64) -> Jacobian {
        let (s, c) = angle.sin_cos();
        let [x, y, z] = axis;
        [
            [c + x * x * (1.0 - c), x * y * (1.0 - c) - z * s, x * z * (1.0 - c) + y * s],
            [y * x * (1.0 - c) + z * s, c + y * y * (1.0 - c), y * z * (1.0 - c) - x * s],
            [z * x * (1.0 - c) - y * s, z * y * (1.0 - c) + x * s, c + z * z * (1.0 - c)],
        ]
    }

    fn apply(j: &Jacobian, p: Point3) -> Point3 {
        [dot(j[0], p), dot(j[1], p), dot(j[2], p)]
    }

    /// A rotation turns no face over, however far it turns: 0 counted, while the template's own
    /// normals would flag most faces of a sphere turned by 150°.
    #[test]
    fn a_rotation_by_150_degrees_turns_no_face() {
        let (pos, tris) = sphere();
        let r = rotation(normalize([1.0, 1.0, 0.3]), 150f64.to_radians());
        let turned: Vec<Point3> = pos.iter().map(|&p| apply(&r, p)).collect();
        let mut o = Orientation::new(&pos, &tris);
        // Against the raw template normals (no map pushed), most faces of the turned sphere oppose.
        let raw_count = o.faces_against(&turned, &tris);
        assert!(raw_count > tris.len() / 2, "{raw_count} of {}", tris.len());
        assert_eq!(o.push(&pos, |_, _| r), 0);
        assert_eq!(o.faces_against(&turned, &tris), 0);
        assert_eq!(o.faces_inverted(&tris), 0);
    }

    /// A smooth map that turns space inside out beyond a plane, (x, y, z) ↦ (x, y, z·g(x)) with
    /// g = 1 for x ≤ 0 falling to −1 for x ≥ 0.4 (det J = g, 0 at x = 0.2): the faces beyond
    /// the plane come out inside out and are counted, those before it are not. The surface-based
    /// measure (the mesh's own vertex normals) sees none of them.
    #[test]
    fn a_map_that_turns_a_region_inside_out_counts_its_faces() {
        let (pos, tris) = sphere();
        let g = |x: f64| (std::f64::consts::PI * (x / 0.4).clamp(0.0, 1.0)).cos();
        let dg = |x: f64| {
            if (0.0..=0.4).contains(&x) {
                -std::f64::consts::PI / 0.4 * (std::f64::consts::PI * x / 0.4).sin()
            } else {
                0.0
            }
        };
        let image: Vec<Point3> = pos.iter().map(|p| [p[0], p[1], p[2] * g(p[0])]).collect();
        let mut o = Orientation::new(&pos, &tris);
        let inverted_vertices =
            o.push(&pos, |_, p| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [p[2] * dg(p[0]), 0.0, g(p[0])]]);
        assert_eq!(inverted_vertices, pos.iter().filter(|p| p[0] >= 0.2).count());
        // The truth by position: faces wholly beyond x = 0.2 are inside out, faces wholly before
        // it are not; faces across it may go either way.
        let beyond = tris.iter().filter(|t| t.iter().all(|&v| pos[v as usize][0] > 0.2)).count();
        let touching = tris.iter().filter(|t| t.iter().any(|&v| pos[v as usize][0] > 0.2)).count();
        let counted = o.faces_against(&image, &tris);
        assert!(beyond > 100, "the case: {beyond} faces beyond the plane");
        assert!((beyond..=touching).contains(&counted), "{counted} not in {beyond}..={touching}");
        let inverted = o.faces_inverted(&tris);
        assert!((beyond..=touching).contains(&inverted), "{inverted} not in {beyond}..={touching}");
        // The faces before the plane: none counted.
        let before: Vec<[u32; 3]> =
            tris.iter().copied().filter(|t| t.iter().all(|&v| pos[v as usize][0] < 0.2)).collect();
        assert_eq!(o.faces_against(&image, &before), 0);
        // Against the deformed surface's own normals (the report's measure before): blind to it.
        let own = Orientation::new(&image, &tris);
        let old = own.faces_against(&image, &tris);
        assert!(old * 10 < beyond, "old measure {old}, inside-out faces {beyond}");
    }

    /// Added vertices take their parents' Jacobians and places: a vertex inside a template face
    /// refers to that face's normal, whatever its corners' vertex normals; a rolled-back addition
    /// is dropped.
    #[test]
    fn added_vertices_take_their_parents_maps_and_places() {
        // A thin fin: two faces folded back to 20° from each other on the edge 0-1, their
        // corners' vertex normals nearly along the edge's bisector.
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, 0.94, 0.34]];
        let tris = vec![[0, 1, 2], [1, 0, 3]];
        let mut o = Orientation::new(&pos, &tris);
        o.push(
            &pos,
            |v, _| if v == 1 { [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] } else { IDENTITY },
        );
        let parents = vec![[(0, 0.25), (1, 0.25), (2, 0.5)], [(0, 0.5), (1, 0.5), (0, 0.0)]];
        o.sync(&parents);
        assert_eq!(o.len(), 6);
        assert_eq!(o.places[4], Place::Face(0));
        assert_eq!(o.places[5], Place::Edge(0, 1));
        assert!((o.jacobians[4][0][0] - 1.25).abs() < 1e-12 && (o.jacobians[5][0][0] - 1.5).abs() < 1e-12);
        // Face 0 split at vertex 4: each piece is in face 0 and compared with its normal.
        let mut at = pos.clone();
        at.push([0.5, 0.5, 0.0]);
        at.push([0.5, 0.0, 0.0]);
        let split = [[0, 1, 4], [1, 2, 4], [2, 0, 4]];
        assert_eq!(o.faces_against(&at, &split), 0);
        // The same pieces turned over are all counted.
        let turned: Vec<[u32; 3]> = split.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert_eq!(o.faces_against(&at, &turned), 3);
        o.sync(&parents[..1]);
        assert_eq!(o.len(), 5);
    }

    /// A face with normal `n` at `at` (edge length 1e-3).
    fn face_with_normal(at: Point3, n: Point3) -> [Point3; 3] {
        let n = normalize(n);
        let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let a = normalize(cross(helper, n));
        let b = cross(n, a);
        [at, add(at, scale(a, 1e-3)), add(at, scale(b, 1e-3))]
    }

    /// A field map pushed in single precision ([`Orientation::push_field`]) counts exactly what
    /// the same map pushed in f64 counts, also for faces whose normal is within 1e-10 of
    /// perpendicular to their reference (the bounds leave those open and the count replays them
    /// exactly), and for faces on vertices added between two maps (replayed through their
    /// parents) and after the last (blended).
    #[test]
    fn a_single_precision_field_counts_as_the_exact_one() {
        let (pos, tris) = sphere();
        let centres: Vec<Point3> = pos.iter().step_by(7).copied().collect();
        let values: Vec<Point3> = centres
            .iter()
            .map(|p| [0.3 * p[1] * p[2], 0.2 * (3.0 * p[0]).sin(), -0.25 * p[0] * p[1]])
            .collect();
        let f = Arc::new(Rbf::fit(&centres, &values, crate::fit::rbf::Kernel::Linear, "test").unwrap());
        let progress = Progress::new();
        let (mut exact, mut approx) = (Orientation::new(&pos, &tris), Orientation::new(&pos, &tris));
        exact.push(&pos, |_, p| field_step(&f.gradient(p), 0.5));
        approx.push_field(&pos, f.clone(), 0.5, &progress).unwrap();
        // Midpoints of some edges, added between the two maps, then more after the last.
        let mut parents: Vec<[(u32, f64); 3]> =
            tris.iter().take(40).map(|t| [(t[0], 0.5), (t[1], 0.5), (t[2], 0.0)]).collect();
        exact.sync(&parents);
        approx.sync(&parents);
        let mut at = pos.clone();
        for p in &parents {
            at.push(scale(add(at[p[0].0 as usize], at[p[1].0 as usize]), 0.5));
        }
        exact.push(&at, |_, p| field_step(&f.gradient(p), 1.0));
        approx.push_field(&at, f.clone(), 1.0, &progress).unwrap();
        let nv = at.len() as u32;
        parents.extend((0..10u32).map(|i| [(nv - 1 - i, 0.25), (i, 0.75), (0, 0.0)]));
        exact.sync(&parents);
        approx.sync(&parents);
        let n = exact.len() as u32;
        // Faces on template vertices, on vertices added between the maps, and after them.
        let faces: Vec<[u32; 3]> =
            tris.iter().take(30).copied().chain((0..20).map(|i| [i, nv - 1 - i, n - 1 - i % 10])).collect();
        let (mut open, mut counted) = (0, 0);
        for t in &faces {
            // The exact reference, from the f64 push.
            let normals = exact.corner_normals(t);
            let mut r = [0.0; 3];
            for k in 0..3 {
                r = add(r, push_normal(&exact.jacobians[t[k] as usize], normals[k]));
            }
            let r = normalize(r);
            let side = normalize(cross(r, [0.3, -0.5, 0.8]));
            for sign in [-1.0, 1.0] {
                let mut out = vec![[0.0; 3]; n as usize];
                let corners = face_with_normal([0.1, 0.2, 0.3], add(side, scale(r, sign * 1e-10)));
                for k in 0..3 {
                    out[t[k] as usize] = corners[k];
                }
                let truth = (sign < 0.0) as usize;
                assert_eq!(exact.faces_against(&out, &[*t]), truth, "f64 push, face {t:?}");
                assert_eq!(approx.faces_against(&out, &[*t]), truth, "f32 push, face {t:?}");
                let stored = |v: u32| (approx.jacobians[v as usize], approx.errors[v as usize]);
                open += (approx.decide(&out, t, stored) == Decision::Open) as usize;
                counted += truth;
            }
        }
        assert_eq!(open, 2 * faces.len(), "every such face is open under the single-precision bounds");
        assert_eq!(counted, faces.len());
        // Faces far from perpendicular: decided from the bounds, the same count.
        assert_eq!(approx.faces_against(&pos, &tris), exact.faces_against(&pos, &tris));
        assert_eq!(approx.faces_inverted(&tris), exact.faces_inverted(&tris));
    }

    /// cof(J)·n is the normal of the image of a face with normal n, and det J its volume factor.
    #[test]
    fn the_cofactor_maps_face_normals() {
        let j = [[1.2, -0.3, 0.5], [0.1, 0.9, -0.4], [0.7, 0.2, 1.1]];
        let (a, b) = ([1.0, 0.2, -0.1], [0.3, -0.8, 0.5]);
        let (c, det) = cofactor_times(&j, cross(a, b));
        let image = cross(apply(&j, a), apply(&j, b));
        assert!(norm(crate::geometry::sub(c, image)) < 1e-12);
        let by_hand =
            1.2 * (0.9 * 1.1 + 0.4 * 0.2) + 0.3 * (0.1 * 1.1 + 0.4 * 0.7) + 0.5 * (0.1 * 0.2 - 0.9 * 0.7);
        assert!((det - by_hand).abs() < 1e-12);
    }
}

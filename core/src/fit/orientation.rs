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

use std::sync::Arc;

use rayon::prelude::*;

use crate::error::Result;
use crate::geometry::{add, dot, normalize, scale, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::rbf::Rbf;

mod jacobian;
mod repair;
mod replay;

use jacobian::{cofactor, frobenius, mat_vec};
pub use jacobian::{cofactor_times, mat_mul, push_normal};
pub(super) use jacobian::{det, field_step};
pub use repair::AfterLastMap;
use replay::{Replay, Step};

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
    /// The template's triangles (for "is template vertex v a corner of template face f").
    template_tris: Vec<[u32; 3]>,
    /// Template faces around each template vertex (CSR).
    vf_start: Vec<u32>,
    vf: Vec<u32>,
    /// Vertices with an index below this are the template's; vertex `base + i` has `parents[i]`.
    base: usize,
    replay: Option<Replay>,
    /// Each vertex's index when the maps were pushed (identity until [`Orientation::renumbered`]).
    working: Option<Vec<u32>>,
    /// The repair reference of the working mesh's face ids, and cof(J) per vertex
    /// ([`Orientation::cache_faces`]); cleared by every map pushed.
    face_cache: Vec<Point3>,
    cofactors: Vec<Jacobian>,
    /// Per vertex: the last map pushed (the fine RBF, in the fit) turns space inside out there
    /// ([`Side::LastMap`]).
    last_inverted: Vec<bool>,
}

/// One corner of a face: its pushed-forward normal and how far the Jacobian's error bound `e`
/// could move it (2, the most a unit vector can move, where the sign of det J or the direction is
/// open). Bounds for ‖ΔJ‖_F ≤ e: cof(J)·n = (J·a)×(J·b) for orthonormal a, b with a×b = n, so it
/// moves by at most 2(‖J‖ + e)e; det J, a triple product of columns, by at most 3(‖J‖ + e)²e;
/// and a unit vector c/|c| by at most 2|Δc|/|c|.
fn corner(j: &Jacobian, e: f64, n: Point3, side: Side) -> (Point3, f64) {
    let (c, d) = cofactor_times(j, n);
    let unit = normalize(if d > 0.0 || side == Side::Image { c } else { scale(c, -1.0) });
    if e == 0.0 || dot(n, n) == 0.0 {
        return (unit, 0.0);
    }
    let f = frobenius(j) + e;
    let (dc, dd, len) = (2.0 * f * e, 3.0 * f * f * e, dot(c, c).sqrt());
    let open = !(d.abs() > dd && len > 2.0 * dc);
    (unit, if open { 2.0 } else { 2.0 * dc / len })
}

/// Which way a corner's pushed-forward template normal points where the maps invert space.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// J⁻ᵀ·n: against the image of the template face where det J ≤ 0 (the count: a face the maps
    /// turned inside out is turned over relative to the template).
    Covector,
    /// cof(J)·n: the normal of the template face's image under the maps, whatever det J (the
    /// repair stages: where the maps turned space inside out no local edit can undo it, so the
    /// repair keeps faces consistent with the maps' image there, as the fine-surface normals it
    /// used before did; those faces stay counted, also in `faces_inverted_by_maps`).
    Image,
    /// cof(J)·n, turned where the last map pushed inverts space: the untangling right after the
    /// fine stage undoes the fine map's own (local) inversions, as it did against the surface
    /// before that map until session 15, and follows the earlier maps' image.
    LastMap,
}

/// The side the repair stages take ([`Reference for Orientation`]). The count's side instead
/// (measured, session 15): the cross-template rows of `sweep_unseen` went from 353 to 1,549
/// (rocker-arm on homer's sections) and from 170 to 1,078 (icosphere on homer's) flipped faces,
/// the untanglings chasing every face of the regions the maps turned inside out.
const REPAIR_SIDE: Side = Side::Image;

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
            template_tris: template_tris.to_vec(),
            vf_start,
            vf,
            base: nv,
            replay: None,
            working: None,
            face_cache: Vec::new(),
            cofactors: Vec::new(),
            last_inverted: vec![false; nv],
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
            Place::Vertex(v) => self.template_tris[f as usize].contains(&v),
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
        self.truncate_to(self.base + parents.len());
        for p in &parents[self.jacobians.len() - self.base..] {
            self.push_vertex(p);
        }
    }

    /// Forgets the vertices from `want` on.
    fn truncate_to(&mut self, want: usize) {
        self.cofactors.truncate(want);
        self.last_inverted.truncate(want);
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
    }

    /// One vertex added as the weighted blend `p` of older ones.
    fn push_vertex(&mut self, p: &[(u32, f64); 3]) {
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
        // The last map's inversion at the blend: the parents' weighted vote.
        let vote: f64 = used().map(|&(v, w)| if self.last_inverted[v as usize] { -w } else { w }).sum();
        self.last_inverted.push(vote < 0.0);
        self.jacobians.push(j);
        self.errors.push(e);
        self.places.push(place);
        if let Some(r) = self.replay.as_mut() {
            r.added.push((*p, r.steps.len()));
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
    /// fine RBF of `matching = nearest_vertex` (the approach levels and the inserted fine stage
    /// compute their gradients with the values instead: [`Orientation::push_gradients`]). Keeps
    /// what the count needs to evaluate them again exactly where a face's decision is open.
    /// Returns how many vertices the map inverts by the single-precision values.
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

    /// Composes every vertex's Jacobian with the map x ↦ x + step · field(x) from the field's
    /// gradient at each vertex's position before the map (`gradients[v]`, computed in double
    /// precision with the field's values: [`Rbf::eval_with_gradients`]): exact, no bound. Returns
    /// how many vertices the map inverts.
    pub fn push_gradients(&mut self, before: &[Point3], gradients: &[Jacobian], step: f64) -> usize {
        self.push(&before[..gradients.len().min(before.len())], |v, _| field_step(&gradients[v], step))
    }

    /// Multiplies every vertex's Jacobian by its step on the left; `bound(v)`: the step's error
    /// bound (‖ΔĴ'‖ ≤ b‖Ĵ‖ + (‖Ŝ‖ + b)·e for Ĵ' = Ŝ·Ĵ). Returns the steps with det ≤ 0.
    fn apply(&mut self, steps: &[Jacobian], bound: impl Fn(usize) -> f64 + Sync) -> usize {
        self.face_cache.clear();
        self.cofactors.clear();
        self.last_inverted.resize(self.jacobians.len(), false);
        self.jacobians
            .par_iter_mut()
            .zip(self.errors.par_iter_mut())
            .zip(self.last_inverted.par_iter_mut())
            .zip(steps.par_iter())
            .enumerate()
            .map(|(v, (((j, e), last), s))| {
                let b = bound(v);
                *e = b * frobenius(j) + (frobenius(s) + b) * *e;
                *j = mat_mul(s, j);
                let d = det(s);
                *last = d <= 0.0 || !d.is_finite();
                *last as usize
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

    /// Face `t`'s carried reference: the sum over its corners of the template's normal there
    /// ([`Orientation::corner_normals`]) pushed forward by the corner's Jacobian, each a unit
    /// vector, with each corner's Jacobian and error bound from `jac`; and how far those bounds
    /// could move it. The one definition of a face's reference: the count
    /// ([`Orientation::decide`]) and the repair stages ([`Reference::face`]) both use it.
    fn reference_with(
        &self,
        t: &[u32; 3],
        side: Side,
        jac: impl Fn(u32) -> (Jacobian, f64),
    ) -> (Point3, f64) {
        let normals = self.corner_normals(t);
        let (mut r, mut slack) = ([0.0; 3], 0.0);
        for (k, &v) in t.iter().enumerate() {
            let turned = side == Side::LastMap && self.last_inverted.get(v as usize) == Some(&true);
            let side = if side == Side::LastMap { Side::Image } else { side };
            // The repair sides (stored Jacobians, no bound): from cof(J) kept, the same vector as
            // `corner` gives. Never the count, which needs `jac`'s exact Jacobians and bounds.
            if side == Side::Image {
                if let Some(c) = self.cofactors.get(v as usize) {
                    let c = mat_vec(c, normals[k]);
                    r = add(r, normalize(if turned { scale(c, -1.0) } else { c }));
                    continue;
                }
            }
            let (j, e) = jac(v);
            let (unit, moves) = corner(&j, e, normals[k], side);
            let unit = if turned { scale(unit, -1.0) } else { unit };
            r = add(r, unit);
            slack += moves;
        }
        (r, slack)
    }

    /// A face against its reference ([`Orientation::reference_with`]): open when the bounds
    /// could change the sign.
    fn decide(&self, pos: &[Point3], t: &[u32; 3], jac: impl Fn(u32) -> (Jacobian, f64)) -> Decision {
        let n = normalize(triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]));
        if dot(n, n) == 0.0 {
            // A zero-area face has no normal to oppose anything (counted elsewhere: `degenerate`).
            return Decision::With;
        }
        let (r, slack) = self.reference_with(t, Side::Covector, jac);
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
        self.faces_against_list(pos, tris).len()
    }

    /// The faces [`Orientation::faces_against`] counts, by index into `tris`, ascending.
    pub fn faces_against_list(&self, pos: &[Point3], tris: &[[u32; 3]]) -> Vec<u32> {
        let stored = |v: u32| (self.jacobians[v as usize], self.errors[v as usize]);
        let decided: Vec<Decision> = tris.par_iter().map(|t| self.decide(pos, t, stored)).collect();
        let open: Vec<u32> =
            (0..tris.len() as u32).filter(|&f| decided[f as usize] == Decision::Open).collect();
        let exact = self.exact_at(open.iter().flat_map(|&f| tris[f as usize].iter().copied()));
        (0..tris.len() as u32)
            .filter(|&f| match decided[f as usize] {
                Decision::Against => true,
                Decision::With => false,
                Decision::Open => self.settle_open(pos, &tris[f as usize], &exact),
            })
            .collect()
    }

    /// Whether one face is counted by [`Orientation::faces_against`]: the same decision, face by
    /// face (stored Jacobians, exact ones where the bounds leave it open). For the last repair
    /// ([`super::turned`]), which must judge its edits by the count itself.
    pub fn face_against(&self, pos: &[Point3], t: &[u32; 3]) -> bool {
        let stored = |v: u32| (self.jacobians[v as usize], self.errors[v as usize]);
        match self.decide(pos, t, stored) {
            Decision::Against => true,
            Decision::With => false,
            Decision::Open => self.settle_open(pos, t, &self.exact_at(t.iter().copied())),
        }
    }

    /// A face the stored bounds left open, decided with `exact` Jacobians; still open (without a
    /// replay; none is lost in the fit), the approximate sign decides. Whether it is against.
    fn settle_open(&self, pos: &[Point3], t: &[u32; 3], exact: &impl Fn(u32) -> (Jacobian, f64)) -> bool {
        let d = match self.decide(pos, t, exact) {
            Decision::Open => self.decide(pos, t, |v| (self.jacobians[v as usize], 0.0)),
            d => d,
        };
        d == Decision::Against
    }

    /// The count's reference direction of face `t` (stored Jacobians, no bound): where a face
    /// should point, for the last repair's tangent planes.
    pub fn counted_direction(&self, t: &[u32; 3]) -> Point3 {
        self.reference_with(t, Side::Covector, |v| (self.jacobians[v as usize], 0.0)).0
    }

    /// Whether the composite map turns space inside out (det J ≤ 0, stored Jacobians) at a corner
    /// of face `t`: there the count's reference is reversed against the maps' image.
    pub fn inverted_at_a_corner(&self, t: &[u32; 3]) -> bool {
        t.iter().any(|&v| !(det(&self.jacobians[v as usize]) > 0.0))
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
        self.last_inverted = keep.vec(&self.last_inverted);
        self.face_cache.clear();
        self.cofactors = keep.vec(&self.cofactors);
        self
    }
}

#[cfg(test)]
mod tests;

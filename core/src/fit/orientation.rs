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

use rayon::prelude::*;

use crate::geometry::{add, cross, dot, normalize, scale, triangle_cross};
use crate::mesh::Point3;

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

/// Per working vertex of the fit: the composite Jacobian of every map applied so far, and where
/// on the template the vertex lies.
#[derive(Debug, Clone)]
pub struct Orientation {
    jacobians: Vec<Jacobian>,
    places: Vec<Place>,
    /// The template's unit face normals and area-weighted vertex normals.
    face_normals: Vec<Point3>,
    vertex_normals: Vec<Point3>,
    /// Template faces around each template vertex (CSR).
    vf_start: Vec<u32>,
    vf: Vec<u32>,
    /// Vertices with an index below this are the template's; vertex `base + i` has `parents[i]`.
    base: usize,
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
        self.jacobians.truncate(want);
        self.places.truncate(want);
        for p in &parents[self.jacobians.len() - self.base..] {
            let used = || p.iter().filter(|x| x.1 > 0.0);
            // The composite map is smooth: its Jacobian between two vertices is their blend.
            let mut j = [[0.0; 3]; 3];
            for &(v, w) in used() {
                let jv = &self.jacobians[v as usize];
                for r in 0..3 {
                    for c in 0..3 {
                        j[r][c] += w * jv[r][c];
                    }
                }
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
            self.places.push(place);
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
        self.jacobians[..n]
            .par_iter_mut()
            .enumerate()
            .map(|(v, j)| {
                let step = jacobian(v, before[v]);
                *j = mat_mul(&step, j);
                let d = det(&step);
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

    /// Per face: the template's normal where the face lies, pushed forward by the maps at its
    /// corners, summed. A face whose corners share a template face uses that face's normal at
    /// every corner (no vertex normal, which is ambiguous at a crease or a thin fin: 21 of
    /// suzanne's 968 faces oppose their own corners' vertex normals).
    fn reference(&self, t: &[u32; 3]) -> Point3 {
        let places = t.map(|v| self.places[v as usize]);
        let shared = self.common_faces(places.iter().copied()).and_then(|c| c.first().copied());
        let mut r = [0.0; 3];
        for (k, &v) in t.iter().enumerate() {
            let n = match shared {
                Some(f) => self.face_normals[f as usize],
                None => self.template_normal(places[k]),
            };
            r = add(r, push_normal(&self.jacobians[v as usize], n));
        }
        r
    }

    /// Faces whose normal opposes their reference ([`Orientation::reference`]).
    pub fn faces_against(&self, pos: &[Point3], tris: &[[u32; 3]]) -> usize {
        if std::env::var("FIT_DIAG_FLIPS").is_ok() {
            for t in tris {
                let n = triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
                let r = self.reference(t);
                if dot(n, r) < 0.0 {
                    let places = t.map(|v| self.places[v as usize]);
                    let shared = self.common_faces(places.iter().copied());
                    let per: Vec<(f64, f64)> = t
                        .iter()
                        .enumerate()
                        .map(|(k, &v)| {
                            let nn = match shared.as_ref().and_then(|c| c.first().copied()) {
                                Some(f) => self.face_normals[f as usize],
                                None => self.template_normal(places[k]),
                            };
                            (det(&self.jacobians[v as usize]), dot(normalize(n), push_normal(&self.jacobians[v as usize], nn)))
                        })
                        .collect();
                    eprintln!("DIAGFLIP {t:?} places {places:?} shared {shared:?} area {:.2e} det/dot {per:?}", crate::geometry::norm(n) / 2.0);
                }
            }
        }
        tris.par_iter()
            .filter(|t| {
                let n = triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
                dot(n, self.reference(t)) < 0.0
            })
            .count()
    }

    /// Faces with at least two corners where the composite map turns space inside out (det J ≤ 0).
    pub fn faces_inverted(&self, tris: &[[u32; 3]]) -> usize {
        tris.par_iter()
            .filter(|t| t.iter().filter(|&&v| !(det(&self.jacobians[v as usize]) > 0.0)).count() >= 2)
            .count()
    }

    /// The same, with only the vertices `keep` keeps (a renumbering after removals).
    pub fn renumbered(mut self, keep: &super::compact::Renumber) -> Orientation {
        self.jacobians = keep.vec(&self.jacobians);
        self.places = keep.vec(&self.places);
        self
    }
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

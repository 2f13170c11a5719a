//! Crossings on two sheets of a self-intersecting template.
//!
//! The network build joins two curves that cross in space (within `junction_tolerance`) with a
//! shared vertex, because sampled curves on one surface pass each other by their sag. On a
//! template that passes through itself (a scanned flap folded into the body, a repaired mesh
//! with an overlap), two curves on the two sheets cross in space without meeting on the
//! surface; joining them ties the sheets together and the partition cannot realise the joined
//! segments (measured on the self-intersecting cow fitted to its own sections: 5 inserted
//! crossings, 2 segments "separated", 64 flipped faces; without the joins 100 % and 0 flips).
//!
//! The test, once the template is aligned: the feet of the two crossing segments' ends on the
//! template. On one sheet both segments lie in its tangent plane, so each runs flat to the other's
//! normal (a chord of a curved surface tilts by about its length over twice the radius), and
//! the two normals agree. Two sheets are recognised when the normals under the two segments are
//! more than 120° apart (no sheet turns that far within a segment: a crease that sharp puts a
//! crossing segment's ends on both its sides, and their normals cancel), or more than 90° apart
//! with each segment piercing the other's sheet (tilted over 17.5° to it). On the cow 7 crossings
//! are checked: normals 121°–167° apart, 4 of them piercing at 25°–60°. A crease (one curve along
//! it, one across) or a template that is not yet at the curves (feet far from the segment ends)
//! keeps the join.

use crate::geometry::{add, dist, dot, normalize, scale, sub, triangle_cross};
use crate::mesh::{Faces, Point3};
use crate::spatial::Bvh;

use super::curves::CurveNetwork;
use super::insert::walk::face_components;

/// A foot farther than this × the shorter segment: the template is not at the curves there.
const NEAR: f64 = 0.25;
/// |t · n| above this: the segment pierces the other's sheet (sin 17.5°: a chord of a curved
/// surface tilts by about l / 2R, 0.15 for a segment of 0.3 × the radius).
const PIERCING: f64 = 0.3;

/// n_a · n_b below this (more than 120° apart): two sheets whatever the segments' tilt (a fold
/// back, sheets nearly parallel and facing away: the cow's flap, 151°–167°, tilts 0.1–0.45).
const OPPOSED: f64 = -0.5;

/// The aligned template, for [`Sheets::may_join`].
pub struct Sheets {
    bvh: Bvh,
    normals: Vec<Point3>,
    /// Connected piece of each face (faces sharing a vertex are connected).
    piece: Vec<u32>,
}

impl Sheets {
    pub fn new(pos: &[Point3], tris: &[[u32; 3]]) -> Sheets {
        let normals = tris
            .iter()
            .map(|t| normalize(triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])))
            .collect();
        let piece = face_components(pos.len(), tris);
        Sheets { bvh: Bvh::new(pos, &Faces::from_triangles(tris)), normals, piece }
    }

    /// Whether segments `a` and `b`, which cross in space (or one ends at the other), may be
    /// joined: false only when the template has them on two pieces, or on two sheets that pass
    /// through each other (see the module doc).
    pub fn may_join(&self, a: [Point3; 2], b: [Point3; 2]) -> bool {
        let (la, lb) = (dist(a[0], a[1]), dist(b[0], b[1]));
        // (The longer segment sets the reach here: a segment cut short by a crossing is no
        // reason to think the template is not at the curves.)
        let reach = NEAR * la.max(lb);
        if let (Some(pa), Some(pb)) = (self.segment_piece(a, reach), self.segment_piece(b, reach)) {
            if pa != pb {
                return false;
            }
        }
        let near = NEAR * la.min(lb);
        let (Some(na), Some(nb)) = (self.sheet_normal(a, near), self.sheet_normal(b, near)) else {
            return true;
        };
        let (ta, tb) = (normalize(sub(a[1], a[0])), normalize(sub(b[1], b[0])));
        let facing = dot(na, nb);
        let piercing = dot(ta, nb).abs() > PIERCING && dot(tb, na).abs() > PIERCING;
        let two_sheets = facing < OPPOSED || (facing < 0.0 && piercing);
        !two_sheets
    }

    /// The piece under at least two of segment `s`'s ends and midpoint (feet within `near`), or
    /// None (a segment across the place where two pieces touch, or far from the template).
    fn segment_piece(&self, s: [Point3; 2], near: f64) -> Option<u32> {
        let mid = scale(add(s[0], s[1]), 0.5);
        let under: Vec<u32> = [s[0], mid, s[1]]
            .into_iter()
            .filter_map(|p| self.bvh.closest(p).filter(|c| c.dist2 <= near * near))
            .map(|c| self.piece[c.face as usize])
            .collect();
        under.iter().copied().find(|&p| under.iter().filter(|&&q| q == p).count() >= 2)
    }

    /// The template's normal under segment `s`: the sum of its ends' foot faces' normals, or None
    /// when an end's foot is farther than `near` (or the normals cancel).
    fn sheet_normal(&self, s: [Point3; 2], near: f64) -> Option<Point3> {
        let mut n = [0.0; 3];
        for p in s {
            let c = self.bvh.closest(p)?;
            if c.dist2 > near * near {
                return None;
            }
            n = add(n, self.normals[c.face as usize]);
        }
        let n = normalize(n);
        (dot(n, n) > 0.5).then_some(n)
    }
}

/// The points of `after` at the positions of points `ids` of `before` (the same network built
/// again with fewer joins: every input point keeps its position; a refused crossing point, which
/// only a pair can name, goes to the nearest point).
pub fn renumber_points(before: &CurveNetwork, after: &CurveNetwork, ids: &[u32]) -> Vec<u32> {
    ids.iter()
        .map(|&p| {
            let x = before.points[p as usize];
            (0..after.points.len() as u32)
                .min_by(|&i, &j| {
                    dist(after.points[i as usize], x).total_cmp(&dist(after.points[j as usize], x))
                })
                .unwrap_or(p)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit squares: one in z = 0, one in the plane x = 0.5 (normal +x), crossing it along
    /// the line x = 0.5, z = 0: two sheets passing through each other. The second square spans
    /// z ∈ [−0.5, 0.5], y ∈ [0, 1].
    fn two_sheets() -> (Vec<Point3>, Vec<[u32; 3]>) {
        let pos = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.0, -0.5],
            [0.5, 1.0, -0.5],
            [0.5, 1.0, 0.5],
            [0.5, 0.0, 0.5],
        ];
        (pos, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    }

    #[test]
    fn curves_on_one_sheet_may_join() {
        let (pos, tris) = two_sheets();
        let s = Sheets::new(&pos, &tris);
        // Two segments crossing at (0.3, 0.5, 0) inside the z = 0 square.
        assert!(s.may_join([[0.2, 0.5, 0.0], [0.4, 0.5, 0.0]], [[0.3, 0.4, 0.0], [0.3, 0.6, 0.0]]));
        // On the x = 0.5 square.
        assert!(s.may_join([[0.5, 0.3, 0.2], [0.5, 0.7, 0.2]], [[0.5, 0.5, 0.1], [0.5, 0.5, 0.3]]));
    }

    #[test]
    fn curves_on_sheets_passing_through_each_other_may_not() {
        let (mut pos, tris) = two_sheets();
        // Tip the second sheet by 30° about its line of contact, so that its normal (+x)
        // becomes (cos 30°, 0, −sin 30°): the sheets face away from each other (n₁ · n₂ = −0.5),
        // as the cow's do where it passes through itself.
        for p in &mut pos[4..] {
            let (x, z) = (p[0] - 0.5, p[2]);
            let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
            p[0] = 0.5 + c * x + s * z;
            p[2] = -s * x + c * z;
        }
        let s = Sheets::new(&pos, &tris);
        let n2 = s.normals[2];
        assert!(n2[2] < -0.4, "the second sheet leans to −z: {n2:?}");
        // Segment a along x on the z = 0 sheet, crossing the line x = 0.5; segment b on the
        // second sheet, running across z = 0 at (0.5, 0.5, 0).
        let a = [[0.45, 0.5, 0.0], [0.55, 0.5, 0.0]];
        // (in the second sheet, across y: b pierces the first sheet at 60°, a the second at 60°)
        let d = [s.normals[2][2], 0.0, -s.normals[2][0]];
        let b = [add([0.5, 0.5, 0.0], scale(d, -0.05)), add([0.5, 0.5, 0.0], scale(d, 0.05))];
        assert!(!s.may_join(a, b));
        assert!(!s.may_join(b, a), "symmetric");
        // The same crossing with the template far from the curves (all moved up by 1) is joined.
        let lifted: Vec<Point3> = pos.iter().map(|p| [p[0], p[1], p[2] + 1.0]).collect();
        assert!(Sheets::new(&lifted, &tris).may_join(a, b));
    }

    #[test]
    fn curves_on_two_pieces_that_touch_in_one_plane_may_not_join() {
        // Two unit squares side by side in z = 0, touching along x = 1 but sharing no vertex:
        // two pieces, normals equal (the normal test alone would join them). An end on the
        // right square next to a segment on the left one, and a crossing over the seam.
        let pos = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let tris = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let s = Sheets::new(&pos, &tris);
        let left = [[0.9, 0.3, 0.0], [0.9, 0.7, 0.0]];
        let right_end = [[1.3, 0.5, 0.0], [0.91, 0.5, 0.0]];
        assert!(!s.may_join(right_end, left), "the end's segment lies on the right square");
        assert!(!s.may_join(left, right_end), "symmetric");
        // Both on the left square: joined.
        assert!(s.may_join([[0.5, 0.5, 0.0], [0.89, 0.5, 0.0]], left));
    }

    #[test]
    fn a_crossing_on_a_crease_is_joined() {
        // A valley fold: the floor z = 0 (x ∈ [0, 1]) and a wall x = 1 (z ∈ [0, 1]), one oriented
        // surface (normals +z and −x). Curve a runs across the crease, b along it.
        let pos = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let tris = vec![[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]];
        let s = Sheets::new(&pos, &tris);
        assert!(dot(s.normals[2], [-1.0, 0.0, 0.0]) > 0.99, "the wall faces −x");
        let a = [[0.9, 0.5, 0.0], [1.0, 0.5, 0.1]];
        let b = [[1.0, 0.4, 0.0], [1.0, 0.6, 0.0]];
        assert!(s.may_join(a, b));
        assert!(s.may_join(b, a));
    }

    #[test]
    fn a_fold_back_of_facing_away_sheets_is_not_joined_however_flat() {
        // A flap folded back over the surface: z = 0 facing +z and, 0.001 above, a sheet facing
        // −z. Two flat segments, one on each, crossing (seen from above) with a 0.001 gap: no
        // tilt at all, but the normals are 180° apart.
        let pos = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.001],
            [1.0, 0.0, 0.001],
            [1.0, 1.0, 0.001],
            [0.0, 1.0, 0.001],
        ];
        let tris = vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]];
        let s = Sheets::new(&pos, &tris);
        let a = [[0.45, 0.5, 0.0], [0.55, 0.5, 0.0]];
        let b = [[0.5, 0.45, 0.001], [0.5, 0.55, 0.001]];
        assert!(!s.may_join(a, b));
        // Both on the lower sheet: joined.
        assert!(s.may_join(a, [[0.5, 0.45, 0.0], [0.5, 0.55, 0.0]]));
    }
}

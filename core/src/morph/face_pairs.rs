//! The face-pair walk shared by the spherical and the planar overlay
//! ([`super::metamesh::overlay`], [`super::plane_overlay::overlay`]): which pairs of an A-face and
//! a B-face get intersected, and how their intersection polygons become numbered vertices and
//! triangles. What a corner is and where it lies differ between the sphere and the plane; the
//! walk and the bookkeeping do not, so they live here once.

use std::hash::Hash;

use crate::error::Result;
use crate::hash::IntMap;
use crate::job::Progress;
use crate::mesh::Point3;

use super::correspond::Locator;

/// Calls `pair(fa, fb)` for every A-face `fa` and every B-face `fb` whose intersection can be
/// non-empty, and returns how many pairs only touched (1 or 2 corners). `pair` intersects the two
/// faces and returns the number of corners it found.
///
/// For each A-face the walk starts at the B-face holding the A-face's `centre` and goes breadth
/// first over B's face neighbours (`nbr_b`, `u32::MAX` = none), past a B-face only when its
/// intersection had 3 or more corners: the intersections of one A-face with the B-faces form a
/// connected patch. The start face always expands, since the centre can sit on its edge.
pub(super) fn walk_face_pairs(
    a_tris: &[[u32; 3]],
    nbr_b: &[[u32; 3]],
    loc: &mut Locator,
    progress: &Progress,
    centre: impl Fn([u32; 3]) -> Point3,
    mut pair: impl FnMut(usize, u32) -> usize,
) -> Result<usize> {
    let mut hint = 0u32;
    let (mut queue, mut seen): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    let mut touching = 0;
    for (fa, &ta) in a_tris.iter().enumerate() {
        if fa % 8192 == 0 {
            progress.fraction(fa as f64 / a_tris.len() as f64)?;
        }
        let seed = loc.locate(centre(ta), hint);
        hint = seed;
        queue.clear();
        seen.clear();
        queue.push(seed);
        seen.push(seed);
        let mut qi = 0;
        while qi < queue.len() {
            let fb = queue[qi];
            qi += 1;
            let corners = pair(fa, fb);
            if corners >= 3 || qi == 1 {
                for &g in &nbr_b[fb as usize] {
                    if g != u32::MAX && !seen.contains(&g) {
                        seen.push(g);
                        queue.push(g);
                    }
                }
            }
            if (1..3).contains(&corners) {
                touching += 1;
            }
        }
    }
    Ok(touching)
}

/// The overlay's vertices and triangles as they are found: one vertex per distinct corner label
/// (neighbouring polygons name a shared corner with the same label), each convex polygon fanned
/// from its first corner.
pub(super) struct PolygonFans<L> {
    ids: IntMap<L, u32>,
    pub tris: Vec<[u32; 3]>,
    poly: Vec<u32>,
}

impl<L: Copy + Eq + Hash> PolygonFans<L> {
    pub fn with_capacity(labels: usize) -> Self {
        PolygonFans {
            ids: IntMap::with_capacity_and_hasher(labels, Default::default()),
            tris: Vec::new(),
            poly: Vec::with_capacity(12),
        }
    }

    /// Adds the convex polygon whose corners, in order, are `corners` (labelled by `label`).
    /// `new_vertex` is called once per label never seen before, in corner order, and must add
    /// exactly one vertex: vertex ids count the labels seen so far.
    pub fn add<C>(&mut self, corners: &[C], label: impl Fn(&C) -> L, mut new_vertex: impl FnMut(&C)) {
        self.poly.clear();
        for c in corners {
            let next = self.ids.len() as u32;
            let id = *self.ids.entry(label(c)).or_insert_with(|| {
                new_vertex(c);
                next
            });
            self.poly.push(id);
        }
        let p = &self.poly;
        for k in 1..p.len().saturating_sub(1) {
            self.tris.push([p[0], p[k], p[k + 1]]);
        }
    }
}

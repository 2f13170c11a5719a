//! The single edits of the last repair other than the split ([`super::split`]): flip a
//! non-curve edge of a counted face, or move one of its free corners, each judged by
//! [`super::judge`] on the faces it touches.

use super::*;

/// An accepted flip: the count's fall, the smallest angle of the two new faces, the neighbour
/// across the flipped edge and the new faces.
struct FlipChoice {
    gain: usize,
    min_angle: f64,
    g: u32,
    new: [[u32; 3]; 2],
}

/// Flips the best non-locked edge of counted face `f` whose quad's two new faces lower the count.
/// Returns the count's fall and the new faces.
pub(super) fn try_flip(
    mesh: &mut TriMesh,
    counted: &impl Counted,
    locked: &EdgeSet,
    f: u32,
    stats: &mut TurnedStats,
    attempt: &mut Attempt,
) -> Option<(usize, Vec<u32>)> {
    let t = mesh.tris[f as usize];
    let mut best: Option<FlipChoice> = None;
    for Quad { a, b, c, g, d, .. } in quads(mesh, locked, f) {
        if d == c || mesh.has_edge(c, d) || !replaceable(mesh, [f, g], [[c, a, d], [d, b, c]]) {
            continue;
        }
        let pos = &mesh.pos;
        // The quad's four outer neighbours (normals unchanged by the flip), each with the face of
        // the quad it touches before and after.
        let outer =
            |x: u32, y: u32, own: u32| mesh.across(own, x, y).map(|h| normal(pos, mesh.tris[h as usize]));
        let (nf, ng) = (normal(pos, t), normal(pos, mesh.tris[g as usize]));
        let (n1, n2) = ([c, a, d], [d, b, c]);
        let (m1, m2) = (normal(pos, n1), normal(pos, n2));
        let (oca, obc) = (outer(c, a, f), outer(b, c, f));
        let (oad, odb) = (outer(a, d, g), outer(d, b, g));
        let with = |n: Point3, o: Option<Point3>| o.map(|o| (n, o));
        let before_pairs: Vec<(Point3, Point3)> =
            [Some((nf, ng)), with(nf, oca), with(nf, obc), with(ng, oad), with(ng, odb)]
                .into_iter()
                .flatten()
                .collect();
        let after_pairs: Vec<(Point3, Point3)> =
            [Some((m1, m2)), with(m1, oca), with(m1, oad), with(m2, odb), with(m2, obc)]
                .into_iter()
                .flatten()
                .collect();
        let before = tally(pos, counted, &[t, mesh.tris[g as usize]], &before_pairs);
        let after = tally(pos, counted, &[n1, n2], &after_pairs);
        let verdict = judge(&before, &after, stats.floor_now);
        note(stats, attempt, verdict);
        if verdict != Verdict::Accept {
            continue;
        }
        let gain = before.counted - after.counted;
        if best.as_ref().is_none_or(|b| (gain, after.min_angle) > (b.gain, b.min_angle)) {
            best = Some(FlipChoice { gain, min_angle: after.min_angle, g, new: [n1, n2] });
        }
    }
    let FlipChoice { gain, g, new: [n1, n2], .. } = best?;
    mesh.remove_face(f);
    mesh.remove_face(g);
    let (x, y) = (mesh.add_face(n1).ok()?, mesh.add_face(n2).ok()?);
    Some((gain, vec![x, y]))
}

/// Whether faces `new` can take the place of faces `old` (both live): no directed edge of `new` is
/// held by a live face outside `old`. Checked before the old faces are removed, so that
/// [`TriMesh::add_face`] cannot refuse afterwards and leave the mesh two faces short (a
/// non-manifold neighbourhood can hold a directed edge twice).
fn replaceable(mesh: &TriMesh, old: [u32; 2], new: [[u32; 3]; 2]) -> bool {
    new.iter().all(|t| {
        (0..3).all(|k| {
            let (x, y) = (t[k], t[(k + 1) % 3]);
            mesh.faces_of(x).iter().all(|&h| {
                let s = mesh.tris[h as usize];
                old.contains(&h) || !(0..3).any(|j| s[j] == x && s[(j + 1) % 3] == y)
            })
        })
    })
}

/// Moves one free corner of counted face `f` (towards its ring's mean in the count's tangent
/// plane, else towards its star's kernel centre, halving the step) when the star's count falls.
/// Returns the count's fall and the star's faces.
pub(super) fn try_move(
    mesh: &mut TriMesh,
    counted: &impl Counted,
    fixed: &[bool],
    f: u32,
    stats: &mut TurnedStats,
    attempt: &mut Attempt,
) -> Option<(usize, Vec<u32>)> {
    let t = mesh.tris[f as usize];
    for v in t {
        if fixed.get(v as usize).copied().unwrap_or(true) || mesh.is_boundary_vertex(v) {
            continue;
        }
        let star: Vec<u32> = mesh.faces_of(v).to_vec();
        let star_tris: Vec<[u32; 3]> = star.iter().map(|&g| mesh.tris[g as usize]).collect();
        // Every pair of adjacent faces with one in the star (each pair once).
        let mut pair_ids: Vec<(u32, u32)> = Vec::new();
        for (&g, tg) in star.iter().zip(&star_tris) {
            for k in 0..3 {
                if let Some(h) = mesh.across(g, tg[k], tg[(k + 1) % 3]) {
                    let key = (g.min(h), g.max(h));
                    if !pair_ids.contains(&key) {
                        pair_ids.push(key);
                    }
                }
            }
        }
        let pair_tris: Vec<([u32; 3], [u32; 3])> =
            pair_ids.iter().map(|&(g, h)| (mesh.tris[g as usize], mesh.tris[h as usize])).collect();
        let pairs_at = |pos: &[Point3]| -> Vec<(Point3, Point3)> {
            pair_tris.iter().map(|&(g, h)| (normal(pos, g), normal(pos, h))).collect()
        };
        let before = tally(&mesh.pos, counted, &star_tris, &pairs_at(&mesh.pos));
        let p0 = mesh.pos[v as usize];
        let n = normalize(star_tris.iter().fold([0.0; 3], |s, &g| add(s, normalize(counted.direction(g)))));
        let mut ring: Vec<u32> = Vec::new();
        let mut ring_edges: Vec<(Point3, Point3)> = Vec::new();
        for tg in &star_tris {
            let k = tg.iter().position(|&w| w == v).unwrap_or(0);
            let (x, y) = (tg[(k + 1) % 3], tg[(k + 2) % 3]);
            ring_edges.push((mesh.pos[x as usize], mesh.pos[y as usize]));
            for w in [x, y] {
                if !ring.contains(&w) {
                    ring.push(w);
                }
            }
        }
        let mean = scale(
            ring.iter().fold([0.0; 3], |s, &w| add(s, mesh.pos[w as usize])),
            1.0 / ring.len().max(1) as f64,
        );
        let d = sub(mean, p0);
        let tangential = add(p0, sub(d, scale(n, dot(d, n))));
        let kernel = super::untangle::kernel_centre(&ring_edges, n);
        for target in [Some(tangential), kernel].into_iter().flatten() {
            for s in STEPS {
                let q = add(p0, scale(sub(target, p0), s));
                // Judged in place (no copy of the positions), then put back.
                mesh.pos[v as usize] = q;
                let after = tally(&mesh.pos, counted, &star_tris, &pairs_at(&mesh.pos));
                mesh.pos[v as usize] = p0;
                let verdict = judge(&before, &after, stats.floor_now);
                if verdict == Verdict::Accept {
                    let uv = uvs::record(mesh, v, q);
                    mesh.pos[v as usize] = q;
                    stats.uv_batches.push(uv.into_iter().collect());
                    return Some((before.counted - after.counted, star));
                }
                note(stats, attempt, verdict);
            }
        }
    }
    None
}

//! The morph's `domain` parameter and the repair of damaged inputs for it (issue 6, step 1): a
//! disk with an extra hole, with a fin face on an interior edge (non-manifold) and a stray piece,
//! morphed after `repair: true`; refusals that name what was found; the auto rule on the shared
//! meshes. Truths are computed here: an analytic hemisphere (its area, rim, unit radius),
//! brute-force closest points, the hand-counted hole and rim.

use std::f64::consts::{PI, TAU};

use meshwork_core::error::Error;
use meshwork_core::geometry::{norm, sub, triangle_area};
use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::morph::domain::{measure_loops, rim_rule, Chosen, RIM_DOMINANCE, RIM_SPAN};
use meshwork_core::shapes;
use serde_json::json;

mod morph_support;
use morph_support::{bbox_diag, disk, dist_brute, load, relative_distance_brute};

const RINGS: usize = 10;
const SEG: usize = 24;
/// Centre of the punched hole (on the unit sphere, 45° from the pole) and its radius.
const HOLE_AT: Point3 = [0.70710678118654757, 0.0, 0.70710678118654757];
const HOLE_R: f64 = 0.25;

fn tris_of(m: &Mesh) -> Vec<[u32; 3]> {
    shapes::fan_triangles(&m.faces)
}

fn area(m: &Mesh) -> f64 {
    tris_of(m)
        .iter()
        .map(|t| {
            triangle_area(m.positions[t[0] as usize], m.positions[t[1] as usize], m.positions[t[2] as usize])
        })
        .sum()
}

/// The upper unit hemisphere of `RINGS` rings of `SEG` vertices (the last on the equator is the
/// rim), faces oriented outwards.
fn hemisphere() -> Mesh {
    shapes::hemisphere(RINGS, SEG)
}

fn centroid(m: &Mesh, t: &[u32; 3]) -> Point3 {
    let p = |k: usize| m.positions[t[k] as usize];
    [
        (p(0)[0] + p(1)[0] + p(2)[0]) / 3.0,
        (p(0)[1] + p(1)[1] + p(2)[1]) / 3.0,
        (p(0)[2] + p(1)[2] + p(2)[2]) / 3.0,
    ]
}

/// The hemisphere with the faces whose centroid lies within `HOLE_R` of `HOLE_AT` removed: a
/// second boundary loop, well inside the rim. Returns the mesh and the removed-face count.
fn holed_hemisphere() -> (Mesh, usize) {
    let h = hemisphere();
    let all = tris_of(&h);
    let kept: Vec<[u32; 3]> =
        all.iter().copied().filter(|t| norm(sub(centroid(&h, t), HOLE_AT)) > HOLE_R).collect();
    let removed = all.len() - kept.len();
    (Mesh::from_triangles(h.positions.clone(), &kept), removed)
}

/// The hemisphere with a fin (a third face on an interior edge, its apex off the surface) and a
/// stray triangle far away: one non-manifold edge, two extra components after splitting.
fn finned_hemisphere() -> Mesh {
    let h = hemisphere();
    let mut tris = tris_of(&h);
    let mut pos = h.positions.clone();
    let e = (tris[100][0], tris[100][1]);
    pos.push([0.2, 0.3, 1.6]);
    tris.push([e.0, e.1, (pos.len() - 1) as u32]);
    let s = pos.len() as u32;
    pos.extend([[3.0, 3.0, 3.0], [3.1, 3.0, 3.0], [3.0, 3.1, 3.0]]);
    tris.push([s, s + 1, s + 2]);
    Mesh::from_triangles(pos, &tris)
}

/// z = 0.5·(x² + y²) over the unit disk (a clean disk target of another connectivity).
fn paraboloid(n: usize) -> Mesh {
    let mut m = disk(n);
    for p in &mut m.positions {
        p[2] = 0.5 * (p[0] * p[0] + p[1] * p[1]);
    }
    m
}

fn morph(inputs: Vec<Mesh>, params: serde_json::Value) -> job::Output {
    job::run(JobKind::Morph, inputs, params, &Progress::new()).unwrap_or_else(|e| panic!("morph: {e}"))
}

fn refusal(inputs: Vec<Mesh>, params: serde_json::Value) -> String {
    match job::run(JobKind::Morph, inputs, params, &Progress::new()) {
        Err(Error::Topology(m)) => m,
        Err(other) => panic!("wrong error: {other}"),
        Ok(o) => panic!("accepted: {}", o.report),
    }
}

/// Boundary edges (used by one face) of a triangle mesh.
fn boundary_edges(m: &Mesh) -> Vec<(u32, u32)> {
    let mut c = std::collections::HashMap::new();
    for t in tris_of(m) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *c.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    c.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect()
}

/// The rim's length as a polygon of `SEG` chords of the unit circle.
fn rim_length() -> f64 {
    SEG as f64 * 2.0 * (PI / SEG as f64).sin()
}

/// The end frame in input 0's coordinates is the holed hemisphere with the hole patched: checked
/// against the hemisphere without any code of the morph or the repair.
fn assert_is_patched_hemisphere(frame: &Mesh, damaged: &Mesh) {
    let (ft, dt) = (tris_of(frame), tris_of(damaged));
    let d = bbox_diag(&damaged.positions);
    // Every vertex of the damaged input lies on the frame, and every frame vertex away from the
    // hole lies on the damaged input.
    let mut worst_in = 0.0f64;
    for (v, p) in damaged.positions.iter().enumerate() {
        if dt.iter().any(|t| t.contains(&(v as u32))) {
            worst_in = worst_in.max(dist_brute(*p, &frame.positions, &ft));
        }
    }
    let mut worst_out = 0.0f64;
    let mut in_hole = 0;
    for p in &frame.positions {
        if norm(sub(*p, HOLE_AT)) > HOLE_R + 0.2 {
            worst_out = worst_out.max(dist_brute(*p, &damaged.positions, &dt));
        } else {
            // The patch stays close to the missing spherical cap (its sagitta is < 0.06).
            assert!((norm(*p) - 1.0).abs() < 0.06, "patch vertex {p:?} off the sphere by {}", norm(*p) - 1.0);
            in_hole += 1;
        }
    }
    assert!(worst_in / d < 1e-9 && worst_out / d < 1e-9, "{worst_in} {worst_out}");
    assert!(in_hole > 0);
    // No hole left: the frame's area is the hemisphere's (the flat-ish patch a little smaller
    // than the cap it replaces), and its only boundary is the rim on the equator.
    let (a_frame, a_full) = (area(frame), area(&hemisphere()));
    assert!((a_frame / a_full - 1.0).abs() < 0.01, "area {a_frame} vs hemisphere {a_full}");
    let bnd = boundary_edges(frame);
    assert!(bnd.len() >= SEG);
    for (a, b) in bnd {
        for v in [a, b] {
            let p = frame.positions[v as usize];
            // On the surface (checked above) and at z = 0: on the rim polygon, between its
            // chords' midpoints (radius cos(π/SEG)) and its corners (radius 1).
            let r = p[0].hypot(p[1]);
            assert!(
                p[2].abs() < 1e-9 && r > (PI / SEG as f64).cos() - 1e-9 && r < 1.0 + 1e-9,
                "boundary vertex {p:?} off the rim"
            );
        }
    }
}

#[test]
fn disk_with_an_extra_hole_is_morphed_after_repair_with_domain_disk_and_auto() {
    let (damaged, removed) = holed_hemisphere();
    assert!(removed >= 4, "{removed}");
    let target = paraboloid(12);
    for dom in ["disk", "auto"] {
        let out = morph(
            vec![damaged.clone(), target.clone()],
            json!({"repair": true, "domain": dom, "registration": "none", "frames": 3}),
        );
        let r = &out.report;
        assert_eq!(r["domain"], "planar", "{dom}: {}", r["domain_reason"]);
        eprintln!("domain {dom}: {}", r["domain_reason"]);
        assert_eq!(r["foldovers"], json!([0, 0]));
        assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3, "{r}");
        assert!(r["hausdorff_last_frame"].as_f64().unwrap() <= 1e-3, "{r}");
        // The repair, per input: the hole filled, the rim kept open and named.
        let rep = &r["repair"];
        assert_eq!(rep.as_array().unwrap().len(), 2);
        let s0 = &rep[0]["summary"];
        assert_eq!(s0["holes_filled"], 1, "{s0}");
        assert_eq!(s0["holes_left_open"], 1, "{s0}");
        assert_eq!(s0["outer_boundary_edges"], SEG, "{s0}");
        let outer = &rep[0]["holes"]["outer_boundary"];
        assert!((outer["length"].as_f64().unwrap() - rim_length()).abs() < 1e-9, "{outer}");
        assert_eq!(outer["also_largest_vector_area"], true, "{outer}");
        assert_eq!(rep[0]["holes"]["loops"].as_array().unwrap().len(), 2);
        assert_eq!(rep[0]["holes"]["fill"]["skipped_by_reason"]["kept open"], 1);
        // The vertices in and out add up: the vertices only the removed faces used (counted here)
        // are reported as dropped, the patch's own as added.
        assert_eq!(s0["vertices_in"], damaged.positions.len());
        let used: std::collections::HashSet<u32> = tris_of(&damaged).into_iter().flatten().collect();
        let unused = damaged.positions.len() - used.len();
        assert_eq!(s0["vertices_removed_unreferenced"], unused, "{s0}");
        let added = s0["vertices_added"].as_u64().unwrap() as usize;
        assert_eq!(s0["vertices_out"].as_u64().unwrap() as usize, damaged.positions.len() - unused + added);
        assert_eq!(rep[1]["summary"]["holes_filled"], 0);
        // Independent checks of the end frames.
        assert_is_patched_hemisphere(&out.meshes[0], &damaged);
        let h1 = relative_distance_brute(&target, &out.meshes[1]);
        assert!(h1 < 1e-9, "last frame vs target {h1}");
    }
}

#[test]
fn disk_with_a_fin_and_a_stray_piece_is_repaired_and_morphed() {
    let damaged = finned_hemisphere();
    let target = paraboloid(10);
    let msg = refusal(vec![damaged.clone(), target.clone()], json!({"domain": "disk"}));
    assert!(msg.contains("input 0") && msg.contains("non-manifold edge"), "{msg}");
    for dom in ["disk", "auto"] {
        let out = morph(
            vec![damaged.clone(), target.clone()],
            json!({"repair": true, "domain": dom, "registration": "none", "frames": 3}),
        );
        let r = &out.report;
        assert_eq!(r["domain"], "planar", "{}", r["domain_reason"]);
        assert_eq!(r["foldovers"], json!([0, 0]));
        assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3, "{r}");
        let s = &r["repair"][0]["summary"];
        // The fin's face and the stray triangle come off as two pieces: both counted, with the
        // fin's apex, its two split-off corner copies and the stray triangle's 3 vertices.
        assert_eq!(s["components_removed"], 2, "{s}");
        assert_eq!(s["faces_removed_small_components"], 2, "{s}");
        assert_eq!(s["holes_filled"], 0, "{s}");
        assert_eq!(s["faces_out"], tris_of(&hemisphere()).len(), "{s}");
        assert_eq!(s["vertices_out"], hemisphere().positions.len(), "{s}");
        // The first frame is the clean hemisphere (no fin, no hole).
        let clean = hemisphere();
        let h = relative_distance_brute(&clean, &out.meshes[0]);
        assert!(h < 1e-9, "first frame vs hemisphere {h}");
    }
}

#[test]
fn damaged_disk_without_repair_is_refused_naming_the_boundary_loops() {
    let (damaged, _) = holed_hemisphere();
    for dom in ["auto", "disk", "sphere"] {
        let msg = refusal(vec![damaged.clone(), paraboloid(8)], json!({"domain": dom}));
        assert!(msg.contains("input 0") && msg.contains("genus 0 with 2 boundary loops"), "{dom}: {msg}");
        assert!(msg.contains("repair"), "{dom}: the refusal points to `repair`: {msg}");
    }
}

#[test]
fn domain_sphere_closes_a_disk_and_morphs_it_spherically() {
    let h = hemisphere();
    let target = shapes::icosphere(2, 1.0);
    let out = morph(vec![h.clone(), target], json!({"repair": true, "domain": "sphere", "frames": 3}));
    let r = &out.report;
    assert_eq!(r["domain"], "spherical");
    assert!(r["domain_reason"].as_str().unwrap().contains("domain: sphere"), "{}", r["domain_reason"]);
    assert_eq!(r["foldovers"], json!([0, 0]));
    assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3, "{r}");
    assert!(r["hausdorff_last_frame"].as_f64().unwrap() <= 1e-3, "{r}");
    assert_eq!(r["repair"][0]["summary"]["holes_filled"], 1);
    assert!(r["repair"][0]["holes"]["outer_boundary"].is_null());
    // The first frame is the half ball: closed, the hemisphere plus a flat cap on the rim polygon
    // (area SEG/2·sin(2π/SEG)), nothing below the equator.
    let f = &out.meshes[0];
    assert!(boundary_edges(f).is_empty());
    let cap = SEG as f64 / 2.0 * (TAU / SEG as f64).sin();
    let want = area(&h) + cap;
    assert!((area(f) / want - 1.0).abs() < 1e-6, "area {} vs {want}", area(f));
    assert!(f.positions.iter().all(|p| p[2] > -1e-9));
}

#[test]
fn domain_disk_on_a_closed_mesh_is_refused() {
    let s = shapes::icosphere(2, 1.0);
    let msg = refusal(vec![s.clone(), paraboloid(6)], json!({"domain": "disk"}));
    assert!(
        msg.contains("input 0")
            && msg.contains("domain: disk")
            && msg.contains("genus 0 with 0 boundary loops"),
        "{msg}"
    );
    let msg = refusal(vec![s, paraboloid(6)], json!({"domain": "disk", "repair": true}));
    assert!(
        msg.contains("input 0") && msg.contains("no boundary") && msg.contains("domain: sphere"),
        "{msg}"
    );
    // A disk source with a closed target under auto + repair is no longer refused: it goes to the
    // sphere (auto_with_repair_closes_a_disk_whose_partner_is_closed).
}

#[test]
fn unknown_domain_is_a_params_error() {
    match job::run(
        JobKind::Morph,
        vec![hemisphere(), paraboloid(6)],
        json!({"domain": "torus"}),
        &Progress::new(),
    ) {
        Err(Error::InvalidParams { field, message }) => {
            assert_eq!(field, "domain", "{message}");
            assert!(message.contains("torus") && message.contains("disk"), "{message}");
        }
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("accepted"),
    }
}

/// The auto rule's measurements on analytic shapes (hand-known rims) and on the shared meshes:
/// the scanned bunny (5 holes in its base) must stay a closed surface with holes, the open
/// meshes woody and alligator (one rim each) are disks.
#[test]
fn auto_rule_on_analytic_and_shared_meshes() {
    let (damaged, _) = holed_hemisphere();
    let loops = measure_loops(&damaged);
    assert_eq!(loops.len(), 2);
    assert_eq!(loops[0].edges, SEG);
    assert!((loops[0].length - rim_length()).abs() < 1e-9);
    // Rim bbox 2×2×0 in a 2×2×1 box: span 2√2/3.
    assert!((loops[0].span - 8f64.sqrt() / 3.0).abs() < 1e-9, "{}", loops[0].span);
    assert_eq!(rim_rule(&loops).0, Chosen::Planar);
    // A sphere with two small holes: no rim.
    let s = shapes::icosphere(3, 1.0);
    let mut t = tris_of(&s);
    t.remove(300);
    t.remove(100);
    let holed = Mesh::from_triangles(s.positions.clone(), &t);
    let (c, why) = rim_rule(&measure_loops(&holed));
    assert_eq!(c, Chosen::Spherical, "{why}");
    assert_eq!(rim_rule(&[]).0, Chosen::Spherical);
    for (name, want) in [
        ("stanford-bunny.obj", Chosen::Spherical),
        ("woody.obj", Chosen::Planar),
        ("alligator.obj", Chosen::Planar),
    ] {
        let m = load(name);
        let loops = measure_loops(&m);
        let (c, why) = rim_rule(&loops);
        eprintln!(
            "{name}: {} loops, longest span {:.3}, dominance {:.2} (rule: span ≥ {RIM_SPAN}, ≥ {RIM_DOMINANCE}×) → {c:?}",
            loops.len(),
            loops[0].span,
            loops[0].length / loops.get(1).map_or(0.0, |l| l.length)
        );
        assert_eq!(c, want, "{name}: {why}");
    }
}

/// Feature indices refer to the input files: through the repair (which drops the vertices only the
/// hole's faces used, renumbering the rest) a pair still means the same two points, and they meet.
#[test]
fn feature_indices_survive_the_repair_renumbering() {
    let (damaged, _) = holed_hemisphere();
    let used: std::collections::HashSet<u32> = tris_of(&damaged).into_iter().flatten().collect();
    let first_dropped =
        (0..damaged.positions.len() as u32).find(|v| !used.contains(v)).expect("a dropped vertex");
    // A source vertex numbered after the dropped one (so its index shifts), away from the rim.
    let va = (first_dropped + 1..damaged.positions.len() as u32)
        .find(|v| used.contains(v) && damaged.positions[*v as usize][2] > 0.3)
        .expect("a later vertex");
    let target = paraboloid(10);
    let vb = (0..target.positions.len() as u32)
        .min_by(|&i, &j| {
            let d = |k: u32| target.positions[k as usize][0].hypot(target.positions[k as usize][1] + 0.3);
            d(i).total_cmp(&d(j))
        })
        .unwrap();
    let out = morph(
        vec![damaged.clone(), target.clone()],
        json!({"repair": true, "domain": "disk", "registration": "none", "frames": 3, "features": [[va, vb]]}),
    );
    assert_eq!(out.report["features"]["foldovers"], 0, "{}", out.report["features"]);
    let (m0, m1) = (&out.meshes[0].positions, &out.meshes[1].positions);
    // The metamesh vertex at the source vertex (input 0's coordinates, through the normalising
    // similarity and back: equal up to round-off).
    let pa = damaged.positions[va as usize];
    let k = (0..m0.len()).min_by(|&i, &j| norm(sub(m0[i], pa)).total_cmp(&norm(sub(m0[j], pa)))).unwrap();
    assert!(norm(sub(m0[k], pa)) < 1e-9, "source vertex not in the metamesh");
    let gap = norm(sub(m1[k], target.positions[vb as usize])) / bbox_diag(&target.positions);
    assert!(gap < 1e-3, "feature ({va}, {vb}) ends {gap} apart; {}", out.report["features"]);
}

/// A hole touching the rim at one vertex (a pinch: the two loops share it): the one-triangle hole
/// is filled (with that very triangle, the only way to close three edges), the rim kept, and the
/// first frame is the undamaged hemisphere.
#[test]
fn hole_touching_the_rim_at_a_vertex_is_filled() {
    let h = hemisphere();
    let mut t = tris_of(&h);
    // The last band's triangle [a, d, b] of segment 5: d on the rim, a and b on the ring above.
    let idx = SEG + (RINGS - 2) * 2 * SEG + 2 * 5 + 1;
    let on_rim = t[idx].iter().filter(|&&v| h.positions[v as usize][2].abs() < 1e-12).count();
    assert_eq!(on_rim, 1);
    t.remove(idx);
    let m = Mesh::from_triangles(h.positions.clone(), &t);
    for dom in ["disk", "auto"] {
        let out = morph(vec![m.clone(), paraboloid(8)], json!({"repair": true, "domain": dom, "frames": 3}));
        let r = &out.report;
        assert_eq!(r["domain"], "planar", "{}", r["domain_reason"]);
        let s = &r["repair"][0]["summary"];
        assert_eq!((s["holes_filled"].as_u64(), s["faces_added"].as_u64()), (Some(1), Some(1)), "{s}");
        assert_eq!(s["outer_boundary_edges"], SEG, "{s}");
        let d = relative_distance_brute(&h, &out.meshes[0]);
        assert!(d < 1e-9, "first frame vs hemisphere {d}");
        assert!((area(&out.meshes[0]) / area(&h) - 1.0).abs() < 1e-12);
    }
}

/// The hemisphere cut open along the seam between segments SEG−1 and 0 (the faces of that strip
/// use duplicates of the segment-0 vertices, as an exporter splitting UV seams writes it): the
/// repair's weld merges one duplicate per ring, counted in the summary, and the first frame is the
/// closed-up hemisphere.
#[test]
fn welded_seam_is_counted_and_the_surface_restored() {
    let h = hemisphere();
    let mut pos = h.positions.clone();
    let id = |i: usize, j: usize| (1 + (i - 1) * SEG + j) as u32;
    let first: Vec<u32> = (1..=RINGS).map(|i| id(i, 0)).collect();
    let last: Vec<u32> = (1..=RINGS).map(|i| id(i, SEG - 1)).collect();
    let mut dup = std::collections::HashMap::new();
    let tris: Vec<[u32; 3]> = tris_of(&h)
        .into_iter()
        .map(|t| {
            if !t.iter().any(|v| last.contains(v)) {
                return t;
            }
            t.map(|v| {
                if first.contains(&v) {
                    *dup.entry(v).or_insert_with(|| {
                        pos.push(h.positions[v as usize]);
                        (pos.len() - 1) as u32
                    })
                } else {
                    v
                }
            })
        })
        .collect();
    assert_eq!(dup.len(), RINGS);
    let cut = Mesh::from_triangles(pos, &tris);
    let out = morph(vec![cut.clone(), paraboloid(8)], json!({"repair": true, "frames": 3}));
    let r = &out.report;
    assert_eq!(r["domain"], "planar", "{}", r["domain_reason"]);
    let s = &r["repair"][0]["summary"];
    assert_eq!(s["vertices_in"], h.positions.len() + RINGS, "{s}");
    assert_eq!(s["vertices_merged"], RINGS, "{s}");
    assert_eq!(s["vertices_removed_unreferenced"], RINGS, "{s}");
    assert_eq!(s["vertices_out"], h.positions.len(), "{s}");
    assert_eq!(s["holes_filled"], 0, "{s}");
    let d = relative_distance_brute(&h, &out.meshes[0]);
    assert!(d < 1e-9, "first frame vs hemisphere {d}");
    // The rim is the hemisphere's again: SEG edges on the equator.
    assert!(boundary_edges(&out.meshes[0])
        .iter()
        .all(|&(a, b)| { [a, b].iter().all(|&v| out.meshes[0].positions[v as usize][2].abs() < 1e-9) }));
}

/// A closed surface with one small hole is topologically a disk: without `repair` it takes the
/// planar domain as it is; with `repair: true` the auto rule sees no rim (the hole spans a few % of
/// the diagonal) and closes it for the spherical domain.
#[test]
fn sphere_with_one_small_hole_is_a_disk_as_is_and_a_sphere_after_repair() {
    let s = shapes::icosphere(2, 1.0);
    let mut t = tris_of(&s);
    t.remove(7);
    let holed = Mesh::from_triangles(s.positions.clone(), &t);
    let target = shapes::icosphere(1, 1.0);
    let out = morph(vec![holed.clone(), paraboloid(6)], json!({"frames": 2}));
    assert_eq!(out.report["domain"], "planar", "{}", out.report["domain_reason"]);
    let out = morph(vec![holed, target], json!({"frames": 2, "repair": true}));
    let r = &out.report;
    assert_eq!(r["domain"], "spherical", "{}", r["domain_reason"]);
    assert!(r["domain_reason"].as_str().unwrap().contains("no loop is a rim"), "{}", r["domain_reason"]);
    assert_eq!(r["repair"][0]["summary"]["holes_filled"], 1);
    assert_eq!(r["repair"][0]["summary"]["faces_added"], 1);
    assert_eq!(r["foldovers"], json!([0, 0]));
    // The one-triangle hole is closed by that triangle: the first frame is the icosphere.
    let d = relative_distance_brute(&s, &out.meshes[0]);
    assert!(d < 1e-9, "first frame vs icosphere {d}");
}

#[test]
fn auto_with_repair_closes_a_disk_whose_partner_is_closed() {
    // Input 0 is a disk by the rim rule, input 1 a closed sphere: no disk domain fits both, so the
    // auto rule goes spherical (the hemisphere's rim is closed) instead of refusing input 1.
    let sphere = shapes::icosphere(3, 1.0);
    let o = morph(vec![hemisphere(), sphere.clone()], json!({"frames": 2, "repair": true}));
    assert_eq!(o.report["domain"], "spherical");
    let why = o.report["domain_reason"].as_str().unwrap();
    assert!(why.contains("input 1") && why.contains("closed"), "{why}");
    // The first frame is the closed hemisphere: no boundary edge left.
    assert!(boundary_edges(&o.meshes[0]).is_empty());
    // Without repair the rule is unchanged: input 0 (a disk) decides and the sphere is refused.
    let msg = refusal(vec![hemisphere(), sphere], json!({"frames": 2}));
    assert!(msg.contains("disk"), "{msg}");
}

//! The morph job on the planar domain (disk-like inputs), the pseudo-metamesh, and the frames ZIP,
//! checked against truths computed here: analytic disks, hemispheres and paraboloids, brute-force
//! closest points for the end frames, plane triangle areas of the map (a fold-free map of the
//! disk covers the boundary polygon exactly once), Python's `zipfile`, the Khronos validator.

use meshwork_core::error::Error;
use meshwork_core::geometry::{dot, norm, sub};
use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::morph::planar::{self, PlanarMethod};
use meshwork_core::morph::trimesh::TriMesh;
use meshwork_core::shapes;

mod morph_support;
use morph_support::{bbox_diag, disk, khronos_report, load, max_dist_brute};

fn tris_of(m: &Mesh) -> Vec<[u32; 3]> {
    shapes::fan_triangles(&m.faces)
}

/// Symmetric vertex-sampled Hausdorff distance between two meshes, relative to b's diagonal
/// (brute force; the metamesh faces lie in input faces, so vertices bound it one way, and the
/// input's vertices are metamesh vertices the other way).
fn hausdorff(a: &Mesh, b: &Mesh) -> f64 {
    let (ta, tb) = (tris_of(a), tris_of(b));
    max_dist_brute(&a.positions, &b.positions, &tb).max(max_dist_brute(&b.positions, &a.positions, &ta))
        / bbox_diag(&b.positions)
}

/// z = 0.6·(x² + y²) over the disk (a different grid resolution).
fn paraboloid(n: usize) -> Mesh {
    let mut m = disk(n);
    for p in &mut m.positions {
        p[2] = 0.6 * (p[0] * p[0] + p[1] * p[1]);
    }
    m
}

fn plane_area(plane: &[Point3], tris: &[[u32; 3]]) -> (f64, usize) {
    let mut s = 0.0;
    let mut neg = 0;
    for t in tris {
        let (a, b, c) = (plane[t[0] as usize], plane[t[1] as usize], plane[t[2] as usize]);
        let ar = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        if ar <= 0.0 {
            neg += 1;
        }
        s += ar.abs();
    }
    (s, neg)
}

#[test]
fn elrp_maps_of_the_test_shapes_cover_the_boundary_polygon_once() {
    for (name, m) in
        [("hemisphere", shapes::hemisphere(10, 24)), ("paraboloid", paraboloid(14)), ("disk", disk(12))]
    {
        let (t, _, _) = TriMesh::from_mesh(&m);
        let map = planar::parameterise(&t, PlanarMethod::Elrp).expect("disk map");
        // Independent check of "embedding": all plane triangles positive and their areas summing
        // to the boundary polygon's area (no overlap, no gap).
        let (area, neg) = plane_area(&map.plane, &t.tris);
        let n = map.angles.len();
        let poly: f64 = (0..n)
            .map(|i| {
                let d = if i + 1 < n {
                    map.angles[i + 1] - map.angles[i]
                } else {
                    std::f64::consts::TAU - map.angles[i]
                };
                0.5 * d.sin()
            })
            .sum();
        assert_eq!(neg, 0, "{name}");
        assert!((area - poly).abs() < 1e-9, "{name}: {area} vs polygon {poly}");
        eprintln!(
            "{name}: {} vertices, AD {:.4} SD {:.4} ({})",
            t.pos.len(),
            map.report.angle_distortion,
            map.report.area_distortion,
            map.report.method
        );
    }
}

#[test]
fn disk_to_hemisphere_end_frames_reproduce_both_inputs() {
    let (a, b) = (disk(16), shapes::hemisphere(12, 28));
    let out = job::run(
        JobKind::Morph,
        vec![a.clone(), b.clone()],
        serde_json::json!({"registration": "none", "frames": 5}),
        &Progress::new(),
    )
    .expect("planar morph");
    let r = &out.report;
    assert_eq!(r["domain"], "planar");
    assert_eq!(r["correspondence"], "overlay", "{r}");
    assert_eq!(r["foldovers"], serde_json::json!([0, 0]));
    // Independent brute-force Hausdorff of the end frames (registration none: own coordinates).
    let h0 = hausdorff(&out.meshes[0], &a);
    let h1 = hausdorff(&out.meshes[1], &b);
    eprintln!(
        "disk↔hemisphere: metamesh {} vertices; Hausdorff first {h0:.2e} last {h1:.2e}; AD {} SD {}",
        r["metamesh_vertices"], r["angle_distortion"], r["area_distortion"]
    );
    assert!(h0 <= 1e-3 && h1 <= 1e-3, "{h0} {h1}");
    assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3);
    assert!(r["hausdorff_last_frame"].as_f64().unwrap() <= 1e-3);
    for k in 0..2 {
        assert!(r["angle_distortion"][k].as_f64().unwrap().is_finite());
        assert!(r["area_distortion"][k].as_f64().unwrap().is_finite());
    }
    // The boundary goes to the boundary: the disk's rim (r = 1, z = 0) onto the equator (z = 0).
    let (m0, m1) = (&out.meshes[0].positions, &out.meshes[1].positions);
    let mut rim = 0;
    for (p, q) in m0.iter().zip(m1) {
        if (p[0].hypot(p[1]) - 1.0).abs() < 1e-9 {
            rim += 1;
            assert!(q[2].abs() < 1e-9, "rim vertex goes to z = {}", q[2]);
        }
    }
    assert!(rim >= 64, "{rim}");
}

#[test]
fn default_registration_and_the_paraboloid() {
    let out = job::run(
        JobKind::Morph,
        vec![disk(12), paraboloid(17)],
        serde_json::json!({"frames": 4}),
        &Progress::new(),
    )
    .expect("planar morph");
    let r = &out.report;
    assert_eq!(r["foldovers"], serde_json::json!([0, 0]));
    assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3, "{r}");
    assert!(r["hausdorff_last_frame"].as_f64().unwrap() <= 1e-3, "{r}");
    // A paraboloid over the same disk: the boundary rotation found is a symmetry of the square
    // grid's rim (a multiple of 90°, the rims are congruent up to those).
    let phi = r["features"]["boundary_rotation"][1].as_f64().unwrap();
    eprintln!("disk↔paraboloid: rotation {phi}, AD {} SD {}", r["angle_distortion"], r["area_distortion"]);
}

#[test]
fn pseudo_metamesh_reproduces_the_target_and_approximates_the_source() {
    let (a, b) = (disk(16), shapes::hemisphere(12, 28));
    let run = |c: &str| {
        job::run(
            JobKind::Morph,
            vec![a.clone(), b.clone()],
            serde_json::json!({"registration": "none", "frames": 3, "correspondence": c}),
            &Progress::new(),
        )
        .expect("morph")
    };
    let (ov, ps) = (run("overlay"), run("pseudo"));
    assert_eq!(ps.report["correspondence"], "pseudo");
    let h_first = hausdorff(&ps.meshes[0], &a);
    let h_last = hausdorff(&ps.meshes[1], &b);
    eprintln!(
        "disk↔hemisphere: overlay {} vertices (H first {}, last {}); pseudo {} vertices (H first {h_first:.2e}, last {h_last:.2e}; report {} / {})",
        ov.report["metamesh_vertices"],
        ov.report["hausdorff_first_frame"],
        ov.report["hausdorff_last_frame"],
        ps.report["metamesh_vertices"],
        ps.report["hausdorff_first_frame"],
        ps.report["hausdorff_last_frame"],
    );
    // Target exact (midpoints on target edges), the flat source's samples lie on the disk too.
    assert!(h_last <= 1e-9, "{h_last}");
    assert!(h_first <= 1e-3, "{h_first}");
    // The report samples face centroids too: within a loose bound of the brute-force vertices.
    assert!(ps.report["hausdorff_last_frame"].as_f64().unwrap() <= 1e-9);
}

#[test]
fn feature_pairs_meet_in_the_plane() {
    let (a, b) = (disk(12), shapes::hemisphere(10, 24));
    // The disk's vertex nearest (0.5, 0, 0) with the hemisphere's nearest (0, 0.6, ·), and the
    // disk's nearest (−0.4, −0.4) with the hemisphere's nearest (0.3, −0.5): a rotation plus a warp.
    let near = |m: &Mesh, x: f64, y: f64| -> u32 {
        (0..m.positions.len())
            .min_by(|&i, &j| {
                let d = |k: usize| (m.positions[k][0] - x).hypot(m.positions[k][1] - y);
                d(i).total_cmp(&d(j))
            })
            .unwrap() as u32
    };
    let pairs = [(near(&a, 0.5, 0.0), near(&b, 0.0, 0.6)), (near(&a, -0.4, -0.4), near(&b, 0.3, -0.5))];
    let out = job::run(
        JobKind::Morph,
        vec![a.clone(), b.clone()],
        serde_json::json!({"registration": "none", "frames": 3,
            "features": pairs.iter().map(|&(x, y)| vec![x, y]).collect::<Vec<_>>()}),
        &Progress::new(),
    )
    .expect("morph with features");
    let r = &out.report;
    assert_eq!(r["features"]["rotation_rule"], "features");
    assert_eq!(r["features"]["foldovers"], 0);
    let (m0, m1) = (&out.meshes[0].positions, &out.meshes[1].positions);
    let diag = bbox_diag(&b.positions);
    for &(va, vb) in &pairs {
        let k =
            m0.iter().position(|p| *p == a.positions[va as usize]).expect("source vertex in the metamesh");
        let gap = norm(sub(m1[k], b.positions[vb as usize])) / diag;
        assert!(gap < 1e-3, "feature ({va}, {vb}) ends {gap} apart; {}", r["features"]);
    }
}

#[test]
fn shared_open_meshes_woody_and_alligator() {
    let (a, b) = (load("woody.obj"), load("alligator.obj"));
    let out = job::run(JobKind::Morph, vec![a, b], serde_json::json!({"frames": 3}), &Progress::new())
        .expect("woody ↔ alligator");
    let r = &out.report;
    eprintln!(
        "woody↔alligator: metamesh {} vertices, H first {} last {}, AD {} SD {}, methods {} / {}, {} ms",
        r["metamesh_vertices"],
        r["hausdorff_first_frame"],
        r["hausdorff_last_frame"],
        r["angle_distortion"],
        r["area_distortion"],
        r["per_input"][0]["parameterisation"]["method"],
        r["per_input"][1]["parameterisation"]["method"],
        r["total_ms"]
    );
    assert_eq!(r["domain"], "planar");
    assert_eq!(r["foldovers"], serde_json::json!([0, 0]));
    assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3);
    assert!(r["hausdorff_last_frame"].as_f64().unwrap() <= 1e-3);
}

#[test]
fn neither_disk_nor_sphere_is_refused_with_genus_and_boundary_count() {
    // An annulus (grid with the middle cell removed): genus 0, 2 boundary loops.
    let g = shapes::grid(3, 3, 1.0, false);
    let tris: Vec<[u32; 3]> =
        tris_of(&g).into_iter().enumerate().filter(|(i, _)| *i != 8 && *i != 9).map(|x| x.1).collect();
    let annulus = Mesh::from_triangles(g.positions.clone(), &tris);
    let msg = |e: Error| match e {
        Error::Topology(m) => m,
        other => panic!("wrong error: {other}"),
    };
    let e = job::run(JobKind::Morph, vec![annulus.clone(), disk(4)], serde_json::json!({}), &Progress::new())
        .expect_err("annulus");
    let m = msg(e);
    assert!(m.contains("genus 0 with 2 boundary loops") && m.contains("input 0"), "{m}");
    // A disk source with an annulus or a sphere as target.
    let e = job::run(JobKind::Morph, vec![disk(4), annulus], serde_json::json!({}), &Progress::new())
        .expect_err("disk → annulus");
    let m = msg(e);
    assert!(m.contains("input 1") && m.contains("genus 0 with 2 boundary loops"), "{m}");
    let e = job::run(
        JobKind::Morph,
        vec![disk(4), shapes::icosphere(1, 1.0)],
        serde_json::json!({}),
        &Progress::new(),
    )
    .expect_err("disk → sphere");
    let m = msg(e);
    assert!(m.contains("input 1") && m.contains("genus 0 with 0 boundary loops"), "{m}");
    // A torus with a hole: genus 1, one boundary loop.
    let t = shapes::torus(12, 6, 1.0, 0.3, false);
    let tt: Vec<[u32; 3]> = tris_of(&t).into_iter().skip(1).collect();
    let e = job::run(
        JobKind::Morph,
        vec![Mesh::from_triangles(t.positions.clone(), &tt), disk(4)],
        serde_json::json!({}),
        &Progress::new(),
    )
    .expect_err("holed torus");
    let m = msg(e);
    assert!(m.contains("genus 1 with 1 boundary loops"), "{m}");
}

fn python_zip_listing(zip: &[u8]) -> Option<String> {
    let dir = std::env::temp_dir().join(format!("meshwork-zip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    let f = dir.join("frames.zip");
    std::fs::write(&f, zip).ok()?;
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(
            "import sys, zipfile, zlib\n\
             z = zipfile.ZipFile(sys.argv[1])\n\
             assert z.testzip() is None\n\
             for i in z.infolist():\n\
             \x20   d = z.read(i)\n\
             \x20   assert i.compress_type == 0 and zlib.crc32(d) == i.CRC\n\
             \x20   print(i.filename, len(d), d[:4].hex())\n",
        )
        .arg(&f)
        .output();
    let _ = std::fs::remove_dir_all(&dir);
    match out {
        Ok(o) if o.status.success() => Some(String::from_utf8_lossy(&o.stdout).into_owned()),
        Ok(o) => panic!("python zipfile rejected the archive: {}", String::from_utf8_lossy(&o.stderr)),
        Err(_) => None,
    }
}

#[test]
fn frames_zip_opens_in_python_zipfile() {
    for (fmt, magic) in [("glb", "676c5446"), ("obj", "")] {
        let out = job::run(
            JobKind::Morph,
            vec![disk(6), paraboloid(7)],
            serde_json::json!({"frames": 4, "frames_zip": fmt}),
            &Progress::new(),
        )
        .expect("morph");
        let z = &out.artifacts[0];
        assert_eq!(z.media_type, "application/zip");
        assert_eq!(out.artifacts[1].media_type, "model/gltf-binary");
        let Some(listing) = python_zip_listing(&z.bytes) else {
            eprintln!("\n*** python3 not found: the ZIP was NOT checked against Python's zipfile ***\n");
            return;
        };
        let lines: Vec<&str> = listing.lines().collect();
        assert_eq!(lines.len(), 4, "{listing}");
        for (j, l) in lines.iter().enumerate() {
            let mut it = l.split(' ');
            assert_eq!(it.next().unwrap(), format!("frame_{j:04}.{fmt}"));
            let _len = it.next();
            if !magic.is_empty() {
                assert_eq!(it.next().unwrap(), magic, "GLB magic");
            }
        }
    }
    // The spherical path writes the same ZIP.
    let out = job::run(
        JobKind::Morph,
        vec![shapes::icosphere(1, 1.0), shapes::icosphere(2, 1.0)],
        serde_json::json!({"frames": 2, "frames_zip": "obj"}),
        &Progress::new(),
    )
    .expect("spherical morph");
    assert_eq!(out.artifacts[0].media_type, "application/zip");
    if let Some(l) = python_zip_listing(&out.artifacts[0].bytes) {
        assert_eq!(l.lines().count(), 2, "{l}");
    }
}

#[test]
fn planar_and_pseudo_glbs_pass_the_khronos_validator() {
    if std::env::var("MESHWORK_SKIP_VALIDATOR").as_deref() == Ok("1") {
        eprintln!("\n*** MESHWORK_SKIP_VALIDATOR=1: the planar morph GLB validator test was SKIPPED ***\n");
        return;
    }
    let dir = std::env::temp_dir().join(format!("meshwork-planar-glb-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let cases = [
        ("planar", vec![disk(8), shapes::hemisphere(6, 16)], serde_json::json!({"frames": 6})),
        (
            "sphere-pseudo",
            vec![shapes::icosphere(2, 1.0), shapes::icosphere(1, 1.0)],
            serde_json::json!({"frames": 6, "correspondence": "pseudo"}),
        ),
    ];
    for (name, inputs, params) in cases {
        let out = job::run(JobKind::Morph, inputs, params, &Progress::new()).expect("morph");
        let file = dir.join(format!("{name}.glb"));
        std::fs::write(&file, &out.artifacts[0].bytes).expect("save");
        let report = khronos_report(&file);
        assert_eq!(report["numErrors"], 0, "{name}: {report}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sphere_pseudo_metamesh_reports_both_end_frames() {
    let a = shapes::icosphere(3, 1.0);
    let mut b = shapes::icosphere(2, 1.0);
    for p in &mut b.positions {
        *p = [p[0] * 1.4, p[1], p[2] * 0.8];
    }
    let out = job::run(
        JobKind::Morph,
        vec![a.clone(), b.clone()],
        serde_json::json!({"registration": "none", "frames": 2, "correspondence": "pseudo"}),
        &Progress::new(),
    )
    .expect("pseudo");
    let r = &out.report;
    let h_last = hausdorff(&out.meshes[1], &b);
    let h_first = hausdorff(&out.meshes[0], &a);
    eprintln!(
        "sphere↔ellipsoid pseudo: {} vertices (inputs {} + {}), H first {h_first:.2e} (report {}), last {h_last:.2e} (report {})",
        r["metamesh_vertices"],
        a.positions.len(),
        b.positions.len(),
        r["hausdorff_first_frame"],
        r["hausdorff_last_frame"]
    );
    assert!(h_last <= 1e-9, "{h_last}");
    assert!(r["pseudo_metamesh"][0]["vertices"].as_u64().unwrap() > 0);
    // The first frame samples the finer sphere at the metamesh vertices: close, not exact.
    assert!(h_first < 0.05, "{h_first}");
    let _ = dot;
}

#[test]
fn three_disks_chain_through_the_common_rim() {
    let inputs = vec![disk(10), shapes::hemisphere(8, 20), paraboloid(13)];
    let out = job::run(
        JobKind::Morph,
        inputs.clone(),
        serde_json::json!({"registration": "none", "frames": 5, "planar_method": "tutte"}),
        &Progress::new(),
    )
    .expect("three-way planar morph");
    let r = &out.report;
    assert_eq!(r["correspondence"], "overlay", "{}", r["correspondence_fallback"]);
    assert_eq!(r["foldovers"], serde_json::json!([0, 0, 0]));
    assert_eq!(r["per_input"][1]["parameterisation"]["method"], "tutte");
    assert_eq!(out.meshes.len(), 3);
    for k in 0..3 {
        let h = hausdorff(&out.meshes[k], &inputs[k]);
        assert!(h <= 1e-3, "input {k}: {h}");
    }
}

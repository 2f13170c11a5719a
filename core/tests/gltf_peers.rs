//! Files written by another program (Blender 3.4's glTF exporter), read and compared with the
//! numbers Blender itself computed for the same scene (core/tests/gltf_fixtures/make_blender.py):
//! world-space points, triangle counts, areas, signed volumes and area-weighted normals per mesh.
//! This checks node transforms (rotation, non-uniform scale, a mirror), winding, groups and
//! normals against an independent implementation.

use std::collections::BTreeMap;
use std::path::Path;

use meshwork_core::io::gltf::read;
use meshwork_core::io::ReadOptions;
use meshwork_core::Mesh;

fn fixture(name: &str) -> Vec<u8> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf_fixtures").join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Per group base name (`Icosphere/0` and `/1` together): triangles, area, signed volume, Σ n·A.
fn measures(m: &Mesh) -> BTreeMap<String, (usize, f64, f64, [f64; 3])> {
    let mut out: BTreeMap<String, (usize, f64, f64, [f64; 3])> = BTreeMap::new();
    for (i, f) in m.faces.iter().enumerate() {
        let name = m.group_name(m.faces.group(i)).split('/').next().unwrap().to_owned();
        let [a, b, c] = [f[0], f[1], f[2]].map(|v| m.positions[v as usize]);
        let cr = cross(sub(b, a), sub(c, a));
        let e = out.entry(name).or_default();
        e.0 += 1;
        e.1 += dot(cr, cr).sqrt() / 2.0;
        e.2 += dot(a, cross(b, c)) / 6.0;
        for k in 0..3 {
            e.3[k] += cr[k] / 2.0;
        }
    }
    out
}

#[test]
fn blender_scene_matches_blenders_own_numbers() {
    let expected: serde_json::Value =
        serde_json::from_slice(&fixture("blender-scene.expected.json")).unwrap();
    let points: Vec<[f64; 3]> = expected["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [0, 1, 2].map(|k| p[k].as_f64().unwrap()))
        .collect();
    for file in ["blender-scene.glb", "blender-scene.gltf"] {
        let l = read(&fixture(file), &ReadOptions::default()).unwrap();
        let m = &l.mesh;
        let mut groups = m.groups.clone();
        groups.sort();
        assert_eq!(groups, ["Cube", "Icosphere/0", "Icosphere/1", "Plane"], "{file}");

        // Every vertex read is one of Blender's world-space vertices (Blender splits vertices at
        // UV seams and sharp edges on export, so several of ours may match one of its).
        for (i, p) in m.positions.iter().enumerate() {
            let nearest =
                points.iter().map(|q| dot(sub(*p, *q), sub(*p, *q)).sqrt()).fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-5, "{file}: vertex {i} {p:?} is {nearest} away from every Blender vertex");
        }
        for q in &points {
            assert!(
                m.positions.iter().any(|p| dot(sub(*p, *q), sub(*p, *q)) < 1e-10),
                "{file}: {q:?} missing"
            );
        }

        let got = measures(m);
        for (name, e) in expected["objects"].as_object().unwrap() {
            let (tris, area, vol, nsum) = got[name];
            assert_eq!(tris as u64, e["triangles"].as_u64().unwrap(), "{file} {name}");
            let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1.0);
            assert!(
                rel(area, e["area"].as_f64().unwrap()) < 1e-5,
                "{file} {name}: area {area} vs {}",
                e["area"]
            );
            // Signed volume: positive and equal means every triangle kept its outward winding
            // through the mirror and the sheared parent transform.
            assert!(
                rel(vol, e["volume"].as_f64().unwrap()) < 1e-5,
                "{file} {name}: volume {vol} vs {}",
                e["volume"]
            );
            for k in 0..3 {
                let want = e["normal_area_sum"][k].as_f64().unwrap();
                assert!(
                    (nsum[k] - want).abs() < 1e-5,
                    "{file} {name}: Σ n·A {nsum:?} vs {}",
                    e["normal_area_sum"]
                );
            }
        }

        // Normals went through the same transforms: the mirrored plane faces +y in glTF space.
        let normals = m.normals.as_ref().expect("every Blender primitive has NORMAL");
        let plane = m.groups.iter().position(|g| g == "Plane").unwrap() as u32;
        for (i, f) in m.faces.iter().enumerate().filter(|(i, _)| m.faces.group(*i) == plane) {
            for &v in f {
                let n = normals[v as usize];
                assert!((n[1] - 1.0).abs() < 1e-6, "{file}: face {i} vertex {v} normal {n:?}");
            }
        }
        assert!(m.uvs.is_some());
    }
}

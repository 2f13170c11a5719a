//! Validation reports of the shared real meshes against the counts in ../shared/meshes/README.md
//! (made by other people with other tools), and against counts derived here from the raw files.

mod shared_meshes;

use meshwork_core::io::{self, ReadOptions};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::validate::{analyze, Report};

fn report(name: &str) -> Option<Report> {
    shared_meshes::load(name).map(|m| analyze(&m))
}

#[test]
fn bunny_five_holes_one_component() {
    let Some(r) = report("stanford-bunny.obj") else { return };
    assert_eq!(r.faces, 69_451);
    // README counts 34,834 vertices: the file has 35,947 `v` lines, 1,113 of them unused.
    assert_eq!(r.vertices - r.unreferenced_vertices, 34_834);
    assert_eq!(r.boundary_loops, 5);
    assert_eq!(r.components, 1);
    assert!(!r.closed);
    assert_eq!(r.genus, None);
    assert_eq!(r.non_manifold_edges, 0);
    // One sphere with 5 holes: χ = 2 − 5.
    assert_eq!(r.euler_characteristic, -3);
}

#[test]
fn closed_genus_zero_and_one() {
    for (name, genus) in [("fandisk.obj", 0), ("homer.obj", 0), ("rocker-arm.obj", 1)] {
        let Some(r) = report(name) else { return };
        assert!(r.closed && r.manifold, "{name}");
        assert_eq!(r.genus, Some(genus), "{name}");
        assert_eq!(r.euler_characteristic, 2 - 2 * genus, "{name}");
        assert_eq!(r.inconsistent_orientation, 0, "{name}");
        assert!(r.volume.unwrap() > 0.0, "{name}: outward");
    }
}

#[test]
fn cow_odd_euler_is_a_non_manifold_vertex() {
    let Some(r) = report("cow.obj") else { return };
    assert!(r.closed);
    assert_eq!(r.euler_characteristic % 2, 1, "odd χ is impossible for a closed manifold");
    assert_eq!(r.non_manifold_vertices, 1);
    assert_eq!(r.non_manifold_edges, 0);
    assert!(!r.manifold);
    assert_eq!(r.genus, None);
}

/// Suzanne as polygons has 3 parts (head, two eyes) and no edge with > 2 faces. The README's
/// "1 non-manifold edge" appears once quads are fan-triangulated: two quads share the diagonal
/// 71–139 (1-based in the file), which becomes an edge with 4 triangles. (The README's "4
/// components" we do not reproduce: trimesh also reports 3 bodies.)
#[test]
fn suzanne_polygons_and_triangulated() {
    let Some(m) = shared_meshes::load("suzanne.obj") else { return };
    let r = analyze(&m);
    assert_eq!(r.faces, 500);
    assert_eq!(r.face_arity.get("4"), Some(&468));
    assert_eq!(r.face_arity.get("3"), Some(&32));
    assert_eq!(r.components, 3);
    assert_eq!(r.non_manifold_edges, 0);
    // The naive fan from every face's first corner (built here by hand) cuts both quads along
    // their shared diagonal: that edge then has 4 triangles (the README's count).
    let naive: Vec<[u32; 3]> =
        m.faces.iter().flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]])).collect();
    let t = analyze(&Mesh::from_triangles(m.positions.clone(), &naive));
    assert_eq!(t.non_manifold_edges, 1);
    assert_eq!(t.examples.non_manifold_edges, vec![[70, 138]]);
    // Meshwork's triangulation (used by every writer and job that needs triangles) cuts the second
    // quad along its other diagonal and keeps the mesh manifold.
    let ours = analyze(&Mesh::from_triangles(m.positions.clone(), &m.faces.triangles()));
    assert_eq!(ours.non_manifold_edges, 0);
    assert_eq!(ours.faces, naive.len());
    // The same through a triangles-only format: written as GLB and as STL, read back.
    for fmt in [meshwork_core::io::Format::Glb, meshwork_core::io::Format::Stl] {
        let bytes = meshwork_core::io::write(&m, fmt).expect("writes");
        let back = meshwork_core::io::read(&bytes, &Default::default()).expect("reads back").mesh;
        assert_eq!(analyze(&back).non_manifold_edges, 0, "{fmt:?}");
    }
}

/// Teapot as read: an unwelded soup. Its parts touch only at vertices until welded.
#[test]
fn teapot_soup() {
    let Some(r) = report("teapot.obj") else { return };
    assert_eq!((r.vertices, r.faces), (3_644, 6_320));
    assert!(!r.closed);
    assert_eq!(r.components_by_vertex, 4);
    assert!(r.components > 4);
}

/// Spot split along its texture seams the way a UV-keeping reader does: one vertex per distinct
/// (position, uv) pair of the file's `f v/vt` corners, built here from the raw text.
pub fn spot_uv_split(bytes: &[u8]) -> Mesh {
    let text = std::str::from_utf8(bytes).unwrap();
    let mut pos = Vec::new();
    let mut faces = Faces::new();
    let mut ids = std::collections::HashMap::new();
    let mut out_pos = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).map(|x| x.parse().unwrap()).collect();
                pos.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = it
                    .map(|c| {
                        let mut p = c.split('/');
                        let v: usize = p.next().unwrap().parse().unwrap();
                        let t: usize = p.next().unwrap().parse().unwrap();
                        *ids.entry((v, t)).or_insert_with(|| {
                            out_pos.push(pos[v - 1]);
                            out_pos.len() as u32 - 1
                        })
                    })
                    .collect();
                faces.push(&f, 0);
            }
            _ => {}
        }
    }
    Mesh::new(out_pos, faces)
}

#[test]
fn spot_thirteen_pieces_until_welded() {
    let Some(bytes) = shared_meshes::bytes("spot.obj") else { return };
    let split = spot_uv_split(&bytes);
    let r = analyze(&split);
    assert_eq!(r.vertices, 3_225);
    assert_eq!(r.components, 13);
    assert_eq!(r.boundary_edges, 576);
    // As read (positions indexed as in the file): one closed genus-0 surface.
    let r = analyze(&io::read(&bytes, &ReadOptions::default()).unwrap().mesh);
    assert!(r.closed && r.manifold);
    assert_eq!((r.components, r.genus), (1, Some(0)));
}

#[test]
fn open_meshes() {
    for name in ["woody.obj", "alligator.obj"] {
        let Some(r) = report(name) else { return };
        assert_eq!(r.components, 1, "{name}");
        assert!(!r.closed, "{name}");
    }
}

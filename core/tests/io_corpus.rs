//! The corpus of broken files (core/tests/corpus/, written by make_corpus.py there) and a
//! fuzz-style sweep: truncating and corrupting valid files must give errors, never panics, and
//! whatever a reader accepts must satisfy the mesh invariants.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use meshwork_core::error::{Error, Location};
use meshwork_core::io::{self, Format, ReadOptions};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::shapes;

fn location_of(e: &Error) -> Option<&Location> {
    match e {
        Error::Malformed { location, .. }
        | Error::InvalidMesh { location, .. }
        | Error::ExternalReference { location, .. } => Some(location),
        _ => None,
    }
}

fn parse_expected_location(s: &str) -> Option<Location> {
    if let Some(n) = s.strip_prefix("line-") {
        return Some(Location::Line(n.parse().unwrap()));
    }
    if let Some(n) = s.strip_prefix("byte-") {
        return Some(Location::Byte(n.parse().unwrap()));
    }
    assert_eq!(s, "none", "corpus file names end in .line-N, .byte-N or .none");
    None
}

#[test]
fn every_corpus_file_gives_its_error_kind_and_location() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let mut checked = 0;
    let mut failures = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let parts: Vec<&str> = name.split('.').collect();
        if parts.len() != 4 {
            continue; // make_corpus.py
        }
        let (kind, loc) = (parts[1], parse_expected_location(parts[2]));
        let bytes = std::fs::read(&path).unwrap();
        let opts = ReadOptions { name_hint: Some(name.clone()), ..Default::default() };
        let got = catch_unwind(|| io::read(&bytes, &opts));
        checked += 1;
        match got {
            Err(_) => failures.push(format!("{name}: PANIC")),
            Ok(Ok(_)) => failures.push(format!("{name}: read without error")),
            Ok(Err(e)) => {
                if e.kind() != kind || location_of(&e) != loc.as_ref() {
                    failures.push(format!("{name}: got {} at {:?}: {e}", e.kind(), location_of(&e)));
                }
            }
        }
    }
    assert!(checked >= 45, "corpus has only {checked} files");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Small valid files in every format and variant we read.
fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
    let mut m = shapes::icosphere(1, 1.0);
    m.normals = Some(m.positions.clone());
    m.uvs = Some(m.positions.iter().map(|p| [p[0], p[1]]).collect());
    let mut g = shapes::grid(3, 2, 0.5, true);
    let mut faces = Faces::new();
    for (i, f) in g.faces.iter().enumerate() {
        faces.push(f, (i % 2) as u32);
    }
    g.faces = faces;
    g.groups = vec!["a".into(), "b".into()];
    g.curves = vec![vec![0, 1, 2]];
    let w = |m: &Mesh, f| io::write(m, f).unwrap();
    vec![
        ("obj", w(&m, Format::Obj)),
        ("obj", w(&g, Format::Obj)),
        ("obj", b"v 1 2 3\nv 4 5 6\nv 7 8 9\nvt 0 0\nvn 0 0 1\nf -3/1/1 -2/1/1 -1/1/1\nl 1 2\n".to_vec()),
        ("ply", w(&m, Format::Ply)),
        ("ply", w(&g, Format::Ply)),
        (
            "ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n\
              element face 1\nproperty list uchar uint vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
                .to_vec(),
        ),
        ("stl", w(&m, Format::Stl)),
        (
            "stl",
            b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n\
              endsolid s\n"
                .to_vec(),
        ),
        ("off", w(&m, Format::Off)),
        ("off", w(&g, Format::Off)),
    ]
}

/// Reads `bytes` as `ext`; a panic fails the test, an accepted mesh must pass `Mesh::check`.
fn must_not_panic(ext: &str, bytes: &[u8], what: &str) {
    let opts = ReadOptions { name_hint: Some(format!("f.{ext}")), ..Default::default() };
    match catch_unwind(AssertUnwindSafe(|| io::read(bytes, &opts))) {
        Err(_) => panic!("{ext}: reader panicked on {what}"),
        Ok(Ok(l)) => {
            if let Err(e) = l.mesh.check() {
                panic!("{ext}: accepted {what} but the mesh breaks an invariant: {e}");
            }
        }
        Ok(Err(_)) => {}
    }
}

#[test]
fn truncating_and_corrupting_never_panics() {
    let prev = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {})); // the sweep reports panics itself
    let result = catch_unwind(|| {
        for (ext, bytes) in valid_files() {
            // Every length for small files, ~1500 evenly spread lengths for larger ones.
            let step = (bytes.len() / 1500).max(1);
            for cut in (0..bytes.len()).step_by(step) {
                must_not_panic(ext, &bytes[..cut], &format!("truncation at {cut}"));
            }
            let mut buf = bytes.clone();
            for pos in (0..bytes.len()).step_by(step) {
                for v in [0x00, 0xFF, b'-', b'9', b'\n', b' ', b'/', bytes[pos] ^ 0x10] {
                    buf[pos] = v;
                    must_not_panic(ext, &buf, &format!("byte {pos} set to {v:#04x}"));
                }
                buf[pos] = bytes[pos];
            }
        }
    });
    std::panic::set_hook(prev);
    if let Err(e) = result {
        std::panic::resume_unwind(e);
    }
}

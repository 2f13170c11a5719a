//! Format benchmark: builds a ≥ 1M-vertex mesh by midpoint-subdividing a real scan, writes it as
//! OBJ, GLB, PLY and STL, then times reading each (file read included, as a peer's `load` does),
//! `validate` on the OBJ, and writing. Prints `file<TAB>operation<TAB>meshwork<TAB>ms` lines (best
//! of `--reps`), the same shape as bench/io_peers.py, so bench/io.sh can put ratios side by side.
//!
//! usage: bench_io [MESH.obj] [--levels N] [--out DIR] [--reps N]
//! (defaults: ../shared/meshes/stanford-bunny.obj, 3 levels ≈ 2.2M vertices, /tmp/meshwork-bench-io, 3)

mod bench_support;
use bench_support::best;

use std::path::PathBuf;

use meshwork_core::io::{self, Format, ReadOptions};
use meshwork_core::{shapes, validate, Mesh};

struct Args {
    mesh: PathBuf,
    levels: u32,
    out: PathBuf,
    reps: usize,
}

fn args() -> Args {
    let mut a = Args {
        mesh: PathBuf::from("../shared/meshes/stanford-bunny.obj"),
        levels: 3,
        out: PathBuf::from("/tmp/meshwork-bench-io"),
        reps: 3,
    };
    let mut it = std::env::args().skip(1);
    while let Some(s) = it.next() {
        let mut val = || it.next().expect("flag needs a value");
        match s.as_str() {
            "--levels" => a.levels = val().parse().expect("--levels N"),
            "--out" => a.out = PathBuf::from(val()),
            "--reps" => a.reps = val().parse().expect("--reps N"),
            _ => a.mesh = PathBuf::from(s),
        }
    }
    a
}

fn report(file: &str, op: &str, ms: f64) {
    println!("{file}\t{op}\tmeshwork\t{ms:.1}");
}

fn load(path: &PathBuf) -> Mesh {
    let bytes = std::fs::read(path).expect("readable file");
    let opts = ReadOptions { name_hint: Some(path.to_string_lossy().into_owned()), ..Default::default() };
    io::read(&bytes, &opts).expect("valid mesh").mesh
}

fn main() {
    let a = args();
    std::fs::create_dir_all(&a.out).expect("output folder");
    let base = load(&a.mesh);
    let big = shapes::subdivide_midpoint(&base, a.levels);
    eprintln!(
        "# {} subdivided {}x: {} vertices, {} triangles; rayon threads: {}",
        a.mesh.display(),
        a.levels,
        big.vertex_count(),
        big.face_count(),
        rayon::current_num_threads()
    );
    for fmt in [Format::Obj, Format::Glb, Format::Ply, Format::Stl] {
        let name = format!("big.{}", fmt.extension());
        let path = a.out.join(&name);
        // Encoding and writing the file, as a peer's `export(path)` does.
        let (ms, len) = best(a.reps, || {
            let bytes = io::write(&big, fmt).expect("writable");
            std::fs::write(&path, &bytes).expect("write file");
            bytes.len()
        });
        report(&name, &format!("write_{}", fmt.extension()), ms);
        eprintln!("# wrote {} ({:.1} MB)", path.display(), len as f64 / 1e6);
    }
    for fmt in [Format::Obj, Format::Glb, Format::Ply, Format::Stl] {
        let name = format!("big.{}", fmt.extension());
        let path = a.out.join(&name);
        let (t_load, m) = best(a.reps, || load(&path));
        report(&name, "load", t_load);
        let (t_val, rep) = best(a.reps, || validate::analyze(&m));
        report(&name, "validate", t_val);
        report(&name, "load+validate", t_load + t_val);
        eprintln!("# {name}: {} vertices, {} faces, closed={}", m.vertex_count(), m.face_count(), rep.closed);
        if fmt == Format::Obj {
            let out = a.out.join("from_obj.glb");
            let (ms, _) =
                best(a.reps, || std::fs::write(&out, io::write(&m, Format::Glb).expect("writable")));
            report(&name, "write_glb", ms);
        }
    }
}

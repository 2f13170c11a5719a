//! GLB read/write benchmark on a 2.6M-vertex icosphere (5.2M triangles). Writes the file it reads
//! to `OUT/big-sphere.glb` so trimesh can load the very same bytes:
//!
//! ```text
//! CARGO_TARGET_DIR=/work/target-release cargo build --release -p meshwork-core --example bench_gltf
//! /work/target-release/release/examples/bench_gltf [OUT_DIR] [REPS]
//! ~/.cache/meshwork-peers/bin/python bench/io_peers.py OUT_DIR/big-sphere.glb
//! ```
//! Prints `file<TAB>operation<TAB>meshwork<TAB>ms` (best of REPS), the shape bench/io_peers.py prints.

mod bench_support;
use bench_support::best;

use meshwork_core::io::gltf;
use meshwork_core::shapes;

fn main() {
    let mut args = std::env::args().skip(1);
    let out = std::path::PathBuf::from(args.next().unwrap_or_else(|| "/tmp/meshwork-bench-gltf".into()));
    let reps: usize = args.next().map(|r| r.parse().expect("REPS is a number")).unwrap_or(3);
    std::fs::create_dir_all(&out).expect("output folder");
    let mesh = shapes::subdivide_midpoint(&shapes::icosphere(8, 1.0), 1);
    eprintln!("# icosphere: {} vertices, {} triangles", mesh.vertex_count(), mesh.face_count());
    let path = out.join("big-sphere.glb");
    std::fs::write(&path, gltf::write_glb(&mesh).expect("write")).expect("save");
    let name = "big-sphere.glb";

    let (ms, loaded) = best(reps, || {
        let bytes = std::fs::read(&path).expect("read file");
        gltf::read(&bytes, &Default::default()).expect("valid GLB")
    });
    assert_eq!(loaded.mesh.face_count(), mesh.face_count());
    println!("{name}\tload\tmeshwork\t{ms:.1}");
    let (ms, _) = best(reps, || {
        let bytes = gltf::write_glb(&loaded.mesh).expect("write");
        std::fs::write(out.join("_meshwork_out.glb"), bytes).expect("save");
    });
    println!("{name}\twrite_glb\tmeshwork\t{ms:.1}");
}

//! Reads one mesh file `reps` times with `io::read` and prints the wall time of each read, for
//! profiling a reader alone (e.g. under `perf stat -e task-clock` to see CPU time on a busy machine).
//! usage: read_mesh FILE [REPS]

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: read_mesh FILE [REPS]");
    let reps: usize = args.next().map_or(2, |r| r.parse().expect("REPS is a number"));
    let bytes = std::fs::read(&path).expect("readable file");
    let opts = meshwork_core::io::ReadOptions { name_hint: Some(path.clone()), ..Default::default() };
    for _ in 0..reps {
        let t = std::time::Instant::now();
        let l = meshwork_core::io::read(&bytes, &opts).expect("valid mesh");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        println!("{path}\t{ms:.1} ms\t{} vertices\t{} faces", l.mesh.vertex_count(), l.mesh.face_count());
    }
}

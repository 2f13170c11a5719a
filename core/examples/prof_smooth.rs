//! Times the pieces of the smooth job on one mesh (min of N runs): a profiling aid.
//! usage: prof_smooth MESH.obj [REPS]
use std::time::Instant;

use meshwork_core::laplacian::{self, PairLayout, Stencil};
use meshwork_core::metrics;

fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> f64 {
    let mut t = f64::INFINITY;
    for _ in 0..reps {
        let s = Instant::now();
        std::hint::black_box(f());
        t = t.min(s.elapsed().as_secs_f64() * 1e3);
    }
    t
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let reps: usize = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    faer::set_global_parallelism(faer::Par::Seq);
    let bytes = std::fs::read(&a[1]).unwrap();
    let m = meshwork_core::io::read(&bytes, &Default::default()).unwrap().mesh;
    let (x, f, n) = (&m.positions, &m.faces, m.vertex_count());
    let p = |name: &str, ms: f64| println!("{name:40} {ms:8.2} ms");
    p("stencil edges", best(reps, || Stencil::new(f, n, PairLayout::Edges).unwrap()));
    p("stencil uniform", best(reps, || Stencil::uniform(f, n).unwrap()));
    let st = Stencil::new(f, n, PairLayout::Edges).unwrap();
    p("uniform_stiffness", best(reps, || st.uniform_stiffness()));
    p("boundary_vertices", best(reps, || st.boundary_vertices()));
    p("mean_edge_length", best(reps, || laplacian::mean_edge_length(&st, x)));
    p("volume_about", best(reps, || metrics::volume_about(x, f, [0.0; 3])));
    p(
        "metrics::compare",
        best(reps, || {
            metrics::compare(x, x, f, [0.0; 3], &vec![false; n], true, &meshwork_core::job::Progress::new())
        }),
    );
    p("displacement", best(reps, || metrics::displacement(x, x)));
    p("mesh clone", best(reps, || m.clone()));
    let job = |params: serde_json::Value| {
        meshwork_core::job::run(
            meshwork_core::job::JobKind::Smooth,
            vec![m.clone()],
            params,
            &meshwork_core::job::Progress::new(),
        )
        .unwrap()
    };
    for params in [
        serde_json::json!({"method": "taubin", "hausdorff": false}),
        serde_json::json!({"method": "taubin", "iterations": 5, "hausdorff": false}),
        serde_json::json!({"method": "implicit", "hausdorff": false}),
        serde_json::json!({"method": "implicit", "solver": "cholesky", "hausdorff": false}),
        serde_json::json!({"method": "implicit", "operator": "uniform", "relative_time_step": false,
                           "time_step": 0.5, "preserve_volume": true, "hausdorff": false}),
    ] {
        let mut bestv: Option<serde_json::Value> = None;
        let mut bt = f64::INFINITY;
        for _ in 0..reps {
            let s = Instant::now();
            let o = job(params.clone());
            let t = s.elapsed().as_secs_f64() * 1e3;
            if t < bt {
                bt = t;
                bestv = Some(o.report["stages"].clone());
            }
        }
        println!("job {params}\n    {bt:8.2} ms (incl. input clone) {}", bestv.unwrap());
    }
}

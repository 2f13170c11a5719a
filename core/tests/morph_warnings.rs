//! The morph report warns when feature pairs were asked for but did not meet, and is quiet when
//! they met: a stalled warp must not be silent.

mod shared_meshes;

use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::shapes::icosphere;
use serde_json::json;

#[test]
fn met_features_give_no_warning() {
    // Two icospheres of the same connectivity, one turned: pairs of the same vertex are
    // consistent, so the warp closes every gap.
    let a = icosphere(3, 1.0);
    let mut b = a.clone();
    for p in &mut b.positions {
        *p = [p[0] * 1.3, p[1], p[2] * 0.8];
    }
    let o = job::run(
        JobKind::Morph,
        vec![a, b],
        json!({"frames": 2, "features": [[0, 0], [40, 40], [200, 200], [500, 500]]}),
        &Progress::new(),
    )
    .expect("morph");
    let gap = o.report["features"]["max_feature_gap_after"].as_f64().expect("gap");
    assert!(gap <= 1e-6, "gap {gap}");
    assert_eq!(o.report["warnings"], json!([]));
}

#[test]
fn a_stalled_planar_warp_is_a_warning() {
    // woody ↔ alligator with one interior pair whose goal is near the rim: the planar warp stops
    // before it folds (a known limit, see docs/benchmarks.md → Morph sweep).
    let (Some(a), Some(b)) = (shared_meshes::load("woody.obj"), shared_meshes::load("alligator.obj")) else {
        eprintln!("SKIP: ../shared/meshes not present");
        return;
    };
    let o = job::run(
        JobKind::Morph,
        vec![a, b],
        json!({"frames": 2, "repair": true, "registration": "none", "features": [[300, 1500]]}),
        &Progress::new(),
    )
    .expect("morph");
    let gap = o.report["features"]["max_feature_gap_after"].as_f64().expect("gap");
    let w = o.report["warnings"].as_array().expect("warnings array");
    eprintln!("gap {gap}, warnings {w:?}");
    if gap > 1e-6 {
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].as_str().unwrap().contains("did not meet"), "{w:?}");
    } else {
        assert!(w.is_empty(), "the pair met (gap {gap}) yet the report warns: {w:?}");
    }
}

//! A coarse copy of a shared mesh as the template for that mesh's own plane sections (the issue's
//! "a different template (…, a coarse shared mesh)"): the repaired mesh in the unit box,
//! simplified by quadric half-edge collapses that keep it a closed manifold of the same genus
//! (`morph::simplify`), so the sections cut it into as many regions as the source.

use serde_json::json;

use meshwork_core::fit::testdata::sections_of_repaired;
use meshwork_core::mesh::Mesh;
use meshwork_core::morph::simplify::Hierarchy;
use meshwork_core::{Error, Progress};

use crate::support::{case, read_as, shared, unit_repaired, Case, Expect};

/// The repaired `name` in the sections' unit-box frame (`support::unit_repaired`), simplified to
/// `vertices`.
pub fn coarse_copy(name: &str, vertices: usize) -> Result<Mesh, Error> {
    let fixed = unit_repaired(name)?;
    let mut h = Hierarchy::new(&fixed.positions, &fixed.faces.triangles());
    h.simplify(vertices, true, &Progress::new())?;
    let (map, tris) = h.current();
    let pos = map.iter().map(|&v| fixed.positions[v as usize]).collect();
    Ok(Mesh::from_triangles(pos, &tris))
}

pub fn coarse() -> Vec<Case> {
    let mut out = Vec::new();
    for name in ["homer", "fandisk", "spot", "cow", "rocker-arm", "stanford-bunny"] {
        let raw = read_as(&shared(name), "x.obj").unwrap_or_default();
        let regions = sections_of_repaired(raw).map(|(_, _, n)| n).ok();
        for vertices in [300, 1000] {
            out.push(case(
                &format!("coarse {name} ({vertices} vertices) vs its sections (auto)"),
                move || {
                    let raw = read_as(&shared(name), "x.obj")?;
                    let (curves, _, _) = sections_of_repaired(raw)?;
                    Ok(vec![coarse_copy(name, vertices)?, curves])
                },
                json!({}),
                Expect::Fit(regions),
            ));
        }
    }
    out
}

//! Feature-line networks (`testdata::feature_curves`): the sharp edges of a CAD or scanned mesh,
//! edge by edge as two-point polylines the reader must weld, fitted onto a coarse copy of the same
//! mesh placed where the curves are (as a user who drew the curves on the template has it). Unlike
//! plane sections, feature lines end in the open and meet at corners of any valence, and they sample
//! the surface so unevenly that their principal axes are unlike the template's.
//!
//! The hand count of the regions: `testdata::sharp_edges` on the source (`support::unit_repaired`,
//! the frame of `coarse_copy`).

use serde_json::json;

use crate::coarse::coarse_copy;
use crate::support::{case, unit_repaired as source, Case, Expect};
use meshwork_core::fit::testdata::{feature_curves, sharp_edges};

pub fn features() -> Vec<Case> {
    let mut out = Vec::new();
    for (name, deg) in [("fandisk", 40.0), ("rocker-arm", 50.0)] {
        let regions = source(name).ok().map(|m| sharp_edges(&m, deg).1);
        for vertices in [1000, 3000] {
            out.push(case(
                &format!("coarse {name} ({vertices} vertices) vs its feature lines over {deg}°"),
                move || Ok(vec![coarse_copy(name, vertices)?, feature_curves(&source(name)?, deg)]),
                json!({}),
                Expect::Fit(regions),
            ));
        }
        // The template given elsewhere (turned a quarter about z, moved 2 away): the placed pose is
        // no start, and only the PCA starts are left for curves that sample it unevenly.
        out.push(case(
            &format!("coarse {name} (3000 vertices) turned and moved off its feature lines over {deg}°"),
            move || {
                let mut t = coarse_copy(name, 3000)?;
                for p in &mut t.positions {
                    *p = [2.0 - p[1], p[0], p[2]];
                }
                Ok(vec![t, feature_curves(&source(name)?, deg)])
            },
            json!({}),
            Expect::Fit(regions),
        ));
    }
    out
}

//! Shared meshes as templates for another mesh's curves (session 9): a real template of another
//! shape, aligned automatically (cow onto spot's sections and back, homer onto cow's), a genus-1
//! template (rocker-arm) under a genus-0 network, and the flat open meshes (woody, alligator) as
//! they are read, under their own sections.

use meshwork_core::mesh::Mesh;
use meshwork_core::Error;

use crate::support::{case, repaired, sections_of, to_unit_box, Case, Expect};

/// The repaired shared mesh `template` in the unit box and the sections of shared mesh `curves`.
fn template_vs_sections(template: &str, curves: &str) -> Result<Vec<Mesh>, Error> {
    let (_, raw, _) = sections_of(template);
    let mut t = repaired(raw);
    to_unit_box(&mut t);
    let (c, _, _) = sections_of(curves);
    Ok(vec![t, c])
}

pub fn sources() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    for (t, c) in
        [("cow", "spot"), ("spot", "cow"), ("homer", "cow"), ("rocker-arm", "homer"), ("fandisk", "homer")]
    {
        let regions = sections_of(c).2;
        out.push(case(
            &format!("{t} template vs {c}'s sections (auto)"),
            move || template_vs_sections(t, c),
            json!({}),
            // The region count of the curves' own surface holds for a template of the same genus.
            Expect::Fit(if t == "rocker-arm" { None } else { Some(regions) }),
        ));
    }
    for name in ["woody", "alligator"] {
        for (how, params) in [
            ("none", json!({"alignment": "none", "coplanar_centres": "augment"})),
            ("auto", json!({"coplanar_centres": "augment"})),
        ] {
            out.push(case(
                &format!("{name}-raw vs own sections ({how})"),
                move || {
                    let (c, raw, _) = sections_of(name);
                    Ok(vec![raw, c])
                },
                params.clone(),
                Expect::Fit(None),
            ));
        }
    }
    out
}

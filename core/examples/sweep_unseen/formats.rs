//! Templates in every format we read (session 9): PLY (ASCII and binary), STL (binary: f32
//! corners, a soup welded on read; ASCII), OFF, glTF and GLB, written by our own writer or by hand,
//! and a repaired shared mesh carried through STL (f32 rounding of every vertex).

use meshwork_core::fit::testdata::{ascii_stl, binary_ply};
use meshwork_core::io::{write, Format};
use meshwork_core::mesh::Mesh;
use meshwork_core::shapes::icosphere;
use meshwork_core::Error;

use crate::support::{case, read_as, repaired, sections_of, sphere_sections, to_unit_box, Case, Expect};

/// `m` written as `format` and read back as a template.
fn through(m: &Mesh, format: Format) -> Result<Mesh, Error> {
    let bytes = write(m, format)?;
    read_as(&bytes, &format!("t.{}", format.extension()))
}

pub fn formats() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    for format in [Format::Ply, Format::Stl, Format::Off, Format::Gltf, Format::Glb] {
        out.push(case(
            &format!("template as {} (our writer)", format.extension().to_uppercase()),
            move || Ok(vec![through(&icosphere(3, 1.0), format)?, sphere_sections(6)]),
            json!({}),
            Expect::Fit(Some(8)),
        ));
    }
    out.push(case(
        "template as binary PLY (float, hand-written)",
        || Ok(vec![read_as(&binary_ply(&icosphere(3, 1.0)), "t.ply")?, sphere_sections(6)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "template as ASCII STL soup (hand-written)",
        || Ok(vec![read_as(&ascii_stl(&icosphere(3, 1.0)), "t.stl")?, sphere_sections(6)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    let spot_regions = sections_of("spot").2;
    out.push(case(
        "spot through binary STL (f32) vs own sections",
        || {
            let (c, raw, _) = sections_of("spot");
            let mut t = repaired(raw);
            to_unit_box(&mut t);
            Ok(vec![through(&t, Format::Stl)?, c])
        },
        json!({"alignment": "none"}),
        Expect::Fit(Some(spot_regions)),
    ));
    out.push(case(
        "template GLB + curves GLB (both our writer)",
        || {
            let c = read_as(&write(&sphere_sections(6), Format::Glb)?, "c.glb")?;
            Ok(vec![through(&icosphere(3, 1.0), Format::Glb)?, c])
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out
}

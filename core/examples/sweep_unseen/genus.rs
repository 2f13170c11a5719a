//! Templates of genus 1: a torus template fitted to plane sections of another torus (finer,
//! turned about its axis so no vertex is shared, fatter, squashed or tilted). A plane through the
//! hole cuts a torus into two circles, a plane across the ring into two loops; the hand count of
//! the regions is `section_regions` on the source torus.

use meshwork_core::fit::testdata::{plane_sections, section_regions};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::torus;
use meshwork_core::Error;

use crate::support::{case, fit_inputs, Case, Expect, X, Y, Z};

/// The source torus: `torus(nu, nv, 1, r_minor)` turned by `turn` radians about z, its y scaled
/// by `squash`, then tilted by `tilt` radians about x.
fn source(r_minor: f64, squash: f64, turn: f64, tilt: f64) -> Mesh {
    let mut m = torus(240, 96, 1.0, r_minor, false);
    let (ct, st, cx, sx) = (turn.cos(), turn.sin(), tilt.cos(), tilt.sin());
    for p in &mut m.positions {
        let [x, y, z] = *p;
        let (x, y) = (ct * x - st * y, (st * x + ct * y) * squash);
        *p = [x, cx * y - sx * z, sx * y + cx * z];
    }
    m
}

/// Planes through the hole (z), across the ring (x, y) and one off-centre across the ring, all
/// a little off the axes so no plane holds a template vertex.
fn planes() -> Vec<(Point3, f64)> {
    vec![(Z, 0.013), (X, 0.011), (Y, -0.017), (X, 0.63)]
}

fn inputs(template: Mesh, src: &Mesh) -> Result<Vec<Mesh>, Error> {
    fit_inputs(template, plane_sections(src, &planes()))
}

pub fn genus() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    // (label, template (nu, nv, minor radius, quads), source (minor, squash, turn, tilt))
    let rows: [(&str, (usize, usize, f64, bool), (f64, f64, f64, f64)); 5] = [
        ("torus vs sections of a finer torus", (48, 16, 0.4, false), (0.4, 1.0, 0.05, 0.0)),
        ("torus vs sections of a fatter torus", (48, 16, 0.3, false), (0.45, 1.0, 0.05, 0.0)),
        ("torus vs sections of a squashed torus", (48, 16, 0.4, false), (0.4, 0.7, 0.05, 0.0)),
        ("torus vs sections of a tilted torus (auto)", (48, 16, 0.4, false), (0.4, 1.0, 0.05, 0.35)),
        ("quad torus vs sections of a finer torus", (40, 12, 0.4, true), (0.4, 1.0, 0.05, 0.0)),
    ];
    for (label, (nu, nv, minor, quads), (r, squash, turn, tilt)) in rows {
        let regions = section_regions(&source(r, squash, turn, tilt), &planes());
        out.push(case(
            label,
            move || inputs(torus(nu, nv, 1.0, minor, quads), &source(r, squash, turn, tilt)),
            json!({}),
            Expect::Fit(Some(regions)),
        ));
    }
    out
}

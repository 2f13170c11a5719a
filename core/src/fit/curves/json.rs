//! Curves given as JSON polylines.

use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Reads a curve network given as JSON `{"polylines": [[[x, y, z], …], …]}` (issue 5's third curve
/// format besides OBJ `l` and glTF lines). Returns `None` when `bytes` is not such a document, so the
/// caller can fall back to the mesh readers. Each polyline becomes one `Mesh::curves` entry; shared
/// endpoints are joined later, like those of any other curve input.
pub fn polylines_from_json(bytes: &[u8]) -> Option<Result<Mesh>> {
    let text = std::str::from_utf8(bytes).ok()?.trim_start();
    if !text.starts_with('{') || text.contains("\"asset\"") && !text.contains("\"polylines\"") {
        return None;
    }
    let doc: serde_json::Value = match serde_json::from_str(text) {
        Ok(v) => v,
        // Not even JSON and no "polylines" key: maybe a truncated glTF; the mesh readers say why.
        Err(_) if !text.contains("\"polylines\"") => return None,
        Err(e) => {
            return Some(Err(Error::malformed(
                "json",
                crate::error::Location::Line(e.line()),
                format!("curve network JSON: {e}"),
            )))
        }
    };
    match doc.get("polylines") {
        Some(lines) => Some(parse_polylines(lines)),
        // A JSON object that is neither glTF (no "asset") nor a curves document: the mesh readers
        // would only say that no format matches, so say what a curves document needs.
        None if doc.is_object() => Some(Err(Error::malformed(
            "json",
            crate::error::Location::Gltf("polylines".into()),
            "a curves JSON document is {\"polylines\": [[[x, y, z], …], …]}; this object has no \"polylines\" key",
        ))),
        None => None,
    }
}

fn parse_polylines(lines: &serde_json::Value) -> Result<Mesh> {
    use crate::error::Location;
    let at = |path: String, msg: &str| Error::malformed("json", Location::Gltf(path), msg.to_string());
    let lines = lines.as_array().ok_or_else(|| at("polylines".into(), "must be an array of polylines"))?;
    let mut mesh = Mesh::default();
    for (i, line) in lines.iter().enumerate() {
        let points =
            line.as_array().ok_or_else(|| at(format!("polylines[{i}]"), "must be an array of points"))?;
        if points.len() < 2 {
            return Err(at(format!("polylines[{i}]"), "a polyline needs at least 2 points"));
        }
        let mut curve = Vec::with_capacity(points.len());
        for (j, p) in points.iter().enumerate() {
            let xyz = p
                .as_array()
                .filter(|c| c.len() == 3)
                .and_then(|c| Some([c[0].as_f64()?, c[1].as_f64()?, c[2].as_f64()?]))
                .filter(|c| c.iter().all(|v| v.is_finite() && v.abs() <= crate::mesh::MAX_COORDINATE))
                .ok_or_else(|| {
                    at(
                        format!("polylines[{i}][{j}]"),
                        "a point is [x, y, z] with finite numbers within ±1e150",
                    )
                })?;
            let index = u32::try_from(mesh.positions.len())
                .map_err(|_| at(format!("polylines[{i}]"), "too many points"))?;
            mesh.positions.push(xyz);
            curve.push(index);
        }
        mesh.curves.push(curve);
    }
    if mesh.curves.is_empty() {
        return Err(at("polylines".into(), "no polylines"));
    }
    Ok(mesh)
}

#[cfg(test)]
mod json_tests {
    use super::*;

    #[test]
    fn polylines_json_becomes_curves() {
        let doc = br#"{"polylines": [[[0,0,0],[1,0,0],[1,1,0]], [[1,1,0],[0,1,0.5]]]}"#;
        let m = polylines_from_json(doc).unwrap().unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.curves, vec![vec![0, 1, 2], vec![3, 4]]);
        assert_eq!(m.positions[4], [0.0, 1.0, 0.5]);
        assert_eq!(m.face_count(), 0);
    }

    #[test]
    fn polylines_json_refuses_coordinates_whose_squares_overflow() {
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0],[1,0,0]], [[0,0,0],[0,1e200,0]]]}"#)
            .unwrap()
            .unwrap_err();
        assert!(e.to_string().contains("polylines[1][1]"), "{e}");
    }

    #[test]
    fn polylines_json_errors_name_the_point() {
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0],[1,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("polylines[0][1]"), "{e}");
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("polylines[0]"), "{e}");
        assert!(polylines_from_json(b"v 0 0 0\n").is_none());
        assert!(polylines_from_json(br#"{"asset": {"version": "2.0"}}"#).is_none());
        // An object with neither key names the key it lacks (it was "matches no format").
        let e = polylines_from_json(br#"{"lines": [[[0,0,0],[1,0,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("no \"polylines\" key"), "{e}");
        assert!(polylines_from_json(br#"{"lines": "#).is_none());
    }
}

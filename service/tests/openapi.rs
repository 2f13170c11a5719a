//! `openapi/openapi.json` must be exactly what the code generates (`meshwork openapi`).

mod common;

#[test]
fn checked_in_openapi_matches_the_code() {
    let o = std::process::Command::new(common::BIN).arg("openapi").output().unwrap();
    assert!(o.status.success());
    let generated = String::from_utf8(o.stdout).unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../openapi/openapi.json");
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        generated == checked_in,
        "openapi/openapi.json is stale: run `cargo run -p meshwork-service -- openapi -o openapi/openapi.json`"
    );
    let doc: serde_json::Value = serde_json::from_str(&generated).unwrap();
    assert_eq!(doc["openapi"], "3.1.0");
    for job in ["validate", "convert", "repair", "smooth", "fit", "morph"] {
        assert!(doc["paths"][format!("/v1/{job}")]["post"].is_object(), "{job}");
    }
    for p in
        ["/v1/jobs", "/v1/jobs/{id}", "/v1/jobs/{id}/result", "/v1/jobs/{id}/report", "/healthz", "/metrics"]
    {
        assert!(doc["paths"][p].is_object(), "{p}");
    }
    // Errors are documented with their stable types.
    let types = doc["components"]["schemas"]["Problem"]["properties"]["type"]["enum"].as_array().unwrap();
    for t in
        ["/problems/malformed-input", "/problems/queue-full", "/problems/timed-out", "/problems/too-large"]
    {
        assert!(types.iter().any(|x| x == t), "{t}");
    }
    let smooth = &doc["paths"]["/v1/smooth"]["post"];
    assert_eq!(
        smooth["requestBody"]["content"]["multipart/form-data"]["schema"]["properties"]["params"]["$ref"],
        "#/components/schemas/SmoothParams"
    );
    assert!(smooth["responses"]["503"]["content"]["application/problem+json"].is_object());
}

//! No `.unwrap()` / `.expect(` in library or service code outside tests: each would be a panic
//! where bad input must get an error (HTTP 4xx problem+json, CLI exit 2). Test code (files named
//! `tests.rs`, `#[cfg(test)]` modules, inline or in their own file) and comments may use them.
//!
//! The scan is textual: a `#[cfg(test)]` item is skipped to its matching closing brace (or, for
//! `mod name;`, the file `name.rs` / `name/mod.rs` beside it). So the scan cannot pass by skipping
//! everything, it also counts the calls it skipped in test code and requires some.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

fn calls(line: &str) -> usize {
    line.matches(".unwrap()").count() + line.matches(".expect(").count()
}

/// (calls outside test code with their line numbers, calls inside test code, files of
/// `#[cfg(test)] mod name;` items).
fn scan(path: &Path) -> (Vec<(usize, String)>, usize, Vec<PathBuf>) {
    let text = std::fs::read_to_string(path).unwrap();
    let (mut outside, mut inside, mut test_files) = (Vec::new(), 0, Vec::new());
    let (mut depth, mut skip_until, mut pending) = (0i64, None::<i64>, false);
    for (i, line) in text.lines().enumerate() {
        let code = line.trim();
        if code.starts_with("//") {
            continue;
        }
        if skip_until.is_none() && code.starts_with("#[cfg(test)]") {
            pending = true;
            continue;
        }
        let opens = line.matches('{').count() as i64;
        let closes = line.matches('}').count() as i64;
        if pending && !code.starts_with('#') {
            pending = false;
            if let Some(name) = code.strip_prefix("mod ").or(code.strip_prefix("pub(crate) mod ")) {
                if let Some(name) = name.strip_suffix(';') {
                    let dir = path.parent().unwrap();
                    let stem = path.file_stem().unwrap();
                    // `mod x;` in foo.rs lives in foo/x.rs; in mod.rs or lib.rs, beside it.
                    let base = if stem == "mod" || stem == "lib" || stem == "main" {
                        dir.to_path_buf()
                    } else {
                        dir.join(stem)
                    };
                    test_files.push(base.join(format!("{name}.rs")));
                    test_files.push(base.join(name).join("mod.rs"));
                    continue;
                }
            }
            if opens > closes {
                skip_until = Some(depth);
            }
            inside += calls(line);
            depth += opens - closes;
            continue;
        }
        match skip_until {
            Some(_) => inside += calls(line),
            None if calls(line) > 0 => outside.push((i + 1, code.to_string())),
            None => {}
        }
        depth += opens - closes;
        if skip_until.is_some_and(|d| depth <= d) {
            skip_until = None;
        }
    }
    (outside, inside, test_files)
}

#[test]
fn library_and_service_code_has_no_unwrap_or_expect_outside_tests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["core/src", "service/src"] {
        rust_files(&root.join(dir), &mut files);
    }
    let scans: Vec<_> = files.iter().map(|f| (f, scan(f))).collect();
    let test_files: Vec<&PathBuf> = scans.iter().flat_map(|(_, s)| &s.2).collect();
    let (mut found, mut in_tests) = (Vec::new(), 0);
    for (file, (outside, inside, _)) in &scans {
        let is_test_file = file.file_name().is_some_and(|n| n == "tests.rs")
            || test_files.iter().any(|t| t.canonicalize().ok() == file.canonicalize().ok());
        if is_test_file {
            in_tests += outside.len() + inside;
            continue;
        }
        in_tests += inside;
        found.extend(outside.iter().map(|(l, s)| format!("{}:{l}: {s}", file.display())));
    }
    assert!(
        found.is_empty(),
        "unwrap/expect outside test code (return an error instead):\n{}",
        found.join("\n")
    );
    // The scan saw the test code's calls (it does not pass by skipping everything).
    assert!(in_tests > 100, "only {in_tests} calls seen in test code");
}

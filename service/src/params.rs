//! Job parameters from loose `name=value` pairs: the CLI's unknown `--some-name VALUE` flags and the
//! HTTP query string both become the same JSON object the job's params type deserialises, so a
//! parameter is spelled the same everywhere (`--time-step 0.1`, `?time_step=0.1`, `{"time_step": 0.1}`).

use serde_json::{Map, Value};

/// A flag or query value: JSON when it parses as JSON (`5`, `true`, `[0,1]`, `{"a":1}`), else the
/// plain string (`taubin`). A string that looks like a number must be quoted: `--name '"123"'`.
pub fn parse_value(raw: &str) -> Value {
    serde_json::from_str(raw).unwrap_or_else(|_| Value::String(raw.to_string()))
}

/// `time-step` → `time_step`.
pub fn snake(name: &str) -> String {
    name.replace('-', "_")
}

/// Splits CLI arguments (after the subcommand) into the ones clap knows and job parameters.
///
/// `known_with_value` are long/short options clap parses that take a value (`-o`, `--format`,
/// …); `known_switches` take none (`--quiet`, `--help`). Everything else spelled `--name` is a
/// parameter: `--name=VALUE`, `--name VALUE`, or `--name` alone (= `true`) when it is last or
/// followed by another `--option` or by one of clap's short options (`-o`, `-q`). Positional arguments pass through to clap.
pub fn split_cli_args(
    args: &[String],
    known_with_value: &[&str],
    known_switches: &[&str],
) -> (Vec<String>, Map<String, Value>) {
    // `--repair -o out.glb`: `-o` is clap's, not the value of `repair` (a value may still start
    // with one dash: `--lambda -0.25`).
    let is_option = |a: &str| {
        let flag = a.split_once('=').map_or(a, |(f, _)| f);
        a.starts_with("--") || known_with_value.contains(&flag) || known_switches.contains(&flag)
    };
    let mut clap_args = Vec::new();
    let mut params = Map::new();
    let mut i = 0;
    while i < args.len() {
        let a = &args[i];
        let (flag, inline) = match a.split_once('=') {
            Some((f, v)) if a.starts_with("--") => (f, Some(v)),
            _ => (a.as_str(), None),
        };
        if a == "--" || !a.starts_with('-') || a == "-" {
            clap_args.push(a.clone());
        } else if known_switches.contains(&flag) {
            clap_args.push(a.clone());
        } else if known_with_value.contains(&flag) {
            clap_args.push(a.clone());
            if inline.is_none() && i + 1 < args.len() {
                i += 1;
                clap_args.push(args[i].clone());
            }
        } else if let Some(name) = flag.strip_prefix("--") {
            let value = match inline {
                Some(v) => parse_value(v),
                None if i + 1 < args.len() && !is_option(&args[i + 1]) => {
                    i += 1;
                    parse_value(&args[i])
                }
                None => Value::Bool(true),
            };
            params.insert(snake(name), value);
        } else {
            // Unknown short option: let clap report it.
            clap_args.push(a.clone());
        }
        i += 1;
    }
    (clap_args, params)
}

/// Overlays `top` on `base` (top-level keys; `top` wins).
pub fn merge(mut base: Map<String, Value>, top: Map<String, Value>) -> Map<String, Value> {
    for (k, v) in top {
        base.insert(k, v);
    }
    base
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn s(v: &[&str]) -> Vec<String> {
        v.iter().map(|x| x.to_string()).collect()
    }

    #[test]
    fn unknown_flags_become_snake_case_params() {
        let (clap, p) = split_cli_args(
            &s(&[
                "in.obj",
                "-o",
                "out.glb",
                "--method",
                "taubin",
                "--time-step=0.5",
                "--lambda",
                "-0.25",
                "--preserve-volume",
                "--axis-mask",
                "[1,0,1]",
                "--report",
                "r.json",
                "--flag",
            ]),
            &["-o", "--output", "--report"],
            &["--quiet"],
        );
        assert_eq!(clap, s(&["in.obj", "-o", "out.glb", "--report", "r.json"]));
        assert_eq!(
            Value::Object(p),
            json!({"method": "taubin", "time_step": 0.5, "lambda": -0.25, "preserve_volume": true,
                   "axis_mask": [1, 0, 1], "flag": true})
        );
    }

    #[test]
    fn values_parse_as_json_else_string() {
        assert_eq!(parse_value("5"), json!(5));
        assert_eq!(parse_value("false"), json!(false));
        assert_eq!(parse_value("cotangent"), json!("cotangent"));
        assert_eq!(parse_value("\"12\""), json!("12"));
    }

    /// `meshwork morph a.obj b.obj --repair -o out.glb` used to take `-o` as the value of
    /// `repair` and then fail with "-o OUT is required".
    #[test]
    fn a_bare_flag_before_a_short_option_is_true() {
        let (clap, p) = split_cli_args(
            &s(&["a.obj", "--repair", "-o", "out.glb", "--verbose-thing", "-q", "--lambda", "-0.5"]),
            &["-o", "--output"],
            &["-q", "--quiet"],
        );
        assert_eq!(clap, s(&["a.obj", "-o", "out.glb", "-q"]));
        assert_eq!(Value::Object(p), json!({"repair": true, "verbose_thing": true, "lambda": -0.5}));
    }
}

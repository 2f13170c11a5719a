//! Typed access to the glTF JSON tree where every failure names the JSON path of the offending
//! value (`accessors[3].count`), so the caller can find it in their file.

use serde_json::{Map, Value};

use crate::error::{Error, Location, Result};

pub(super) type Obj = Map<String, Value>;

/// A structural problem at `path`.
pub(super) fn bad(path: impl Into<String>, message: impl Into<String>) -> Error {
    Error::malformed("glTF", Location::Gltf(path.into()), message)
}

/// Unusable geometry at `path` (NaN, index out of range).
pub(super) fn invalid(path: impl Into<String>, message: impl Into<String>) -> Error {
    Error::InvalidMesh { location: Location::Gltf(path.into()), message: message.into() }
}

pub(super) fn object<'v>(value: &'v Value, path: &str) -> Result<&'v Obj> {
    value.as_object().ok_or_else(|| bad(path, "must be a JSON object"))
}

/// `obj[key]` as an array; missing means empty.
pub(super) fn array<'v>(obj: &'v Obj, key: &str, path: &str) -> Result<&'v [Value]> {
    match obj.get(key) {
        None => Ok(&[]),
        Some(Value::Array(a)) => Ok(a),
        Some(_) => Err(bad(join(path, key), "must be an array")),
    }
}

/// `path.key`, or `key` at the root.
pub(super) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_owned()
    } else {
        format!("{path}.{key}")
    }
}

pub(super) fn uint(obj: &Obj, key: &str, path: &str) -> Result<Option<u64>> {
    match obj.get(key) {
        None => Ok(None),
        Some(v) => v
            .as_u64()
            .map(Some)
            .ok_or_else(|| bad(join(path, key), format!("must be a non-negative integer, found {v}"))),
    }
}

pub(super) fn required_uint(obj: &Obj, key: &str, path: &str) -> Result<u64> {
    uint(obj, key, path)?.ok_or_else(|| bad(join(path, key), "is required"))
}

/// `obj[key]` as a usize index into an array of `len` `what`s.
pub(super) fn index(obj: &Obj, key: &str, path: &str, len: usize, what: &str) -> Result<Option<usize>> {
    let Some(i) = uint(obj, key, path)? else { return Ok(None) };
    if i >= len as u64 {
        return Err(bad(join(path, key), format!("{what} {i} does not exist (the file has {len})")));
    }
    Ok(Some(i as usize))
}

/// A value (not under a key) as an index, e.g. an element of `children`.
pub(super) fn index_value(v: &Value, path: &str, len: usize, what: &str) -> Result<usize> {
    let i = v.as_u64().ok_or_else(|| bad(path, format!("must be a non-negative integer, found {v}")))?;
    if i >= len as u64 {
        return Err(bad(path, format!("{what} {i} does not exist (the file has {len})")));
    }
    Ok(i as usize)
}

pub(super) fn string<'v>(obj: &'v Obj, key: &str, path: &str) -> Result<Option<&'v str>> {
    match obj.get(key) {
        None => Ok(None),
        Some(Value::String(s)) => Ok(Some(s)),
        Some(_) => Err(bad(join(path, key), "must be a string")),
    }
}

pub(super) fn boolean(obj: &Obj, key: &str, path: &str) -> Result<bool> {
    match obj.get(key) {
        None => Ok(false),
        Some(Value::Bool(b)) => Ok(*b),
        Some(_) => Err(bad(join(path, key), "must be true or false")),
    }
}

/// `obj[key]` as exactly `N` finite numbers.
pub(super) fn numbers<const N: usize>(obj: &Obj, key: &str, path: &str) -> Result<Option<[f64; N]>> {
    let Some(v) = obj.get(key) else { return Ok(None) };
    let p = join(path, key);
    let a = v.as_array().ok_or_else(|| bad(&p, format!("must be an array of {N} numbers")))?;
    if a.len() != N {
        return Err(bad(&p, format!("must have {N} numbers, has {}", a.len())));
    }
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x
            .as_f64()
            .filter(|f| f.is_finite())
            .ok_or_else(|| bad(&p, format!("{x} is not a finite number")))?;
    }
    Ok(Some(out))
}

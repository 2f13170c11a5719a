//! The GLB container: a 12-byte header (`glTF`, version 2, total length), a JSON chunk, an
//! optional BIN chunk. Every length is checked against the bytes actually present before it is
//! used, and problems are reported with the byte offset of the field that lies.

use crate::error::{Error, Location, Result};

const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// The chunks of a GLB file, borrowed from its bytes.
pub(super) struct Glb<'a> {
    pub json: &'a [u8],
    /// Offset of the JSON chunk's data in the file (for error locations).
    pub json_offset: usize,
    pub bin: Option<&'a [u8]>,
}

fn bad(at: usize, message: impl Into<String>) -> Error {
    Error::malformed("GLB", Location::Byte(at), message)
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

pub(super) fn parse(bytes: &[u8]) -> Result<Glb<'_>> {
    let actual = bytes.len();
    if actual < 12 {
        return Err(bad(
            actual,
            format!("truncated header: a GLB header is 12 bytes, the file has {actual}"),
        ));
    }
    let version = u32_at(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(bad(4, format!("GLB version {version}; only glTF 2.0 (version 2) is supported")));
    }
    let declared = u32_at(bytes, 8).unwrap_or(0) as usize;
    if declared > actual {
        return Err(bad(
            actual,
            format!("truncated: the header declares {declared} bytes, the file ends at byte {actual}"),
        ));
    }
    if declared < actual {
        return Err(bad(8, format!("the header declares {declared} bytes but the file has {actual}")));
    }
    let mut json = None;
    let mut bin = None;
    let mut at = 12;
    let mut index = 0;
    while at < declared {
        let (Some(len), Some(kind)) = (u32_at(bytes, at), u32_at(bytes, at + 4)) else {
            return Err(bad(at, format!("truncated chunk header: 8 bytes needed, {} left", declared - at)));
        };
        if at + 8 > declared {
            return Err(bad(at, format!("truncated chunk header: 8 bytes needed, {} left", declared - at)));
        }
        let start = at + 8;
        let len = len as usize;
        let end = start.checked_add(len).filter(|&e| e <= declared).ok_or_else(|| {
            bad(at, format!("chunk {index} declares {len} bytes but only {} remain", declared - start))
        })?;
        let data = &bytes[start..end];
        match (index, kind) {
            (0, CHUNK_JSON) => json = Some((data, start)),
            (0, _) => {
                return Err(bad(at + 4, format!("the first chunk must be JSON, found type 0x{kind:08x}")))
            }
            (_, CHUNK_JSON) => return Err(bad(at + 4, "a second JSON chunk")),
            (1, CHUNK_BIN) => bin = Some(data),
            (_, CHUNK_BIN) => return Err(bad(at + 4, "a BIN chunk that is not the second chunk")),
            _ => {} // unknown chunk types are skipped, as the spec asks
        }
        at = end;
        index += 1;
    }
    let (json, json_offset) = json.ok_or_else(|| bad(12, "no JSON chunk"))?;
    Ok(Glb { json, json_offset, bin })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(chunks: &[(&[u8], u32)]) -> Vec<u8> {
        let mut body = Vec::new();
        for (data, kind) in chunks {
            body.extend_from_slice(&(data.len() as u32).to_le_bytes());
            body.extend_from_slice(&kind.to_le_bytes());
            body.extend_from_slice(data);
        }
        let mut out = b"glTF".to_vec();
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((12 + body.len()) as u32).to_le_bytes());
        out.extend(body);
        out
    }

    fn offset_of(e: Error) -> usize {
        match e {
            Error::Malformed { location: Location::Byte(b), .. } => b,
            other => panic!("expected a byte location, got {other:?}"),
        }
    }

    #[test]
    fn chunks_are_found() {
        let f = glb(&[(b"{}  ", CHUNK_JSON), (&[1, 2, 3, 4], CHUNK_BIN)]);
        let g = parse(&f).unwrap();
        assert_eq!(g.json, b"{}  ");
        assert_eq!(g.json_offset, 20);
        assert_eq!(g.bin, Some(&[1u8, 2, 3, 4][..]));
    }

    #[test]
    fn lying_lengths_are_located() {
        let f = glb(&[(b"{}  ", CHUNK_JSON), (&[1, 2, 3, 4], CHUNK_BIN)]);
        // Truncation: error at the real end of the file.
        assert_eq!(offset_of(parse(&f[..30]).err().unwrap()), 30);
        // The BIN chunk (header at byte 24) claims more than there is.
        let mut lie = f.clone();
        lie[24..28].copy_from_slice(&100u32.to_le_bytes());
        assert_eq!(offset_of(parse(&lie).err().unwrap()), 24);
        // A chunk length so large that start + len overflows on 32-bit arithmetic.
        lie[24..28].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(offset_of(parse(&lie).err().unwrap()), 24);
        // Header length smaller than the file.
        let mut short = f.clone();
        short[8..12].copy_from_slice(&20u32.to_le_bytes());
        assert_eq!(offset_of(parse(&short).err().unwrap()), 8);
        // Wrong version.
        let mut v1 = f;
        v1[4] = 1;
        assert_eq!(offset_of(parse(&v1).err().unwrap()), 4);
    }

    #[test]
    fn first_chunk_must_be_json() {
        let f = glb(&[(&[0; 4], CHUNK_BIN)]);
        assert_eq!(offset_of(parse(&f).err().unwrap()), 16);
        assert_eq!(offset_of(parse(b"glTF\x02\0\0\0\x0c\0\0\0").err().unwrap()), 12);
    }
}

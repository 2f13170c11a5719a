//! A minimal ZIP writer: entries "stored" (method 0, no compression), CRC-32 per entry, a central
//! directory, no ZIP64 (PKWARE APPNOTE 6.3.x §4.3). Enough to hand a client N frame files in one
//! download without a compression dependency; mesh frames compress poorly anyway (f32 noise).
//!
//! Deterministic output: every entry is dated 1980-01-01 00:00 (the DOS epoch), so the same frames
//! give the same bytes. File names are stored as UTF-8 (general purpose flag bit 11).

use crate::error::{Error, Result};

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), the checksum ZIP stores per entry.
pub fn crc32(data: &[u8]) -> u32 {
    static TABLE: std::sync::OnceLock<[u32; 256]> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let mut t = [0u32; 256];
        for (i, e) in t.iter_mut().enumerate() {
            let mut c = i as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
            }
            *e = c;
        }
        t
    });
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c = table[((c ^ b as u32) & 0xFF) as usize] ^ (c >> 8);
    }
    c ^ 0xFFFF_FFFF
}

/// DOS date of 1980-01-01: year offset 0, month 1, day 1.
const DOS_DATE: u16 = (1 << 5) | 1;
const DOS_TIME: u16 = 0;
const FLAG_UTF8: u16 = 1 << 11;
/// "Version needed to extract": 2.0 (the lowest that readers commonly expect).
const VERSION: u16 = 20;

struct Entry {
    name: String,
    crc: u32,
    size: u32,
    offset: u32,
}

/// Builds a ZIP archive in memory.
#[derive(Default)]
pub struct ZipWriter {
    out: Vec<u8>,
    entries: Vec<Entry>,
}

fn u16le(out: &mut Vec<u8>, v: u16) {
    out.extend_from_slice(&v.to_le_bytes());
}
fn u32le(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn too_large(what: &str, actual: u64, limit: u64) -> Error {
    Error::TooLarge { what: format!("ZIP {what} (no ZIP64 support)"), limit, actual }
}

impl ZipWriter {
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends one stored file. Names must be non-empty, relative, '/'-separated, ≤ 65535 bytes.
    pub fn add(&mut self, name: &str, data: &[u8]) -> Result<()> {
        if name.is_empty()
            || name.starts_with('/')
            || name.contains('\\')
            || name.split('/').any(|c| c == "..")
        {
            return Err(Error::Internal(format!("ZIP entry name {name:?} is not a plain relative path")));
        }
        if name.len() > u16::MAX as usize {
            return Err(too_large("entry name bytes", name.len() as u64, u16::MAX as u64));
        }
        if self.entries.len() >= u16::MAX as usize {
            return Err(too_large("entries", self.entries.len() as u64 + 1, u16::MAX as u64 - 1));
        }
        let end = self.out.len() as u64 + 30 + name.len() as u64 + data.len() as u64;
        if data.len() as u64 >= u32::MAX as u64 || end >= u32::MAX as u64 {
            return Err(too_large("bytes", end, u32::MAX as u64 - 1));
        }
        let crc = crc32(data);
        let offset = self.out.len() as u32;
        let o = &mut self.out;
        u32le(o, 0x0403_4b50); // local file header signature
        u16le(o, VERSION);
        u16le(o, FLAG_UTF8);
        u16le(o, 0); // method: stored
        u16le(o, DOS_TIME);
        u16le(o, DOS_DATE);
        u32le(o, crc);
        u32le(o, data.len() as u32); // compressed size
        u32le(o, data.len() as u32); // uncompressed size
        u16le(o, name.len() as u16);
        u16le(o, 0); // extra field length
        o.extend_from_slice(name.as_bytes());
        o.extend_from_slice(data);
        self.entries.push(Entry { name: name.to_owned(), crc, size: data.len() as u32, offset });
        Ok(())
    }

    /// Writes the central directory and the end record; returns the archive.
    pub fn finish(mut self) -> Result<Vec<u8>> {
        let cd_start = self.out.len() as u64;
        let cd_len: u64 = self.entries.iter().map(|e| 46 + e.name.len() as u64).sum();
        if cd_start + cd_len + 22 >= u32::MAX as u64 {
            return Err(too_large("bytes", cd_start + cd_len + 22, u32::MAX as u64 - 1));
        }
        let o = &mut self.out;
        for e in &self.entries {
            u32le(o, 0x0201_4b50); // central directory header signature
            u16le(o, VERSION); // version made by (MS-DOS attribute conventions)
            u16le(o, VERSION); // version needed
            u16le(o, FLAG_UTF8);
            u16le(o, 0); // stored
            u16le(o, DOS_TIME);
            u16le(o, DOS_DATE);
            u32le(o, e.crc);
            u32le(o, e.size);
            u32le(o, e.size);
            u16le(o, e.name.len() as u16);
            u16le(o, 0); // extra
            u16le(o, 0); // comment
            u16le(o, 0); // disk number start
            u16le(o, 0); // internal attributes
            u32le(o, 0); // external attributes
            u32le(o, e.offset);
            o.extend_from_slice(e.name.as_bytes());
        }
        let n = self.entries.len() as u16;
        u32le(o, 0x0605_4b50); // end of central directory signature
        u16le(o, 0); // this disk
        u16le(o, 0); // disk with the central directory
        u16le(o, n);
        u16le(o, n);
        u32le(o, cd_len as u32);
        u32le(o, cd_start as u32);
        u16le(o, 0); // comment length
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_of_known_strings() {
        // The CRC-32 check value of the standard catalogue ("123456789" → 0xCBF43926).
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
        // "a": one table step by hand: c = 0xFFFFFFFF; index (0xFF ^ 0x61) = 0x9E;
        // table[0x9E] = 0x17B7BE43 → (0x17B7BE43 ^ 0x00FFFFFF) ^ 0xFFFFFFFF = 0xE8B7BE43.
        assert_eq!(crc32(b"a"), 0xE8B7_BE43);
    }

    #[test]
    fn layout_of_a_one_entry_archive() {
        let mut z = ZipWriter::new();
        z.add("a.txt", b"hello").unwrap();
        let b = z.finish().unwrap();
        // local header 30 + name 5 + data 5, central header 46 + 5, end record 22.
        assert_eq!(b.len(), 30 + 5 + 5 + 46 + 5 + 22);
        assert_eq!(&b[0..4], &[0x50, 0x4b, 0x03, 0x04]);
        assert_eq!(&b[30..35], b"a.txt");
        assert_eq!(&b[35..40], b"hello");
        assert_eq!(&b[40..44], &[0x50, 0x4b, 0x01, 0x02]);
        let end = &b[b.len() - 22..];
        assert_eq!(&end[0..4], &[0x50, 0x4b, 0x05, 0x06]);
        assert_eq!(u16::from_le_bytes([end[10], end[11]]), 1);
        assert_eq!(u32::from_le_bytes(end[16..20].try_into().unwrap()), 40); // central dir offset
        assert_eq!(u32::from_le_bytes(b[14..18].try_into().unwrap()), crc32(b"hello"));
    }

    #[test]
    fn unsafe_names_are_refused() {
        let mut z = ZipWriter::new();
        assert!(z.add("../x", b"").is_err());
        assert!(z.add("/abs", b"").is_err());
        assert!(z.add("", b"").is_err());
    }
}

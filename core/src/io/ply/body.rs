//! Body readers: one [`Body`] value source over the binary cursor (either endianness) and over the
//! ascii token stream, so element reading is written once for both encodings.

use super::super::lex;
use super::header::Ty;
use crate::error::{Error, Location, Result};

/// One value source for both encodings.
pub(super) trait Body {
    fn real(&mut self, ty: Ty) -> Result<f64>;
    fn int(&mut self, ty: Ty) -> Result<i64>;
    /// Where the next value starts (line or byte offset).
    fn location(&mut self) -> Location;
    /// Bytes not yet read (caps allocations).
    fn remaining(&self) -> usize;
    /// Skips `n` values of type `ty`.
    fn skip(&mut self, ty: Ty, n: u64) -> Result<()>;
    /// The fewest bytes a value of type `ty` takes.
    fn min_bytes(&self, ty: Ty) -> u64;
}

pub(super) struct Binary<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) pos: usize,
    pub(super) big_endian: bool,
}

impl Binary<'_> {
    #[inline]
    pub(super) fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let Some(s) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(Error::malformed(
                "ply",
                Location::Byte(self.pos),
                format!("data ends early: {N} more bytes needed, {} left", self.bytes.len() - self.pos),
            ));
        };
        self.pos += N;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }
}

impl Body for Binary<'_> {
    #[inline]
    fn real(&mut self, ty: Ty) -> Result<f64> {
        Ok(match ty {
            Ty::F32 => f32::from_le_bytes(self.take()?) as f64,
            Ty::F64 => f64::from_le_bytes(self.take()?),
            _ => self.int(ty)? as f64,
        })
    }

    #[inline]
    fn int(&mut self, ty: Ty) -> Result<i64> {
        Ok(match ty {
            Ty::I8 => i8::from_le_bytes(self.take()?) as i64,
            Ty::U8 => u8::from_le_bytes(self.take()?) as i64,
            Ty::I16 => i16::from_le_bytes(self.take()?) as i64,
            Ty::U16 => u16::from_le_bytes(self.take()?) as i64,
            Ty::I32 => i32::from_le_bytes(self.take()?) as i64,
            Ty::U32 => u32::from_le_bytes(self.take()?) as i64,
            Ty::F32 | Ty::F64 => {
                let at = self.pos;
                let v = self.real(ty)?;
                return integral(v).ok_or_else(|| {
                    Error::malformed("ply", Location::Byte(at), format!("{v} is not an integer"))
                });
            }
        })
    }

    fn location(&mut self) -> Location {
        Location::Byte(self.pos)
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn skip(&mut self, ty: Ty, n: u64) -> Result<()> {
        let len = n.saturating_mul(ty.size() as u64);
        if len > self.remaining() as u64 {
            return Err(Error::malformed(
                "ply",
                Location::Byte(self.pos),
                format!("data ends early: {len} bytes to skip, {} left", self.remaining()),
            ));
        }
        self.pos += len as usize;
        Ok(())
    }

    fn min_bytes(&self, ty: Ty) -> u64 {
        ty.size() as u64
    }
}

pub(super) fn integral(v: f64) -> Option<i64> {
    (v.fract() == 0.0 && v.abs() < 9e15).then_some(v as i64)
}

/// The ascii body as a stream of whitespace-separated tokens across lines.
pub(super) struct Ascii<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) pos: usize,
    /// Line of the current position (1-based, counting the header).
    pub(super) line: usize,
}

impl<'a> Ascii<'a> {
    /// Moves to the start of the next token (or the end), counting lines.
    pub(super) fn skip_space(&mut self) {
        loop {
            while self.pos < self.bytes.len() && lex::is_space(self.bytes[self.pos]) {
                self.pos += 1;
            }
            match self.bytes.get(self.pos) {
                Some(b'\n') => {
                    self.pos += 1;
                    self.line += 1;
                }
                _ => break,
            }
        }
    }

    pub(super) fn token(&mut self) -> Result<&'a [u8]> {
        self.skip_space();
        if self.pos >= self.bytes.len() {
            // Report the file's last line, not the empty one after its final newline.
            let last = self.line - (self.pos > 0 && self.bytes[self.pos - 1] == b'\n') as usize;
            return Err(Error::malformed("ply", Location::Line(last), "data ends early"));
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Ok(&self.bytes[start..self.pos])
    }

    pub(super) fn bad(&self, tok: &[u8], what: &str) -> Error {
        Error::malformed(
            "ply",
            Location::Line(self.line),
            format!("`{}` is not {what}", String::from_utf8_lossy(tok)),
        )
    }
}

impl Body for Ascii<'_> {
    fn real(&mut self, _ty: Ty) -> Result<f64> {
        let t = self.token()?;
        lex::parse_f64(t).ok_or_else(|| self.bad(t, "a number"))
    }

    fn int(&mut self, _ty: Ty) -> Result<i64> {
        let t = self.token()?;
        match lex::parse_i64(t) {
            Some(v) => Ok(v),
            None => lex::parse_f64(t).and_then(integral).ok_or_else(|| self.bad(t, "an integer")),
        }
    }

    fn location(&mut self) -> Location {
        self.skip_space();
        Location::Line(self.line)
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn skip(&mut self, _ty: Ty, n: u64) -> Result<()> {
        for _ in 0..n {
            self.token()?;
        }
        Ok(())
    }

    fn min_bytes(&self, _ty: Ty) -> u64 {
        1
    }
}

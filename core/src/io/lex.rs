//! Small byte-level lexing helpers shared by the text formats (OBJ, OFF, ASCII PLY/STL):
//! whitespace tokenising, exact float parsing with a fast path, integer parsing, and fast
//! shortest-round-trip number formatting for the writers.

/// Powers of ten exactly representable in f64 (10^0 ..= 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18,
    1e19, 1e20, 1e21, 1e22,
];

#[inline]
pub fn is_space(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\r' || b == 0x0b || b == 0x0c
}

/// Splits a line into whitespace-separated tokens.
#[derive(Clone)]
pub struct Tokens<'a> {
    rest: &'a [u8],
}

impl<'a> Tokens<'a> {
    #[inline]
    pub fn new(line: &'a [u8]) -> Self {
        Tokens { rest: line }
    }

    /// What is left after the tokens taken so far, with leading whitespace removed.
    #[inline]
    pub fn rest(&self) -> &'a [u8] {
        trim(self.rest)
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = &'a [u8];

    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        let s = self.rest;
        let start = s.iter().position(|&b| !is_space(b))?;
        let len = s[start..].iter().position(|&b| is_space(b)).unwrap_or(s.len() - start);
        self.rest = &s[start + len..];
        Some(&s[start..start + len])
    }
}

/// The slice without leading and trailing whitespace.
pub fn trim(s: &[u8]) -> &[u8] {
    let a = s.iter().position(|&b| !is_space(b)).unwrap_or(s.len());
    let b = s.iter().rposition(|&b| !is_space(b)).map_or(a, |i| i + 1);
    &s[a..b.max(a)]
}

/// Parses a decimal float. Plain decimals with at most 19 significant digits whose value fits the
/// Clinger fast path (mantissa ≤ 2^53, |exponent| ≤ 22) are converted exactly here (one correctly
/// rounded operation on exact operands); everything else goes through the standard library, which
/// is correctly rounded too. `nan`/`inf` parse (the caller rejects non-finite values with a location).
#[inline]
pub fn parse_f64(tok: &[u8]) -> Option<f64> {
    fast_f64(tok).or_else(|| std::str::from_utf8(tok).ok()?.parse().ok())
}

#[inline]
fn fast_f64(tok: &[u8]) -> Option<f64> {
    let (neg, mut i) = match tok.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    let mut mant: u64 = 0;
    let mut digits = 0u32; // significant digits accumulated (leading zeros excluded)
    let mut any = false;
    let mut exp: i32 = 0;
    while i < tok.len() && tok[i].is_ascii_digit() {
        any = true;
        if mant != 0 || tok[i] != b'0' {
            digits += 1;
        }
        mant = mant.wrapping_mul(10).wrapping_add((tok[i] - b'0') as u64);
        i += 1;
    }
    if i < tok.len() && tok[i] == b'.' {
        i += 1;
        while i < tok.len() && tok[i].is_ascii_digit() {
            any = true;
            if mant != 0 || tok[i] != b'0' {
                digits += 1;
            }
            mant = mant.wrapping_mul(10).wrapping_add((tok[i] - b'0') as u64);
            exp -= 1;
            i += 1;
        }
    }
    if !any || digits > 19 {
        return None;
    }
    if i < tok.len() && (tok[i] == b'e' || tok[i] == b'E') {
        i += 1;
        let (eneg, mut j) = match tok.get(i) {
            Some(b'-') => (true, i + 1),
            Some(b'+') => (false, i + 1),
            _ => (false, i),
        };
        let start = j;
        let mut e: i32 = 0;
        while j < tok.len() && tok[j].is_ascii_digit() {
            e = e.saturating_mul(10).saturating_add((tok[j] - b'0') as i32);
            j += 1;
        }
        if j == start {
            return None;
        }
        exp = exp.saturating_add(if eneg { -e } else { e });
        i = j;
    }
    if i != tok.len() || mant > (1u64 << 53) {
        return None;
    }
    let m = mant as f64;
    let v = if mant == 0 {
        0.0
    } else if (0..=22).contains(&exp) {
        m * POW10[exp as usize]
    } else if (-22..0).contains(&exp) {
        m / POW10[(-exp) as usize]
    } else {
        return None;
    };
    Some(if neg { -v } else { v })
}

/// Parses a signed decimal integer (optional `+`/`-`), rejecting overflow.
#[inline]
pub fn parse_i64(tok: &[u8]) -> Option<i64> {
    let (neg, digits) = match tok.first()? {
        b'-' => (true, &tok[1..]),
        b'+' => (false, &tok[1..]),
        _ => (false, tok),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None; // 18 digits cannot overflow i64; longer indices are nonsense anyway
    }
    let mut v: i64 = 0;
    for &b in digits {
        if !b.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (b - b'0') as i64;
    }
    Some(if neg { -v } else { v })
}

/// Parses an unsigned decimal count.
#[inline]
pub fn parse_u64(tok: &[u8]) -> Option<u64> {
    match parse_i64(tok)? {
        v if v >= 0 && tok.first() != Some(&b'-') => Some(v as u64),
        _ => None,
    }
}

/// Appends the shortest decimal that reads back as exactly `v` (ryu), without a trailing `.0`
/// so that integers stay short (`1` not `1.0`).
#[inline]
pub fn push_f64(out: &mut Vec<u8>, buf: &mut ryu::Buffer, v: f64) {
    let s = buf.format_finite(v).as_bytes();
    let s = s.strip_suffix(b".0").unwrap_or(s);
    out.extend_from_slice(s);
}

/// Appends a non-negative integer in decimal.
#[inline]
pub fn push_u64(out: &mut Vec<u8>, mut v: u64) {
    let mut tmp = [0u8; 20];
    let mut i = tmp.len();
    loop {
        i -= 1;
        tmp[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    out.extend_from_slice(&tmp[i..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_match_std_exactly() {
        let cases = [
            "0",
            "-0",
            "1",
            "-1.5",
            "3.14159",
            "0.1",
            "1e-7",
            "1E+10",
            "-2.5e-3",
            "123456789012345678",
            "0.30000000000000004",
            "9007199254740993",
            "1.7976931348623157e308",
            "4.9e-324",
            "2.292449",
            "-0.871852",
            ".5",
            "5.",
            "+7",
            "1e22",
            "1e23",
            "0.000000000000000000000000001",
        ];
        for c in cases {
            let want: f64 = c.parse().unwrap();
            let got = parse_f64(c.as_bytes()).unwrap();
            assert_eq!(got.to_bits(), want.to_bits(), "{c}");
        }
        for bad in ["", "-", ".", "e5", "1e", "1.2.3", "abc", "1x"] {
            assert!(parse_f64(bad.as_bytes()).is_none(), "{bad}");
        }
        assert!(parse_f64(b"nan").unwrap().is_nan());
        assert!(parse_f64(b"-inf").unwrap().is_infinite());
        assert!(parse_f64(b"1e400").unwrap().is_infinite());
    }

    #[test]
    fn formatting_round_trips() {
        let mut buf = ryu::Buffer::new();
        for v in [0.1, -0.0, 1.0, 1e-300, 123456.789, f64::MAX, f64::MIN_POSITIVE, 1.0 / 3.0] {
            let mut out = Vec::new();
            push_f64(&mut out, &mut buf, v);
            let back = parse_f64(&out).unwrap();
            assert_eq!(back.to_bits(), v.to_bits(), "{}", String::from_utf8_lossy(&out));
        }
        let mut out = Vec::new();
        push_f64(&mut out, &mut buf, 2.0);
        push_u64(&mut out, 0);
        push_u64(&mut out, 4_294_967_295);
        assert_eq!(out, b"204294967295");
    }

    #[test]
    fn integers_and_tokens() {
        assert_eq!(parse_i64(b"-12"), Some(-12));
        assert_eq!(parse_i64(b"+3"), Some(3));
        assert_eq!(parse_i64(b"1/2"), None);
        assert_eq!(parse_i64(b"9999999999999999999"), None);
        assert_eq!(parse_u64(b"-0"), None);
        let t: Vec<&[u8]> = Tokens::new(b"  f 1/2/3\t4 5 \r").collect();
        assert_eq!(t, vec![&b"f"[..], b"1/2/3", b"4", b"5"]);
        assert_eq!(trim(b" \t x y \r"), b"x y");
        assert_eq!(trim(b"   "), b"");
    }
}

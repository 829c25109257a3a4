//! Decimal → `f64` for the motion block's hot loop.
//!
//! Clinger's fast path (W. D. Clinger, "How to read floating point numbers accurately",
//! PLDI 1990): when the decimal significand fits in 53 bits and the power of ten is at most
//! 10^22 (exactly representable), one IEEE multiplication or division is correctly rounded,
//! so the result equals the correctly rounded value. Every BVH exporter we know writes such
//! numbers; anything else falls back to the standard library's (also correctly rounded)
//! parser, so results are always bit-identical to `str::parse::<f64>`.

/// Exact powers of ten representable in an `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Whitespace between tokens: space, tab, CR, LF, vertical tab, form feed.
#[inline]
pub(crate) fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

/// End of the whitespace-delimited token starting at `start`.
#[inline]
pub(crate) fn token_end(src: &[u8], start: usize) -> usize {
    src.get(start..)
        .and_then(|rest| rest.iter().position(|&b| is_space(b)))
        .map_or(src.len(), |n| start + n)
}

/// Parse the whitespace-delimited token at `start` as a number. Returns the value (possibly
/// infinite or NaN: the caller decides) and the token's end, or `None` if the token is not a
/// number.
#[inline]
pub(crate) fn parse_number(src: &[u8], start: usize) -> Option<(f64, usize)> {
    if let Some(hit) = fast_path(src, start) {
        return Some(hit);
    }
    let end = token_end(src, start);
    let text = std::str::from_utf8(src.get(start..end)?).ok()?;
    text.parse::<f64>().ok().map(|v| (v, end))
}

/// Clinger's fast path for `[+-]digits[.digits][(e|E)[+-]digits]`; `None` means "use the
/// slow path", never "invalid".
#[inline]
fn fast_path(src: &[u8], start: usize) -> Option<(f64, usize)> {
    let (negative, mut i) = sign(src, start);
    let mut mantissa: u64 = 0;
    let mut digits = 0u32;
    let mut exponent: i64 = 0;
    while let Some(&b) = src.get(i) {
        if !b.is_ascii_digit() {
            break;
        }
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(b - b'0'));
        digits += 1;
        i += 1;
    }
    if src.get(i) == Some(&b'.') {
        i += 1;
        while let Some(&b) = src.get(i) {
            if !b.is_ascii_digit() {
                break;
            }
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(b - b'0'));
            digits += 1;
            exponent -= 1;
            i += 1;
        }
    }
    if digits == 0 || digits > 19 {
        return None;
    }
    if matches!(src.get(i), Some(b'e' | b'E')) {
        let (e, next) = exponent_part(src, i + 1)?;
        exponent += e;
        i = next;
    }
    if src.get(i).is_some_and(|&b| !is_space(b)) || mantissa > (1 << 53) {
        return None;
    }
    let value = mantissa as f64;
    let value = match exponent {
        0..=22 => value * POW10.get(exponent as usize)?,
        -22..=-1 => value / POW10.get((-exponent) as usize)?,
        _ => return None,
    };
    Some((if negative { -value } else { value }, i))
}

/// An optional `+` or `-` at `i`: whether it was `-`, and the index after it.
#[inline]
fn sign(src: &[u8], i: usize) -> (bool, usize) {
    match src.get(i) {
        Some(b'-') => (true, i + 1),
        Some(b'+') => (false, i + 1),
        _ => (false, i),
    }
}

/// `[+-]digits` after an `e`; saturates far outside the fast path's range.
#[inline]
fn exponent_part(src: &[u8], i: usize) -> Option<(i64, usize)> {
    let (negative, mut i) = sign(src, i);
    let first = i;
    let mut e: i64 = 0;
    while let Some(&b) = src.get(i) {
        if !b.is_ascii_digit() {
            break;
        }
        e = (e * 10 + i64::from(b - b'0')).min(1_000_000);
        i += 1;
    }
    if i == first {
        return None;
    }
    Some((if negative { -e } else { e }, i))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) {
        let ours = parse_number(text.as_bytes(), 0).map(|(v, end)| (v.to_bits(), end));
        let std = text.parse::<f64>().ok().map(|v| (v.to_bits(), text.len()));
        assert_eq!(ours, std, "{text}");
    }

    #[test]
    fn agrees_with_std_on_typical_and_edge_tokens() {
        for text in [
            "0",
            "-0",
            "-0.000000",
            "0.033333",
            ".0083333",
            "5.",
            "+5",
            "-224.689499",
            "1e-7",
            "1E21",
            "2.30145e-07",
            "9007199254740993",
            "12345678901234567890",
            "1e22",
            "1e23",
            "123.456e-30",
            "0.1",
            "4.9e-324",
            "1.7976931348623157e308",
            "1e999",
            "inf",
            "-infinity",
            "NaN",
            "nan",
            "-",
            ".",
            "e5",
            "1e",
            "1e+",
            "1.2.3",
            "--1",
            "1-2",
            "0x10",
            "1_0",
            "",
        ] {
            check(text);
        }
    }

    #[test]
    fn stops_at_whitespace() {
        assert_eq!(parse_number(b"1.5 2", 0), Some((1.5, 3)));
        assert_eq!(parse_number(b"-2\r\n", 0), Some((-2.0, 2)));
        assert_eq!(parse_number(b"7\t", 0), Some((7.0, 1)));
    }

    #[test]
    fn random_decimals_match_std() {
        // A deterministic LCG: no dependency, same inputs every run.
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            state >> 11
        };
        for _ in 0..20_000 {
            let int = next() % 100_000;
            let frac_digits = (next() % 12) as usize;
            let frac = next() % 10u64.pow(frac_digits as u32).max(1);
            let sign = if next() % 2 == 0 { "-" } else { "" };
            let exp = match next() % 4 {
                0 => format!("e{}", (next() % 60) as i64 - 30),
                _ => String::new(),
            };
            check(&format!("{sign}{int}.{frac:0frac_digits$}{exp}"));
            let v = f64::from_bits((next() << 11) | (next() % 2048));
            if v.is_finite() {
                check(ryu::Buffer::new().format(v));
            }
        }
    }
}

//! The `.npy` format (numpy's NEP 1, format versions 1.0–3.0): a magic string, a version, a
//! Python-literal header dict (`descr`, `fortran_order`, `shape`), then the raw data; and
//! the decoding of one element of each dtype.

use std::io::Read;

use crate::{Dtype, Problem};

pub(crate) const MAGIC: &[u8] = b"\x93NUMPY";

/// What a member's header says.
#[derive(Debug, Clone, PartialEq)]
pub struct Header {
    pub dtype: Dtype,
    /// Fortran (column-major) order: the first index varies fastest.
    pub fortran: bool,
    pub shape: Vec<usize>,
}

impl Header {
    /// Elements in the array (`None` when the shape overflows).
    #[must_use]
    pub fn count(&self) -> Option<usize> {
        self.shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d))
    }
}

impl Dtype {
    fn parse(descr: &str) -> Result<Dtype, Problem> {
        let bad = || Problem::Dtype(descr.to_owned());
        let mut chars = descr.chars();
        let (order, kind) = match (chars.next(), chars.next()) {
            (Some(o @ ('<' | '>' | '|' | '=')), Some(k)) => (o, k),
            _ => return Err(bad()),
        };
        let big = order == '>';
        let rest = chars.as_str();
        let width = || rest.parse::<usize>().map_err(|_| bad());
        Ok(match kind {
            'f' if matches!(width()?, 2 | 4 | 8) => Dtype::Float { width: width()?, big },
            'i' | 'u' if matches!(width()?, 1 | 2 | 4 | 8) => {
                Dtype::Int { width: width()?, signed: kind == 'i', big }
            }
            'b' if width()? == 1 => Dtype::Bool,
            'U' => Dtype::Unicode { chars: width()?, big },
            'S' => Dtype::Bytes(width()?),
            'O' => Dtype::Object,
            _ => return Err(bad()),
        })
    }

    /// Bytes per element (`None` for objects, and for string widths that overflow).
    pub(crate) fn width(self) -> Option<usize> {
        match self {
            Dtype::Float { width, .. } | Dtype::Int { width, .. } => Some(width),
            Dtype::Bool => Some(1),
            Dtype::Unicode { chars, .. } => chars.checked_mul(4),
            Dtype::Bytes(n) => Some(n),
            Dtype::Object => None,
        }
    }

    pub(crate) fn is_numeric(self) -> bool {
        matches!(self, Dtype::Float { .. } | Dtype::Int { .. } | Dtype::Bool)
    }

    pub(crate) fn is_string(self) -> bool {
        matches!(self, Dtype::Unicode { .. } | Dtype::Bytes(_))
    }
}

/// Reads the magic, version and header dict of an `.npy` stream (NEP 1).
pub(crate) fn read_header(data: &mut dyn Read) -> Result<Header, Problem> {
    let mut start = [0u8; 8];
    data.read_exact(&mut start).map_err(|_| Problem::NotNpy("too short"))?;
    if start.get(..6) != Some(MAGIC) {
        return Err(Problem::NotNpy("bad magic"));
    }
    let len = match start.get(6) {
        Some(1) => {
            let mut n = [0u8; 2];
            data.read_exact(&mut n).map_err(|_| Problem::TruncatedHeader)?;
            usize::from(u16::from_le_bytes(n))
        }
        Some(2 | 3) => {
            let mut n = [0u8; 4];
            data.read_exact(&mut n).map_err(|_| Problem::TruncatedHeader)?;
            u32::from_le_bytes(n) as usize
        }
        v => return Err(Problem::Version(v.copied().unwrap_or(0))),
    };
    // numpy's headers are at most a few hundred bytes; 64 KiB is far above any of them.
    if len > 1 << 16 {
        return Err(Problem::HugeHeader(len));
    }
    let mut text = vec![0u8; len];
    data.read_exact(&mut text).map_err(|_| Problem::TruncatedHeader)?;
    let text = String::from_utf8_lossy(&text);
    let descr = quoted_value(&text, "descr").ok_or(Problem::HeaderKey("descr"))?;
    let dtype = Dtype::parse(descr)?;
    let fortran = header_value(&text, "fortran_order").is_some_and(|v| v.starts_with("True"));
    let shape = parse_shape(&text).ok_or(Problem::HeaderKey("shape"))?;
    Ok(Header { dtype, fortran, shape })
}

/// The text after `'key':` in a header dict.
fn header_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header.find(&format!("'{key}'"))?;
    let rest = header.get(at + key.len() + 2..)?;
    Some(rest.trim_start().strip_prefix(':')?.trim_start())
}

fn quoted_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let v = header_value(header, key)?;
    let quote = v.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let v = v.get(1..)?;
    v.get(..v.find(quote)?)
}

fn parse_shape(header: &str) -> Option<Vec<usize>> {
    let v = header_value(header, "shape")?.strip_prefix('(')?;
    let inner = v.get(..v.find(')')?)?;
    inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse().ok())
        .collect()
}

/// One element of a numeric dtype (`bytes.len()` is its width).
pub(crate) fn decode_number(dtype: Dtype, bytes: &[u8]) -> f64 {
    let mut b = [0u8; 8];
    let n = bytes.len().min(8);
    if let (Some(dst), Some(src)) = (b.get_mut(..n), bytes.get(..n)) {
        dst.copy_from_slice(src);
    }
    let big = matches!(dtype, Dtype::Float { big: true, .. } | Dtype::Int { big: true, .. });
    if big {
        b.get_mut(..n).unwrap_or_default().reverse();
    }
    let u = u64::from_le_bytes(b);
    match dtype {
        Dtype::Float { width: 8, .. } => f64::from_bits(u),
        Dtype::Float { width: 4, .. } => f64::from(f32::from_bits(u as u32)),
        Dtype::Float { .. } => half_to_f64(u as u16),
        Dtype::Int { width, signed: true, .. } => {
            let shift = 64 - 8 * width as u32;
            (((u << shift) as i64) >> shift) as f64
        }
        Dtype::Int { .. } => u as f64,
        Dtype::Bool => f64::from(u8::from(u != 0)),
        Dtype::Unicode { .. } | Dtype::Bytes(_) | Dtype::Object => f64::NAN,
    }
}

/// IEEE half precision to f64 (numpy `<f2`).
fn half_to_f64(h: u16) -> f64 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f64::from(h & 0x3ff);
    sign * match exp {
        0 => frac * 2f64.powi(-24),
        31 if frac == 0.0 => f64::INFINITY,
        31 => f64::NAN,
        e => (1.0 + frac / 1024.0) * 2f64.powi(e - 15),
    }
}

/// One element of a string dtype, up to its first NUL.
pub(crate) fn decode_string(dtype: Dtype, bytes: &[u8]) -> Result<String, Problem> {
    match dtype {
        Dtype::Unicode { big, .. } => bytes
            .chunks_exact(4)
            .map(|c| {
                let mut u = [0u8; 4];
                u.copy_from_slice(c);
                if big {
                    u32::from_be_bytes(u)
                } else {
                    u32::from_le_bytes(u)
                }
            })
            .take_while(|&c| c != 0)
            .map(|c| char::from_u32(c).ok_or(Problem::Unicode))
            .collect(),
        Dtype::Bytes(_) => {
            let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
            Ok(String::from_utf8_lossy(bytes.get(..end).unwrap_or_default()).into_owned())
        }
        other => Err(Problem::Kind { dtype: other, expected: "strings" }),
    }
}

/// Fortran-order (first index fastest) values of an array of `shape`, in C order.
pub(crate) fn to_c_order<T: Clone + Default>(shape: &[usize], values: &[T]) -> Vec<T> {
    let mut out = Vec::with_capacity(values.len());
    let mut index = vec![0usize; shape.len()];
    for _ in 0..values.len() {
        // Fortran offset of the C-order multi-index.
        let mut offset = 0;
        let mut stride = 1;
        for (i, d) in index.iter().zip(shape) {
            offset += i * stride;
            stride *= d;
        }
        out.push(values.get(offset).cloned().unwrap_or_default());
        // Next C-order index: the last axis fastest.
        for (i, d) in index.iter_mut().zip(shape).rev() {
            *i += 1;
            if *i < *d {
                break;
            }
            *i = 0;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_and_descrs() {
        assert_eq!(half_to_f64(0x3c00), 1.0);
        assert_eq!(half_to_f64(0xc000), -2.0);
        for descr in ["<f8", ">f4", "<f2", "|i1", "|u1", "<i8", ">u4", "|b1", "<U12", ">U3", "|S6"]
        {
            assert_eq!(Dtype::parse(descr).unwrap().to_string(), descr);
        }
        assert_eq!(Dtype::parse("|O").unwrap(), Dtype::Object);
        assert_eq!(Dtype::parse("<c16"), Err(Problem::Dtype("<c16".to_owned())));
        assert_eq!(
            Dtype::parse("<U99999999999999999999"),
            Err(Problem::Dtype("<U99999999999999999999".to_owned()))
        );
    }

    #[test]
    fn fortran_order_is_transposed() {
        // [[1, 2, 3], [4, 5, 6]] column by column; element (i, j, k) of a 2×3×2 at i + 2j + 6k.
        assert_eq!(to_c_order(&[2, 3], &[1, 4, 2, 5, 3, 6]), [1, 2, 3, 4, 5, 6]);
        let f: Vec<usize> = (0..12).collect();
        let c = to_c_order(&[2, 3, 2], &f);
        assert_eq!(c[1], 6);
        assert_eq!(c[2], 2);
        assert_eq!(c[6], 1);
    }
}

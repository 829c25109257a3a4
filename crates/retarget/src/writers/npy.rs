//! numpy's `.npy` format (NEP 1, format versions 1.0–3.0): a magic string, a Python-literal
//! header dict (`descr`, `fortran_order`, `shape`) padded so the data starts at a multiple of
//! 64 bytes, then the raw C-order data. We write float64 (`<f8`), bool (`|b1`) and unicode
//! (`<U`n: n UTF-32LE code units per element, NUL-padded) arrays, as `numpy.save` does, and
//! read those plus `<f4`, `<i4`, `<i8` (converted to `f64`).

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

const MAGIC: &[u8] = b"\x93NUMPY";

/// Array contents.
#[derive(Debug, Clone, PartialEq)]
pub enum ArrayData {
    F64(Vec<f64>),
    Str(Vec<String>),
    /// numpy `bool` (`|b1`: one byte, 0 or 1).
    Bool(Vec<bool>),
}

/// An n-dimensional array in C order.
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    pub shape: Vec<usize>,
    pub data: ArrayData,
}

impl Array {
    /// A float64 array; `data.len()` must be the product of `shape`.
    #[must_use]
    pub fn f64(shape: Vec<usize>, data: Vec<f64>) -> Array {
        Array { shape, data: ArrayData::F64(data) }
    }

    /// A 1-D boolean array.
    #[must_use]
    pub fn bools(items: &[bool]) -> Array {
        Array { shape: vec![items.len()], data: ArrayData::Bool(items.to_vec()) }
    }

    /// A 1-D unicode array.
    #[must_use]
    pub fn strings(items: &[String]) -> Array {
        Array { shape: vec![items.len()], data: ArrayData::Str(items.to_vec()) }
    }

    /// A 0-d unicode array (numpy `np.array("text")`).
    #[must_use]
    pub fn scalar_string(text: &str) -> Array {
        Array { shape: vec![], data: ArrayData::Str(vec![text.to_owned()]) }
    }
}

/// The `.npy` bytes of `array`.
#[must_use]
pub(crate) fn encode(array: &Array) -> Vec<u8> {
    let (descr, width) = match &array.data {
        ArrayData::F64(_) => ("<f8".to_owned(), 8),
        ArrayData::Bool(_) => ("|b1".to_owned(), 1),
        ArrayData::Str(items) => {
            let n = items.iter().map(|s| s.chars().count()).max().unwrap_or(0).max(1);
            (format!("<U{n}"), n)
        }
    };
    let shape = match array.shape.as_slice() {
        [] => "()".to_owned(),
        [n] => format!("({n},)"),
        dims => format!("({})", dims.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
    };
    let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    // Spaces and a newline end the header so that the data starts 64-byte aligned. Version
    // 1.0 stores the header length as u16, version 2.0 (for huge headers only) as u32.
    let pad = |prefix: usize| (64 - (prefix + dict.len() + 1) % 64) % 64;
    let version: u8 = if dict.len() + pad(10) < usize::from(u16::MAX) { 1 } else { 2 };
    let header = format!("{dict}{}\n", " ".repeat(pad(if version == 1 { 10 } else { 12 })));
    let len_bytes = match version {
        1 => (header.len() as u16).to_le_bytes().to_vec(),
        _ => (header.len() as u32).to_le_bytes().to_vec(),
    };
    let mut out = Vec::with_capacity(header.len() + 16 + data_len(&array.data, width));
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[version, 0]);
    out.extend_from_slice(&len_bytes);
    out.extend_from_slice(header.as_bytes());
    match &array.data {
        ArrayData::F64(values) => {
            values.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()))
        }
        ArrayData::Bool(values) => out.extend(values.iter().map(|&v| u8::from(v))),
        ArrayData::Str(items) => {
            for item in items {
                let mut n = 0;
                for c in item.chars() {
                    out.extend_from_slice(&u32::from(c).to_le_bytes());
                    n += 1;
                }
                out.resize(out.len() + 4 * (width - n), 0);
            }
        }
    }
    out
}

fn data_len(data: &ArrayData, width: usize) -> usize {
    match data {
        ArrayData::F64(v) => v.len() * 8,
        ArrayData::Bool(v) => v.len(),
        ArrayData::Str(v) => v.len() * width * 4,
    }
}

/// Parses `.npy` bytes. Errors are messages for the caller to put a file name on. Every
/// allocation is bounded by `bytes.len()`: element counts read from the header are checked
/// against the data present before anything is allocated.
pub fn decode(bytes: &[u8]) -> Result<Array, String> {
    let (Some(magic), Some(&version)) = (bytes.get(..6), bytes.get(6)) else {
        return Err("not a .npy array (bad magic)".to_owned());
    };
    if magic != MAGIC {
        return Err("not a .npy array (bad magic)".to_owned());
    }
    let le = |range: std::ops::Range<usize>| -> Option<usize> {
        let raw = bytes.get(range)?;
        Some(raw.iter().rev().fold(0usize, |a, &b| (a << 8) | usize::from(b)))
    };
    let (header_len, start) = match version {
        1 => (le(8..10), 10),
        2 | 3 => (le(8..12), 12),
        v => return Err(format!("unsupported .npy format version {v}")),
    };
    let header_end = header_len.and_then(|n| n.checked_add(start));
    let (header, body) = header_end
        .and_then(|end| Some((bytes.get(start..end)?, bytes.get(end..)?)))
        .ok_or("truncated .npy header")?;
    let header = std::str::from_utf8(header).map_err(|_| "non-text .npy header")?;
    let descr = quoted_value(header, "descr").ok_or("no 'descr' in the .npy header")?;
    if header_value(header, "fortran_order").is_some_and(|v| v.starts_with("True")) {
        return Err("Fortran-order arrays are not supported".to_owned());
    }
    let shape = parse_shape(header).ok_or("no valid 'shape' in the .npy header")?;
    let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).ok_or("shape overflows")?;
    let data = decode_data(descr, body, count)?;
    Ok(Array { shape, data })
}

fn decode_data(descr: &str, body: &[u8], count: usize) -> Result<ArrayData, String> {
    let need = |width: usize| -> Result<&[u8], String> {
        count
            .checked_mul(width)
            .and_then(|n| body.get(..n))
            .ok_or_else(|| format!("array data truncated ({descr}, {count} elements)"))
    };
    let floats = |width: usize, f: &dyn Fn(&[u8]) -> f64| -> Result<ArrayData, String> {
        Ok(ArrayData::F64(need(width)?.chunks_exact(width).map(f).collect()))
    };
    match descr {
        "<f8" => floats(8, &|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))),
        "<f4" => floats(4, &|c| f64::from(f32::from_le_bytes(c.try_into().unwrap_or([0; 4])))),
        "<i8" => floats(8, &|c| i64::from_le_bytes(c.try_into().unwrap_or([0; 8])) as f64),
        "<i4" => floats(4, &|c| f64::from(i32::from_le_bytes(c.try_into().unwrap_or([0; 4])))),
        "|b1" => Ok(ArrayData::Bool(need(1)?.iter().map(|&b| b != 0).collect())),
        d if d.starts_with("<U") => {
            let width: usize =
                d.get(2..).and_then(|w| w.parse().ok()).ok_or_else(|| format!("bad dtype {d}"))?;
            if width == 0 {
                // Zero-width elements take no bytes, so the data cannot bound their count:
                // numpy never writes `<U0` with elements (it widens to `<U1`), and a count
                // larger than the member is a crafted file, not an array.
                if count > body.len() {
                    return Err(format!(
                        "dtype <U0 with {count} elements in {} bytes of data",
                        body.len()
                    ));
                }
                return Ok(ArrayData::Str(vec![String::new(); count]));
            }
            let raw = need(width.checked_mul(4).ok_or("bad unicode width")?)?;
            let mut items = Vec::with_capacity(count);
            for element in raw.chunks_exact(width * 4) {
                let mut s = String::new();
                for unit in element.chunks_exact(4) {
                    let code = unit.iter().rev().fold(0u32, |a, &b| (a << 8) | u32::from(b));
                    if code == 0 {
                        break;
                    }
                    s.push(char::from_u32(code).ok_or("invalid unicode in a string array")?);
                }
                items.push(s);
            }
            Ok(ArrayData::Str(items))
        }
        d => Err(format!("unsupported dtype {d} (expected <f8, <f4, <i8, <i4, |b1 or <U)")),
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_header_is_numpys() {
        let bytes = encode(&Array::f64(vec![2, 3], vec![0.5; 6]));
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with(" \n"));
        assert_eq!(bytes.len(), 10 + header_len + 48);
    }

    #[test]
    fn round_trips() {
        let arrays = [
            Array::f64(vec![], vec![30.0]),
            Array::f64(vec![1], vec![-0.0]),
            Array::f64(vec![2, 1, 2], vec![1e-300, f64::MAX, 0.1, -7.25]),
            Array::f64(vec![0, 3], vec![]),
            Array::strings(&["pelvis".to_owned(), "π_joint".to_owned(), String::new()]),
            Array::scalar_string("unitree_g1"),
            Array::strings(&[]),
        ];
        for a in arrays {
            assert_eq!(decode(&encode(&a)).unwrap(), a);
        }
    }

    #[test]
    fn unicode_width_is_the_longest_name() {
        let bytes = encode(&Array::strings(&["ab".to_owned(), "abcde".to_owned()]));
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("'descr': '<U5'"), "{text}");
        assert!(text.contains("'shape': (2,)"), "{text}");
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(decode(b"hello").is_err());
        let mut bytes = encode(&Array::f64(vec![4], vec![1.0; 4]));
        bytes.truncate(bytes.len() - 1);
        assert!(decode(&bytes).unwrap_err().contains("truncated"));
        for cut in 0..bytes.len() {
            assert!(decode(&bytes[..cut]).is_err(), "{cut}");
        }
    }

    /// A 128-byte member claiming 1e14 zero-width strings (24 bytes each in memory) used to
    /// abort the process on the allocation; now the count is checked against the data.
    #[test]
    fn zero_width_strings_cannot_claim_more_elements_than_bytes() {
        let header = "{'descr': '<U0', 'fortran_order': False, 'shape': (100000000000000,), }";
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        let err = decode(&bytes).unwrap_err();
        assert_eq!(err, "dtype <U0 with 100000000000000 elements in 0 bytes of data");
        // A header length past the end, and a version-2 length of 4 GiB: errors, no panic.
        let mut long = bytes.clone();
        long.splice(8..10, [0xff, 0xff]);
        assert_eq!(decode(&long).unwrap_err(), "truncated .npy header");
        let mut v2 = b"\x93NUMPY\x02\x00\xff\xff\xff\xff".to_vec();
        v2.extend_from_slice(header.as_bytes());
        assert_eq!(decode(&v2).unwrap_err(), "truncated .npy header");
    }
}

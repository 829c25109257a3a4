//! A whole array in memory, as read by [`crate::Npz::array`] and written by [`crate::write()`].

/// Array contents.
#[derive(Debug, Clone, PartialEq)]
pub enum ArrayData {
    /// Any numeric dtype but bool, as `f64` (written as `<f8`).
    F64(Vec<f64>),
    /// numpy `U` or `S` strings (written as `<U`n, n the longest).
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

    /// The numbers, if a numeric array (not bools).
    #[must_use]
    pub fn as_f64(&self) -> Option<&[f64]> {
        match &self.data {
            ArrayData::F64(v) => Some(v),
            ArrayData::Str(_) | ArrayData::Bool(_) => None,
        }
    }

    /// The strings, if a string array.
    #[must_use]
    pub fn as_strings(&self) -> Option<&[String]> {
        match &self.data {
            ArrayData::Str(v) => Some(v),
            ArrayData::F64(_) | ArrayData::Bool(_) => None,
        }
    }

    /// The bools, if a bool array.
    #[must_use]
    pub fn as_bools(&self) -> Option<&[bool]> {
        match &self.data {
            ArrayData::Bool(v) => Some(v),
            ArrayData::F64(_) | ArrayData::Str(_) => None,
        }
    }

    /// The `.npy` bytes of this array, as `numpy.save` writes them (NEP 1): magic, version,
    /// the header dict padded with spaces and a newline so that the data starts 64-byte
    /// aligned, then the C-order data (`<f8`, `|b1`, or `<U`n: n UTF-32LE code units per
    /// element, n the longest string (at least 1), NUL-padded).
    #[must_use]
    pub fn to_npy(&self) -> Vec<u8> {
        let (descr, width) = match &self.data {
            ArrayData::F64(_) => ("<f8".to_owned(), 8),
            ArrayData::Bool(_) => ("|b1".to_owned(), 1),
            ArrayData::Str(items) => {
                let n = items.iter().map(|s| s.chars().count()).max().unwrap_or(0).max(1);
                (format!("<U{n}"), n)
            }
        };
        let header = npy_header(&descr, &self.shape);
        let mut out = Vec::with_capacity(header.len() + data_len(&self.data, width));
        out.extend_from_slice(&header);
        match &self.data {
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
}

/// Magic, version, header length and the padded C-order header dict of an `.npy`.
fn npy_header(descr: &str, shape: &[usize]) -> Vec<u8> {
    let shape = match shape {
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
    let mut out = Vec::with_capacity(header.len() + 12);
    out.extend_from_slice(crate::npy::MAGIC);
    out.extend_from_slice(&[version, 0]);
    match version {
        1 => out.extend_from_slice(&(header.len() as u16).to_le_bytes()),
        _ => out.extend_from_slice(&(header.len() as u32).to_le_bytes()),
    }
    out.extend_from_slice(header.as_bytes());
    out
}

fn data_len(data: &ArrayData, width: usize) -> usize {
    match data {
        ArrayData::F64(v) => v.len() * 8,
        ArrayData::Bool(v) => v.len(),
        ArrayData::Str(v) => v.len() * width * 4,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_header_is_numpys() {
        let bytes = Array::f64(vec![2, 3], vec![0.5; 6]).to_npy();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with(" \n"));
        assert_eq!(bytes.len(), 10 + header_len + 48);
    }

    #[test]
    fn unicode_width_is_the_longest_name() {
        let bytes = Array::strings(&["ab".to_owned(), "abcde".to_owned()]).to_npy();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("'descr': '<U5'"), "{text}");
        assert!(text.contains("'shape': (2,)"), "{text}");
    }
}

//! Reading arrays out of numpy `.npz` files (a zip of `.npy` members), one member at a time
//! and only the members asked for: a body model's `posedirs` (122 MB in SMPL-X) is never
//! decompressed, and `shapedirs` (100 MB) is streamed row by row ([`Npz::rows`]).
//!
//! Why not `npyz` or `ndarray-npy`: both read a whole member into one typed array, so the
//! rows reader would still be ours, and a caller would still need a dispatch over the
//! dtypes real files use (`<f8`, `<f4`, `<i8`, `<i4`, `<u4`, …) to get `f64`s; `npyz`'s npz
//! support would also pull in a second `zip` version. The format itself is small (numpy's
//! NEP 1: magic, version, a Python-dict header, raw C- or Fortran-order data).
//!
//! Allocation: element counts come from headers, so nothing is allocated from them; buffers
//! grow with the data actually decompressed.

use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

use crate::Error;

/// An open `.npz` and the names of its members.
pub struct Npz<R: Read + Seek> {
    path: PathBuf,
    zip: zip::ZipArchive<R>,
}

/// What a member's header says.
#[derive(Debug, Clone, PartialEq)]
pub struct Header {
    pub dtype: Dtype,
    pub fortran: bool,
    pub shape: Vec<usize>,
}

impl Header {
    /// Elements in the array (`None` when the shape overflows).
    pub fn count(&self) -> Option<usize> {
        self.shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d))
    }
}

/// The element types a reader meets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    Float {
        width: usize,
        big: bool,
    },
    Int {
        width: usize,
        signed: bool,
        big: bool,
    },
    Bool,
    /// numpy `U<n>`: `n` UTF-32 code units.
    Unicode {
        chars: usize,
        big: bool,
    },
    /// numpy `S<n>`: `n` bytes.
    Bytes(usize),
    /// A pickled Python object array.
    Object,
}

impl Dtype {
    fn parse(descr: &str) -> Result<Dtype, String> {
        let bad = || format!("unsupported dtype `{descr}`");
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
    fn width(self) -> Option<usize> {
        match self {
            Dtype::Float { width, .. } | Dtype::Int { width, .. } => Some(width),
            Dtype::Bool => Some(1),
            Dtype::Unicode { chars, .. } => chars.checked_mul(4),
            Dtype::Bytes(n) => Some(n),
            Dtype::Object => None,
        }
    }

    fn is_numeric(self) -> bool {
        matches!(self, Dtype::Float { .. } | Dtype::Int { .. } | Dtype::Bool)
    }
}

/// Elements decoded per read: bounds the buffers of a streamed member.
const CHUNK: usize = 16 * 1024;

impl Npz<std::io::BufReader<std::fs::File>> {
    /// Opens the `.npz` at `path` (reads the zip directory only).
    pub fn open(path: &Path) -> Result<Self, Error> {
        let file = std::fs::File::open(path)
            .map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        Npz::new(std::io::BufReader::new(file), path)
    }
}

impl<R: Read + Seek> Npz<R> {
    /// An `.npz` read from `reader`; `path` names it in errors.
    pub fn new(reader: R, path: &Path) -> Result<Self, Error> {
        let zip = zip::ZipArchive::new(reader)
            .map_err(|e| Error::NotNpz { path: path.to_path_buf(), message: e.to_string() })?;
        Ok(Npz { path: path.to_path_buf(), zip })
    }

    /// The array names (members without `.npy`), in archive order.
    pub fn keys(&self) -> Vec<String> {
        self.zip.file_names().filter_map(|n| n.strip_suffix(".npy")).map(str::to_owned).collect()
    }

    pub fn has(&self, key: &str) -> bool {
        self.zip.index_for_name(&format!("{key}.npy")).is_some()
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    fn array_error(&self, key: &str, message: impl Into<String>) -> Error {
        Error::Array { path: self.path.clone(), key: key.to_owned(), message: message.into() }
    }

    /// Opens member `key`, reads its header and hands the header and the data stream to
    /// `read`.
    fn with_member<T>(
        &mut self,
        key: &str,
        read: impl FnOnce(&Header, &mut dyn Read, &dyn Fn(String) -> Error) -> Result<T, Error>,
    ) -> Result<T, Error> {
        let name = format!("{key}.npy");
        let path = self.path.clone();
        let Some(index) = self.zip.index_for_name(&name) else {
            return Err(Error::Missing { path, key: key.to_owned(), available: self.keys() });
        };
        let err =
            |message: String| Error::Array { path: path.clone(), key: key.to_owned(), message };
        let mut member = self.zip.by_index(index).map_err(|e| err(e.to_string()))?;
        let header = read_header(&mut member).map_err(&err)?;
        if header.dtype == Dtype::Object {
            return Err(Error::Pickled { path, key: key.to_owned() });
        }
        read(&header, &mut member, &err)
    }

    /// Only the header of member `key`.
    pub fn header(&mut self, key: &str) -> Result<Header, Error> {
        self.with_member(key, |h, _, _| Ok(h.clone()))
    }

    /// Member `key` as `f64`s in C order (floats, integers and bools converted), with its
    /// shape.
    pub fn floats(&mut self, key: &str) -> Result<(Vec<usize>, Vec<f64>), Error> {
        self.with_member(key, |header, data, err| {
            let mut out = Vec::new();
            stream(header, data, err, |chunk| out.extend_from_slice(chunk))?;
            if header.fortran {
                out = to_c_order(&header.shape, &out);
            }
            Ok((header.shape.clone(), out))
        })
    }

    /// Member `key` as integers in C order (integer and bool dtypes only), with its shape.
    pub fn ints(&mut self, key: &str) -> Result<(Vec<usize>, Vec<i64>), Error> {
        let header = self.header(key)?;
        if !matches!(header.dtype, Dtype::Int { .. } | Dtype::Bool) {
            return Err(self.array_error(key, format!("{:?}: expected integers", header.dtype)));
        }
        let (shape, values) = self.floats(key)?;
        // Every integer dtype up to 64 bits is exact in f64 below 2^53; larger ones (a
        // legacy uint32 −1 is 4294967295) stay far below it too.
        Ok((shape, values.into_iter().map(|v| v as i64).collect()))
    }

    /// Member `key` streamed in rows of `row` elements (C order): `each(row_index, values)`.
    /// Returns the shape. A Fortran-order member is read whole first.
    pub fn rows(
        &mut self,
        key: &str,
        row: usize,
        mut each: impl FnMut(usize, &[f64]),
    ) -> Result<Vec<usize>, Error> {
        if row == 0 {
            return Err(self.array_error(key, "rows of zero elements"));
        }
        let header = self.header(key)?;
        if header.fortran {
            let (shape, values) = self.floats(key)?;
            values.chunks_exact(row).enumerate().for_each(|(i, r)| each(i, r));
            return Ok(shape);
        }
        self.with_member(key, |header, data, err| {
            let mut pending: Vec<f64> = Vec::with_capacity(row.min(CHUNK * 4));
            let mut index = 0;
            stream(header, data, err, |chunk| {
                let mut chunk = chunk;
                while !chunk.is_empty() {
                    let take = (row - pending.len()).min(chunk.len());
                    let (now, later) = chunk.split_at(take);
                    pending.extend_from_slice(now);
                    chunk = later;
                    if pending.len() == row {
                        each(index, &pending);
                        index += 1;
                        pending.clear();
                    }
                }
            })?;
            if !pending.is_empty() {
                return Err(err(format!("{} elements are not rows of {row}", header.count_str())));
            }
            Ok(header.shape.clone())
        })
    }

    /// Member `key` as strings (numpy `U` or `S`), in C order.
    pub fn strings(&mut self, key: &str) -> Result<Vec<String>, Error> {
        self.with_member(key, |header, data, err| {
            let width = header.dtype.width().ok_or_else(|| err("bad string width".into()))?;
            let count = header.count().ok_or_else(|| err("shape overflows".into()))?;
            let mut out = Vec::new();
            let mut element = vec![0u8; width.min(1 << 20)];
            if element.len() != width {
                return Err(err(format!("strings of {width} bytes")));
            }
            for _ in 0..count {
                data.read_exact(&mut element).map_err(|e| err(truncated(&e, count)))?;
                out.push(decode_string(header.dtype, &element).map_err(&err)?);
            }
            Ok(out)
        })
    }
}

impl Header {
    fn count_str(&self) -> String {
        self.count().map_or_else(|| "an overflowing number of".to_owned(), |c| c.to_string())
    }
}

fn truncated(e: &std::io::Error, count: usize) -> String {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        format!("data truncated (fewer than the {count} elements of its shape)")
    } else {
        format!("cannot read the data: {e}")
    }
}

/// Decodes the numeric data of a member in chunks, handing each to `out`.
fn stream(
    header: &Header,
    data: &mut dyn Read,
    err: &dyn Fn(String) -> Error,
    mut out: impl FnMut(&[f64]),
) -> Result<(), Error> {
    let dtype = header.dtype;
    if !dtype.is_numeric() {
        return Err(err(format!("{dtype:?}: expected numbers")));
    }
    let width = dtype.width().unwrap_or(8);
    let count = header.count().ok_or_else(|| err("shape overflows".into()))?;
    let mut bytes = vec![0u8; CHUNK * width];
    let mut values = Vec::with_capacity(CHUNK);
    let mut left = count;
    while left > 0 {
        let n = left.min(CHUNK);
        let raw = bytes.get_mut(..n * width).unwrap_or_default();
        data.read_exact(raw).map_err(|e| err(truncated(&e, count)))?;
        values.clear();
        values.extend(raw.chunks_exact(width).map(|c| decode_number(dtype, c)));
        out(&values);
        left -= n;
    }
    Ok(())
}

/// One element of a numeric dtype (`bytes.len()` is its width).
fn decode_number(dtype: Dtype, bytes: &[u8]) -> f64 {
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

fn decode_string(dtype: Dtype, bytes: &[u8]) -> Result<String, String> {
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
            .map(|c| char::from_u32(c).ok_or_else(|| "invalid unicode".to_owned()))
            .collect(),
        Dtype::Bytes(_) => {
            let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
            Ok(String::from_utf8_lossy(bytes.get(..end).unwrap_or_default()).into_owned())
        }
        other => Err(format!("{other:?}: expected strings")),
    }
}

/// Reads the magic, version and header dict of an `.npy` stream (NEP 1).
fn read_header(data: &mut dyn Read) -> Result<Header, String> {
    let mut start = [0u8; 8];
    data.read_exact(&mut start).map_err(|_| "not a .npy array (too short)".to_owned())?;
    if start.get(..6) != Some(b"\x93NUMPY".as_slice()) {
        return Err("not a .npy array (bad magic)".to_owned());
    }
    let len = match start.get(6) {
        Some(1) => {
            let mut n = [0u8; 2];
            data.read_exact(&mut n).map_err(|_| "truncated .npy header".to_owned())?;
            usize::from(u16::from_le_bytes(n))
        }
        Some(2 | 3) => {
            let mut n = [0u8; 4];
            data.read_exact(&mut n).map_err(|_| "truncated .npy header".to_owned())?;
            u32::from_le_bytes(n) as usize
        }
        v => return Err(format!("unsupported .npy format version {v:?}")),
    };
    // numpy's headers are at most a few hundred bytes; 64 KiB is far above any of them.
    if len > 1 << 16 {
        return Err(format!("a .npy header of {len} bytes"));
    }
    let mut text = vec![0u8; len];
    data.read_exact(&mut text).map_err(|_| "truncated .npy header".to_owned())?;
    let text = String::from_utf8_lossy(&text);
    let descr = quoted_value(&text, "descr").ok_or("no 'descr' in the .npy header")?;
    let dtype = Dtype::parse(descr)?;
    let fortran = header_value(&text, "fortran_order").is_some_and(|v| v.starts_with("True"));
    let shape = parse_shape(&text).ok_or("no valid 'shape' in the .npy header")?;
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

/// Fortran-order (first index fastest) values of an array of `shape`, in C order.
fn to_c_order(shape: &[usize], values: &[f64]) -> Vec<f64> {
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
        out.push(values.get(offset).copied().unwrap_or(f64::NAN));
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
pub(crate) mod tests {
    use super::*;
    use std::io::{Cursor, Write};

    /// An `.npy` member: header dict text and raw data.
    pub fn npy(descr: &str, shape: &[usize], fortran: bool, data: &[u8]) -> Vec<u8> {
        let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
        let shape = match dims.len() {
            1 => format!("({},)", dims[0]),
            _ => format!("({})", dims.join(", ")),
        };
        let order = if fortran { "True" } else { "False" };
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}");
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(data);
        out
    }

    pub fn f8(values: &[f64]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    /// A zip of named members, deflated.
    pub fn npz(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
        let mut out = zip::ZipWriter::new(Cursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        for (name, bytes) in members {
            out.start_file(format!("{name}.npy"), options).unwrap();
            out.write_all(bytes).unwrap();
        }
        out.finish().unwrap().into_inner()
    }

    fn open(bytes: Vec<u8>) -> Npz<Cursor<Vec<u8>>> {
        Npz::new(Cursor::new(bytes), Path::new("t.npz")).unwrap()
    }

    #[test]
    fn dtypes_are_converted_and_fortran_order_transposed() {
        let i4: Vec<u8> = [-1i32, 2, 3].iter().flat_map(|v| v.to_le_bytes()).collect();
        let u4: Vec<u8> = [4294967295u32, 7].iter().flat_map(|v| v.to_le_bytes()).collect();
        let f4: Vec<u8> = [0.5f32, -2.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let be: Vec<u8> = [1.25f64].iter().flat_map(|v| v.to_be_bytes()).collect();
        // [[1, 2, 3], [4, 5, 6]] written column by column.
        let fortran = f8(&[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]);
        let mut z = open(npz(&[
            ("i4", npy("<i4", &[3], false, &i4)),
            ("u4", npy("<u4", &[2], false, &u4)),
            ("f4", npy("<f4", &[2], false, &f4)),
            ("be", npy(">f8", &[], false, &be)),
            ("ft", npy("<f8", &[2, 3], true, &fortran)),
            ("s", npy("<U4", &[], false, &[b'm', 0, 0, 0, b'a', 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0])),
            ("b", npy("|S6", &[], false, b"female")),
            ("o", npy("|O", &[], false, b"\x80\x02")),
        ]));
        assert_eq!(z.ints("i4").unwrap(), (vec![3], vec![-1, 2, 3]));
        assert_eq!(z.ints("u4").unwrap().1, vec![4294967295, 7]);
        assert_eq!(z.floats("f4").unwrap().1, vec![0.5, -2.0]);
        assert_eq!(z.floats("be").unwrap(), (vec![], vec![1.25]));
        assert_eq!(z.floats("ft").unwrap().1, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(z.strings("s").unwrap(), ["ma"]);
        assert_eq!(z.strings("b").unwrap(), ["female"]);
        assert!(matches!(z.floats("o"), Err(Error::Pickled { .. })));
        assert!(matches!(z.ints("f4"), Err(Error::Array { .. })));
        let missing = z.floats("nope").unwrap_err().to_string();
        assert!(missing.starts_with("t.npz: no `nope` array (the file has: i4, u4"), "{missing}");
        let mut rows = Vec::new();
        z.rows("ft", 3, |i, r| rows.push((i, r.to_vec()))).unwrap();
        assert_eq!(rows, [(0, vec![1.0, 2.0, 3.0]), (1, vec![4.0, 5.0, 6.0])]);
    }

    #[test]
    fn rows_stream_across_chunks() {
        let n = CHUNK * 2 + 7;
        let values: Vec<f64> = (0..n * 3).map(|v| v as f64).collect();
        let mut z = open(npz(&[("a", npy("<f8", &[n, 3], false, &f8(&values)))]));
        let mut seen = 0;
        let shape = z
            .rows("a", 3, |i, r| {
                assert_eq!(r, &values[3 * i..3 * i + 3]);
                seen += 1;
            })
            .unwrap();
        assert_eq!((shape, seen), (vec![n, 3], n));
        assert!(z.rows("a", 4, |_, _| {}).is_err());
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            Npz::new(Cursor::new(b"PK nonsense".to_vec()), Path::new("x")),
            Err(Error::NotNpz { .. })
        ));
        let full = npy("<f8", &[4], false, &f8(&[1.0; 4]));
        for cut in 0..full.len() {
            let mut z = open(npz(&[("a", full[..cut].to_vec())]));
            assert!(z.floats("a").is_err(), "{cut}");
        }
        // A huge shape in a tiny member: an error, no allocation from the count.
        let mut z = open(npz(&[("a", npy("<f8", &[1 << 40, 1 << 20], false, &[0; 16]))]));
        assert!(z.floats("a").unwrap_err().to_string().contains("truncated"));
        let mut z = open(npz(&[("a", npy("<c16", &[1], false, &[0; 16]))]));
        assert!(z.floats("a").unwrap_err().to_string().contains("unsupported dtype"));
        assert_eq!(half_to_f64(0x3c00), 1.0);
        assert_eq!(half_to_f64(0xc000), -2.0);
    }
}

//! Reading an `.npz` one member at a time ([`Npz`]).

use std::collections::BTreeMap;
use std::io::Read;
use std::io::Seek;
use std::path::{Path, PathBuf};

use crate::npy::{decode_number, decode_string, read_header, to_c_order};
use crate::{Array, ArrayData, Dtype, Error, Header, Problem};

/// An open `.npz` and the names of its members.
pub struct Npz<R: Read + Seek> {
    path: PathBuf,
    zip: zip::ZipArchive<R>,
}

/// Elements decoded per read: bounds the buffers of a streamed member.
const CHUNK: usize = 16 * 1024;

/// The widest string element read (1 MiB): far above any name or label.
const MAX_STRING_BYTES: usize = 1 << 20;

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

    /// Whether the file has array `key`.
    pub fn has(&self, key: &str) -> bool {
        self.zip.index_for_name(&format!("{key}.npy")).is_some()
    }

    /// The file's name, as given.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Member `key` as `f64`s in C order (floats, integers and bools converted), with its
    /// shape.
    pub fn floats(&mut self, key: &str) -> Result<(Vec<usize>, Vec<f64>), Error> {
        self.with_member(key, |header, data| Ok((header.shape.clone(), floats(header, data)?)))
    }

    /// Member `key` as integers in C order (integer and bool dtypes only), with its shape.
    pub fn ints(&mut self, key: &str) -> Result<(Vec<usize>, Vec<i64>), Error> {
        self.with_member(key, |header, data| {
            if !matches!(header.dtype, Dtype::Int { .. } | Dtype::Bool) {
                return Err(Problem::Kind { dtype: header.dtype, expected: "integers" });
            }
            // Every integer dtype up to 64 bits is exact in f64 below 2^53; larger ones (a
            // legacy uint32 −1 is 4294967295) stay far below it too.
            let values = floats(header, data)?;
            Ok((header.shape.clone(), values.into_iter().map(|v| v as i64).collect()))
        })
    }

    /// Member `key` as strings (numpy `U` or `S`), in C order.
    pub fn strings(&mut self, key: &str) -> Result<Vec<String>, Error> {
        self.with_member(key, strings)
    }

    /// Only the header of member `key`.
    pub fn header(&mut self, key: &str) -> Result<Header, Error> {
        self.with_member(key, |h, _| Ok(h.clone()))
    }

    /// Member `key` streamed in rows of `row` elements (C order): `each(row_index, values)`.
    /// Returns the shape. A Fortran-order member is read whole first.
    pub fn rows(
        &mut self,
        key: &str,
        row: usize,
        mut each: impl FnMut(usize, &[f64]),
    ) -> Result<Vec<usize>, Error> {
        self.with_member(key, |header, data| {
            if row == 0 {
                return Err(Problem::Rows { count: header.count().unwrap_or(0), row });
            }
            if header.fortran {
                let values = floats(header, data)?;
                if values.len() % row != 0 {
                    return Err(Problem::Rows { count: values.len(), row });
                }
                values.chunks_exact(row).enumerate().for_each(|(i, r)| each(i, r));
                return Ok(header.shape.clone());
            }
            let mut pending: Vec<f64> = Vec::with_capacity(row.min(CHUNK * 4));
            let mut index = 0;
            stream(header, data, |chunk| {
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
                return Err(Problem::Rows { count: header.count().unwrap_or(0), row });
            }
            Ok(header.shape.clone())
        })
    }

    /// Member `key` whole: numbers as `f64`, bools as bools, strings as strings, C order.
    pub fn array(&mut self, key: &str) -> Result<Array, Error> {
        self.with_member(key, array)
    }

    /// Every `.npy` member, by key (other members are skipped).
    pub fn arrays(&mut self) -> Result<BTreeMap<String, Array>, Error> {
        let mut out = BTreeMap::new();
        for index in 0..self.zip.len() {
            let Some(key) = self.zip.name_for_index(index).and_then(|n| n.strip_suffix(".npy"))
            else {
                continue;
            };
            let key = key.to_owned();
            let value = self.with_index(index, &key, array)?;
            out.insert(key, value);
        }
        Ok(out)
    }

    /// Opens member `key`, reads its header and hands the header and the data stream to
    /// `read`; a problem becomes an error naming the file and the member.
    fn with_member<T>(
        &mut self,
        key: &str,
        read: impl FnOnce(&Header, &mut dyn Read) -> Result<T, Problem>,
    ) -> Result<T, Error> {
        let Some(index) = self.zip.index_for_name(&format!("{key}.npy")) else {
            return Err(Error::Missing {
                path: self.path.clone(),
                key: key.to_owned(),
                available: self.keys(),
            });
        };
        self.with_index(index, key, read)
    }

    fn with_index<T>(
        &mut self,
        index: usize,
        key: &str,
        read: impl FnOnce(&Header, &mut dyn Read) -> Result<T, Problem>,
    ) -> Result<T, Error> {
        let path = &self.path;
        let error = |problem| Error::Array { path: path.clone(), key: key.to_owned(), problem };
        let mut member =
            self.zip.by_index(index).map_err(|e| error(Problem::Member(e.to_string())))?;
        let header = read_header(&mut member).map_err(error)?;
        if header.dtype == Dtype::Object {
            return Err(Error::Pickled { path: path.clone(), key: key.to_owned() });
        }
        read(&header, &mut member).map_err(error)
    }
}

/// A whole member by its dtype.
fn array(header: &Header, data: &mut dyn Read) -> Result<Array, Problem> {
    let data = match header.dtype {
        Dtype::Bool => ArrayData::Bool(floats(header, data)?.iter().map(|&v| v != 0.0).collect()),
        d if d.is_string() => ArrayData::Str(strings(header, data)?),
        _ => ArrayData::F64(floats(header, data)?),
    };
    Ok(Array { shape: header.shape.clone(), data })
}

/// The numbers of a member, in C order.
fn floats(header: &Header, data: &mut dyn Read) -> Result<Vec<f64>, Problem> {
    let mut out = Vec::new();
    stream(header, data, |chunk| out.extend_from_slice(chunk))?;
    Ok(if header.fortran { to_c_order(&header.shape, &out) } else { out })
}

/// The strings of a member, in C order. Zero-width elements are checked against the bytes
/// present, as nothing else bounds their count.
fn strings(header: &Header, data: &mut dyn Read) -> Result<Vec<String>, Problem> {
    let dtype = header.dtype;
    if !dtype.is_string() {
        return Err(Problem::Kind { dtype, expected: "strings" });
    }
    let width = dtype.width().ok_or(Problem::Dtype(dtype.to_string()))?;
    let count = header.count().ok_or(Problem::ShapeOverflows)?;
    if width == 0 {
        let bytes = std::io::copy(&mut data.take(count as u64), &mut std::io::sink())
            .map_err(|e| Problem::Read(e.to_string()))?;
        if (bytes as usize) < count {
            return Err(Problem::ZeroWidth { dtype, count, bytes });
        }
    }
    if width > MAX_STRING_BYTES {
        return Err(Problem::StringWidth(width));
    }
    let mut out = Vec::new();
    let mut element = vec![0u8; width];
    for _ in 0..count {
        data.read_exact(&mut element).map_err(|e| truncated(&e, count))?;
        out.push(decode_string(dtype, &element)?);
    }
    Ok(if header.fortran { to_c_order(&header.shape, &out) } else { out })
}

fn truncated(e: &std::io::Error, count: usize) -> Problem {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        Problem::Truncated { count }
    } else {
        Problem::Read(e.to_string())
    }
}

/// Decodes the numeric data of a member in chunks, handing each to `out`.
fn stream(
    header: &Header,
    data: &mut dyn Read,
    mut out: impl FnMut(&[f64]),
) -> Result<(), Problem> {
    let dtype = header.dtype;
    if !dtype.is_numeric() {
        return Err(Problem::Kind { dtype, expected: "numbers" });
    }
    let width = dtype.width().unwrap_or(8);
    let count = header.count().ok_or(Problem::ShapeOverflows)?;
    let mut bytes = vec![0u8; CHUNK * width];
    let mut values = Vec::with_capacity(CHUNK);
    let mut left = count;
    while left > 0 {
        let n = left.min(CHUNK);
        let raw = bytes.get_mut(..n * width).unwrap_or_default();
        data.read_exact(raw).map_err(|e| truncated(&e, count))?;
        values.clear();
        values.extend(raw.chunks_exact(width).map(|c| decode_number(dtype, c)));
        out(&values);
        left -= n;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Cursor, Write};

    /// An `.npy` member: header dict text and raw data (any descr and order, unpadded).
    fn npy(descr: &str, shape: &str, fortran: bool, data: &[u8]) -> Vec<u8> {
        let order = if fortran { "True" } else { "False" };
        let header =
            format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}\n");
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(data);
        out
    }

    fn f8(values: &[f64]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    /// A zip of named members, deflated.
    fn npz(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
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
        let u4_text = [b'm', 0, 0, 0, b'a', 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        let mut z = open(npz(&[
            ("i4", npy("<i4", "(3,)", false, &i4)),
            ("u4", npy("<u4", "(2,)", false, &u4)),
            ("f4", npy("<f4", "(2,)", false, &f4)),
            ("be", npy(">f8", "()", false, &be)),
            ("ft", npy("<f8", "(2, 3)", true, &fortran)),
            ("s", npy("<U4", "()", false, &u4_text)),
            ("b", npy("|S6", "()", false, b"female")),
            ("o", npy("|O", "()", false, b"\x80\x02")),
            ("bo", npy("|b1", "(2, 2)", true, &[1, 0, 0, 1])),
        ]));
        assert_eq!(z.ints("i4").unwrap(), (vec![3], vec![-1, 2, 3]));
        assert_eq!(z.ints("u4").unwrap().1, vec![4294967295, 7]);
        assert_eq!(z.floats("f4").unwrap().1, vec![0.5, -2.0]);
        assert_eq!(z.floats("be").unwrap(), (vec![], vec![1.25]));
        assert_eq!(z.floats("ft").unwrap().1, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(z.strings("s").unwrap(), ["ma"]);
        assert_eq!(z.strings("b").unwrap(), ["female"]);
        assert!(matches!(z.floats("o"), Err(Error::Pickled { .. })));
        let err = z.ints("f4").unwrap_err().to_string();
        assert_eq!(err, "t.npz: array `f4`: dtype <f4: expected integers");
        let missing = z.floats("nope").unwrap_err().to_string();
        assert!(missing.starts_with("t.npz: no `nope` array (the file has: i4, u4"), "{missing}");
        let mut rows = Vec::new();
        z.rows("ft", 3, |i, r| rows.push((i, r.to_vec()))).unwrap();
        assert_eq!(rows, [(0, vec![1.0, 2.0, 3.0]), (1, vec![4.0, 5.0, 6.0])]);
        assert_eq!(
            z.array("bo").unwrap(),
            Array { shape: vec![2, 2], data: ArrayData::Bool(vec![true, false, false, true]) }
        );
        assert_eq!(z.array("i4").unwrap(), Array::f64(vec![3], vec![-1.0, 2.0, 3.0]));
        assert_eq!(
            z.array("b").unwrap(),
            Array { shape: vec![], data: ArrayData::Str(vec!["female".to_owned()]) }
        );
        let all = z.arrays();
        assert!(matches!(all, Err(Error::Pickled { ref key, .. }) if key == "o"), "{all:?}");
    }

    #[test]
    fn rows_stream_across_chunks() {
        let n = CHUNK * 2 + 7;
        let values: Vec<f64> = (0..n * 3).map(|v| v as f64).collect();
        let mut z = open(npz(&[("a", npy("<f8", &format!("({n}, 3)"), false, &f8(&values)))]));
        let mut seen = 0;
        let shape = z
            .rows("a", 3, |i, r| {
                assert_eq!(r, &values[3 * i..3 * i + 3]);
                seen += 1;
            })
            .unwrap();
        assert_eq!((shape, seen), (vec![n, 3], n));
        assert!(z.rows("a", 4, |_, _| {}).is_err());
        assert!(z.rows("a", 0, |_, _| {}).is_err());
    }

    #[test]
    fn written_arrays_read_back() {
        let arrays = [
            ("fps", Array::f64(vec![1], vec![30.0])),
            ("scalar", Array::f64(vec![], vec![30.0])),
            ("neg_zero", Array::f64(vec![1], vec![-0.0])),
            ("wide", Array::f64(vec![2, 1, 2], vec![1e-300, f64::MAX, 0.1, -7.25])),
            ("empty", Array::f64(vec![0, 3], vec![])),
            ("names", Array::strings(&["pelvis".to_owned(), "π_joint".to_owned(), String::new()])),
            ("robot", Array::scalar_string("unitree_g1")),
            ("none", Array::strings(&[])),
            ("contact", Array::bools(&[true, false, false, true])),
        ];
        let mut buf = Cursor::new(Vec::new());
        crate::write(&mut buf, &arrays).unwrap();
        let mut z = open(buf.into_inner());
        assert_eq!(z.keys(), arrays.iter().map(|(k, _)| k.to_string()).collect::<Vec<_>>());
        let back = z.arrays().unwrap();
        for (key, array) in &arrays {
            assert_eq!(&back[*key], array, "{key}");
        }
    }

    /// Every count read from a file is checked against the bytes that hold it: a crafted
    /// header is an error naming the member, not an allocation (issue 15: a 256-byte `.npz`
    /// whose member claimed 1e14 `<U0` strings made a reader allocate 2.4 PB and abort).
    #[test]
    fn crafted_headers_are_errors_not_allocations() {
        let cases = [
            (
                "<U0",
                "(100000000000000,)",
                "dtype <U0 with 100000000000000 elements in 16 bytes of data",
            ),
            (
                "<U4",
                "(100000000000000,)",
                "data truncated (fewer than the 100000000000000 elements of its shape)",
            ),
            ("<f8", "(4294967296, 65536)", "data truncated"),
            ("<f8", "(1099511627776, 1048576)", "data truncated"),
            ("<f8", "(4294967296, 4294967296, 4294967296)", "shape overflows"),
            ("<U99999999999999999999", "(1,)", "unsupported dtype `<U99999999999999999999`"),
            ("<U999999999", "(1,)", "strings of 3999999996 bytes"),
            ("<c16", "(1,)", "unsupported dtype `<c16`"),
        ];
        for (descr, shape, expected) in cases {
            let mut z = open(npz(&[("joint_names", npy(descr, shape, false, &[0; 16]))]));
            let err = z.array("joint_names").unwrap_err().to_string();
            assert!(err.starts_with("t.npz: array `joint_names`: "), "{err}");
            assert!(err.contains(expected), "{descr} {shape}: {err}");
            assert!(z.arrays().is_err());
        }
        // A header length past the end, a version-2 length of 4 GiB, an unknown version.
        let header = "{'descr': '<U0', 'fortran_order': False, 'shape': (1,), }";
        let mut long = b"\x93NUMPY\x01\x00\xff\xff".to_vec();
        long.extend_from_slice(header.as_bytes());
        let mut v2 = b"\x93NUMPY\x02\x00\xff\xff\xff\xff".to_vec();
        v2.extend_from_slice(header.as_bytes());
        let mut v9 = b"\x93NUMPY\x09\x00\x10\x00".to_vec();
        v9.extend_from_slice(header.as_bytes());
        let mut z = open(npz(&[("long", long), ("v2", v2), ("v9", v9)]));
        assert_eq!(
            z.array("long").unwrap_err().to_string(),
            "t.npz: array `long`: truncated .npy header"
        );
        assert_eq!(
            z.array("v2").unwrap_err().to_string(),
            "t.npz: array `v2`: a .npy header of 4294967295 bytes"
        );
        assert!(z
            .array("v9")
            .unwrap_err()
            .to_string()
            .ends_with("unsupported .npy format version 9"));
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            Npz::new(Cursor::new(b"PK nonsense".to_vec()), Path::new("x")),
            Err(Error::NotNpz { .. })
        ));
        let full = Array::f64(vec![4], vec![1.0; 4]).to_npy();
        for cut in 0..full.len() {
            let mut z = open(npz(&[("a", full[..cut].to_vec())]));
            assert!(z.floats("a").is_err(), "{cut}");
            assert!(z.array("a").is_err(), "{cut}");
        }
        let names = Array::strings(&["ab".to_owned(), "c".to_owned()]).to_npy();
        for cut in 0..names.len() {
            let mut z = open(npz(&[("a", names[..cut].to_vec())]));
            assert!(z.strings("a").is_err(), "{cut}");
        }
        let mut z = open(npz(&[("a", npy("<U1", "(1,)", false, &0xd800u32.to_le_bytes()))]));
        assert!(z
            .strings("a")
            .unwrap_err()
            .to_string()
            .ends_with("invalid unicode in a string array"));
        let err = Npz::open(Path::new("/nonexistent/m.npz")).err().unwrap();
        assert!(matches!(err, Error::Io { .. }), "{err}");
    }
}

//! A small `.npz` reader for the Blender oracle (float64/float32/int32 as `f64`, bool,
//! unicode; C or Fortran order): only what the tests need.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

#[derive(Debug, Clone)]
pub enum Data {
    F64(Vec<f64>),
    Bool(Vec<bool>),
    Str(Vec<String>),
}

#[derive(Debug, Clone)]
pub struct Array {
    pub data: Data,
}

impl Array {
    pub fn f64(&self) -> &[f64] {
        match &self.data {
            Data::F64(v) => v,
            other => panic!("not numbers: {other:?}"),
        }
    }
    pub fn bools(&self) -> &[bool] {
        match &self.data {
            Data::Bool(v) => v,
            other => panic!("not bools: {other:?}"),
        }
    }
    pub fn strings(&self) -> &[String] {
        match &self.data {
            Data::Str(v) => v,
            other => panic!("not strings: {other:?}"),
        }
    }
}

pub fn read(path: &Path) -> BTreeMap<String, Array> {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut zip = zip::ZipArchive::new(file).unwrap();
    let mut out = BTreeMap::new();
    for i in 0..zip.len() {
        let mut member = zip.by_index(i).unwrap();
        let name = member.name().trim_end_matches(".npy").to_owned();
        let mut bytes = Vec::new();
        member.read_to_end(&mut bytes).unwrap();
        out.insert(name, decode(&bytes));
    }
    out
}

fn decode(bytes: &[u8]) -> Array {
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        _ => (u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, 12),
    };
    let header = std::str::from_utf8(&bytes[start..start + len]).unwrap();
    let body = &bytes[start + len..];
    let field = |key: &str| {
        let at = header.find(&format!("'{key}'")).unwrap() + key.len() + 3;
        header[at..].trim_start().to_owned()
    };
    let descr = field("descr");
    let descr = descr.trim_start_matches('\'').split('\'').next().unwrap().to_owned();
    let fortran = field("fortran_order").starts_with("True");
    let shape_text = field("shape");
    let shape: Vec<usize> = shape_text[1..shape_text.find(')').unwrap()]
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let count: usize = shape.iter().product();
    let mut data = match descr.as_str() {
        "<f8" => Data::F64(
            body.chunks_exact(8)
                .take(count)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect(),
        ),
        "<f4" => Data::F64(
            body.chunks_exact(4)
                .take(count)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
        ),
        "<i4" => Data::F64(
            body.chunks_exact(4)
                .take(count)
                .map(|c| i32::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
        ),
        "|b1" => Data::Bool(body.iter().take(count).map(|&b| b != 0).collect()),
        d if d.starts_with("<U") => {
            let width: usize = d[2..].parse().unwrap();
            Data::Str(
                body.chunks_exact(width * 4)
                    .take(count)
                    .map(|e| {
                        e.chunks_exact(4)
                            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
                            .take_while(|&c| c != 0)
                            .map(|c| char::from_u32(c).unwrap())
                            .collect()
                    })
                    .collect(),
            )
        }
        d => panic!("dtype {d}"),
    };
    if fortran && shape.len() == 2 {
        if let Data::F64(v) = &data {
            let (r, c) = (shape[0], shape[1]);
            data = Data::F64((0..r * c).map(|k| v[(k % c) * r + k / c]).collect());
        }
    }
    Array { data }
}

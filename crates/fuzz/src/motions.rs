//! Targets for other tools' robot motions (issue 39): GMR's pickle and Unitree's CSV, read by
//! `retarget::writers::read_motion_bytes` for the G1, then the quality report. The pickle
//! generator writes what Python's `pickle` writes for GMR's dict of numpy arrays in each of
//! numpy's ways (`_reconstruct` or `ndarray` + `BUILD`, protocol 5's `_frombuffer`), with
//! memo references, frames and dtypes varied; wild inputs add foreign globals and stray
//! opcodes.

use std::path::Path;

use arbitrary::{Arbitrary, Result, Unstructured};

use crate::generate::{g1, num_value, Num};
use crate::seeds::files;
use crate::Target;

fn report(motion: &retarget::RobotMotion) -> std::result::Result<(), String> {
    let options = retarget::report::ReportOptions::default();
    let report = retarget::report::report(motion, g1(), &options).map_err(|e| e.to_string())?;
    let _ = format!("{report:?}");
    Ok(())
}

/// A value near `base` most of the time; extreme ones only when `wild`.
fn near(u: &mut Unstructured<'_>, base: f64, wild: bool) -> Result<f64> {
    Ok(match Num::arbitrary(u)? {
        Num::Tenths(t) => base + f64::from(t) * 1e-3,
        Num::Small(t) => base + f64::from(t) * 1e-2,
        other if wild => num_value(other),
        _ => base,
    })
}

// ------------------------------------------------------------------------------------------
// GMR's pickle

/// A pickle being written with protocol 2–5 opcodes.
struct Pickler {
    out: Vec<u8>,
    protocol: u8,
    memo: u32,
}

impl Pickler {
    fn memoize(&mut self, u: &mut Unstructured<'_>) -> Result<()> {
        if self.protocol >= 4 && u.ratio(3, 4)? {
            self.out.push(0x94);
        } else if u.ratio(1, 2)? {
            self.out.push(b'q');
            self.out.push(self.memo as u8);
        } else {
            self.out.push(b'r');
            self.out.extend_from_slice(&self.memo.to_le_bytes());
        }
        self.memo += 1;
        Ok(())
    }

    fn string(&mut self, s: &str) {
        if self.protocol >= 4 && s.len() < 256 {
            self.out.extend_from_slice(&[0x8c, s.len() as u8]);
        } else {
            self.out.push(b'X');
            self.out.extend_from_slice(&(s.len() as u32).to_le_bytes());
        }
        self.out.extend_from_slice(s.as_bytes());
    }

    fn int(&mut self, v: i64) {
        match v {
            0..=255 => self.out.extend_from_slice(&[b'K', v as u8]),
            256..=65535 => {
                self.out.push(b'M');
                self.out.extend_from_slice(&(v as u16).to_le_bytes());
            }
            _ => match i32::try_from(v) {
                Ok(small) => {
                    self.out.push(b'J');
                    self.out.extend_from_slice(&small.to_le_bytes());
                }
                Err(_) => {
                    self.out.extend_from_slice(&[0x8a, 8]);
                    self.out.extend_from_slice(&v.to_le_bytes());
                }
            },
        }
    }

    fn global(&mut self, module: &str, name: &str) {
        if self.protocol >= 4 {
            self.string(module);
            self.string(name);
            self.out.push(0x93);
        } else {
            self.out.push(b'c');
            self.out.extend_from_slice(format!("{module}\n{name}\n").as_bytes());
        }
    }

    fn bytes(&mut self, raw: &[u8], bytearray: bool) {
        if bytearray {
            self.out.push(0x96);
            self.out.extend_from_slice(&(raw.len() as u64).to_le_bytes());
        } else if raw.len() < 256 {
            self.out.extend_from_slice(&[b'C', raw.len() as u8]);
        } else {
            self.out.push(b'B');
            self.out.extend_from_slice(&(raw.len() as u32).to_le_bytes());
        }
        self.out.extend_from_slice(raw);
    }

    /// `numpy.dtype(code, False, True)` with numpy's `BUILD` state.
    fn dtype(&mut self, code: &str, order: &str) {
        self.global("numpy", "dtype");
        self.string(code);
        self.out.extend_from_slice(&[0x89, 0x88, 0x87, b'R', b'(']);
        self.int(3);
        self.string(order);
        self.out.extend_from_slice(b"NNN");
        self.int(-1);
        self.int(-1);
        self.int(0);
        self.out.extend_from_slice(b"tb");
    }

    fn shape(&mut self, shape: &[usize]) {
        self.out.push(b'(');
        for &d in shape {
            self.int(d as i64);
        }
        self.out.push(b't');
    }
}

#[derive(Debug, Arbitrary)]
struct ArraySpec {
    /// 0: `_reconstruct`, 1: `ndarray`, 2: `_frombuffer`.
    way: u8,
    dtype: u8,
    fortran: bool,
    /// Replaces a dimension (a shape that does not match the data or the model).
    bad_dim: Option<(u8, u8)>,
}

pub struct PickleTarget;

impl PickleTarget {
    fn array(
        p: &mut Pickler,
        u: &mut Unstructured<'_>,
        shape: &[usize],
        values: &[f64],
        wild: bool,
    ) -> Result<()> {
        let spec = ArraySpec::arbitrary(u)?;
        const DTYPES: &[(&str, &str)] = &[("f8", "<"), ("f4", "<"), ("<f8", "|"), ("f8", ">")];
        const WILD: &[(&str, &str)] =
            &[("i8", "<"), ("u1", "|"), ("b1", "|"), ("U4", "<"), ("O", "|")];
        let (code, order) = if wild && u.ratio(1, 8)? {
            WILD[usize::from(spec.dtype) % WILD.len()]
        } else {
            DTYPES[usize::from(spec.dtype) % DTYPES.len()]
        };
        let big = order == ">" || code.starts_with('>');
        let raw: Vec<u8> = match code {
            "f4" => values
                .iter()
                .flat_map(
                    |&v| if big { (v as f32).to_be_bytes() } else { (v as f32).to_le_bytes() },
                )
                .collect(),
            _ => values
                .iter()
                .flat_map(|&v| if big { v.to_be_bytes() } else { v.to_le_bytes() })
                .collect(),
        };
        let mut shape = shape.to_vec();
        if let (true, Some((at, d))) = (wild, spec.bad_dim) {
            let i = usize::from(at) % shape.len().max(1);
            if let Some(slot) = shape.get_mut(i) {
                *slot = usize::from(d % 40);
            }
        }
        match spec.way % 3 {
            2 => {
                p.global("numpy._core.numeric", "_frombuffer");
                p.out.push(b'(');
                p.bytes(&raw, true);
                p.dtype(code, order);
                p.shape(&shape);
                p.string(if spec.fortran { "F" } else { "C" });
                p.out.extend_from_slice(b"tR");
            }
            way => {
                if way == 0 {
                    p.global("numpy.core.multiarray", "_reconstruct");
                    p.global("numpy", "ndarray");
                    p.int(0);
                    p.out.push(0x85);
                    p.bytes(b"b", false);
                    p.out.extend_from_slice(&[0x87, b'R']);
                } else {
                    p.global("numpy", "ndarray");
                    p.int(0);
                    p.out.extend_from_slice(&[0x85, 0x85, b'R']);
                }
                p.memoize(u)?;
                p.out.push(b'(');
                p.int(1);
                p.shape(&shape);
                p.dtype(code, order);
                p.out.push(if spec.fortran { 0x88 } else { 0x89 });
                p.bytes(&raw, false);
                p.out.extend_from_slice(b"tb");
            }
        }
        p.memoize(u)
    }

    fn fps(p: &mut Pickler, u: &mut Unstructured<'_>, wild: bool) -> Result<()> {
        let fps = if wild { num_value(Num::arbitrary(u)?) } else { 30.0 };
        match u.int_in_range(0..=3)? {
            0 => p.int(fps as i64),
            1 => {
                p.global("numpy.core.multiarray", "scalar");
                p.dtype("f8", "<");
                p.bytes(&fps.to_le_bytes(), false);
                p.out.extend_from_slice(&[0x86, b'R']);
            }
            2 if wild => p.out.push(b'N'),
            _ => {
                p.out.push(b'G');
                p.out.extend_from_slice(&fps.to_be_bytes());
            }
        }
        Ok(())
    }

    fn make(u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let model = g1();
        let wild = u.ratio(1, 4)?;
        let protocol = [2u8, 3, 4, 5][u.choose_index(4)?];
        let frames = u.int_in_range(1..=5)?;
        let joints = model.nq - 7;
        let mut p = Pickler { out: vec![0x80, protocol], protocol, memo: 0 };
        if protocol >= 4 {
            p.out.push(0x95);
            p.out.extend_from_slice(&0u64.to_le_bytes());
        }
        p.out.push(b'}');
        p.memoize(u)?;
        p.out.push(b'(');
        p.string("fps");
        Self::fps(&mut p, u, wild)?;
        let mut root_pos = Vec::new();
        let mut root_rot = Vec::new();
        let mut dof_pos = Vec::new();
        for _ in 0..frames {
            for base in [0.0, 0.0, 0.79] {
                root_pos.push(near(u, base, wild)?);
            }
            for base in [0.0, 0.0, 0.0, 1.0] {
                root_rot.push(near(u, base, wild)?);
            }
            for base in model.qpos0.iter().skip(7) {
                dof_pos.push(near(u, *base, wild)?);
            }
        }
        p.string("root_pos");
        Self::array(&mut p, u, &[frames, 3], &root_pos, wild)?;
        p.string("root_rot");
        Self::array(&mut p, u, &[frames, 4], &root_rot, wild)?;
        p.string("dof_pos");
        Self::array(&mut p, u, &[frames, joints], &dof_pos, wild)?;
        p.string("local_body_pos");
        p.out.push(b'N');
        p.string("link_body_list");
        if u.arbitrary()? {
            p.out.extend_from_slice(b"](");
            for b in model.bodies.iter().skip(1).take(4) {
                p.string(&b.name);
            }
            p.out.push(b'e');
        } else {
            p.out.push(b'N');
        }
        p.out.push(b'u');
        if wild && u.ratio(1, 4)? {
            // A foreign callable, or a stray opcode, where a value goes.
            const GLOBALS: &[(&str, &str)] =
                &[("os", "system"), ("posix", "system"), ("builtins", "eval"), ("numpy", "load")];
            let (m, n) = GLOBALS[u.choose_index(GLOBALS.len())?];
            p.string("extra");
            p.global(m, n);
            p.string("echo");
            p.out.extend_from_slice(&[0x85, b'R', b's']);
        }
        p.out.push(b'.');
        Ok(p.out)
    }
}

impl Target for PickleTarget {
    fn name(&self) -> &'static str {
        "pickle"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let mut seeds = files("crates/retarget/tests/data/gmr", ".pkl");
        let mut u = Unstructured::new(&[3; 4096]);
        seeds.extend(Self::make(&mut u).ok());
        seeds
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        Self::make(u)
    }

    #[rustfmt::skip]
    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "\u{80}\u{4}", "\u{95}", "}", "(", "t", "u", "R", "b", ".", "N", "cos\nsystem\n",
            "numpy", "_reconstruct", "_frombuffer", "dtype", "fps", "root_rot", "dof_pos",
            "\u{8c}", "\u{94}", "h\u{0}", "j\u{0}\u{0}\u{0}\u{0}",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let (motion, _) =
            retarget::writers::read_motion_bytes(input, Path::new("fuzz.pkl"), g1(), None)
                .map_err(|e| e.to_string())?;
        report(&motion)
    }
}

// ------------------------------------------------------------------------------------------
// Unitree's CSV

pub struct CsvTarget;

impl CsvTarget {
    fn make(u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let model = g1();
        let wild = u.ratio(1, 4)?;
        let frames = u.int_in_range(1..=6)?;
        let mut out = String::new();
        let mut bases = vec![0.0, 0.0, 0.79, 0.0, 0.0, 0.0, 1.0];
        bases.extend(model.qpos0.iter().skip(7));
        for _ in 0..frames {
            let mut width = bases.len();
            if wild && u.ratio(1, 8)? {
                width = u.int_in_range(0..=40)?;
            }
            for k in 0..width {
                if k > 0 {
                    out.push_str(if wild && u.ratio(1, 16)? { ", " } else { "," });
                }
                let base = bases.get(k).copied().unwrap_or(0.0);
                if wild && u.ratio(1, 32)? {
                    Num::arbitrary(u)?.write(&mut out, true);
                } else {
                    out.push_str(&format!("{}", near(u, base, wild)?));
                }
            }
            out.push_str(if wild && u.ratio(1, 8)? { "\r\n" } else { "\n" });
            if wild && u.ratio(1, 16)? {
                out.push('\n');
            }
        }
        Ok(out.into_bytes())
    }
}

impl Target for CsvTarget {
    fn name(&self) -> &'static str {
        "csv"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let mut u = Unstructured::new(&[5; 4096]);
        Self::make(&mut u).ok().into_iter().collect()
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        Self::make(u)
    }

    fn dictionary(&self) -> &'static [&'static str] {
        &[",", "\n", "\r\n", "nan", "inf", "1e308", "-0", " ", "\u{feff}", "0.5"]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let (motion, _) =
            retarget::writers::read_motion_bytes(input, Path::new("fuzz.csv"), g1(), Some(30.0))
                .map_err(|e| e.to_string())?;
        report(&motion)
    }
}

//! Reading pickles without executing them: a pickle virtual machine for the opcodes Python's
//! `pickle` (protocols 2–5) emits for a dict of numpy arrays, strings, numbers and lists
//! (GMR's motion files), after `pickletools`' opcode table (CPython `Lib/pickletools.py`).
//!
//! Nothing is imported or called. `GLOBAL` / `STACK_GLOBAL` name a callable; only those
//! numpy uses to rebuild arrays, dtypes and scalars are accepted, and their `REDUCE` / `BUILD`
//! are interpreted here as data:
//! - `numpy.core.multiarray._reconstruct` (or `numpy._core…`, numpy 2) and `numpy.ndarray`,
//!   then `BUILD` with numpy's state `(version, shape, dtype, is_fortran, raw bytes)`;
//! - `numpy.core.numeric._frombuffer` (or `numpy._core…`): protocol 5's
//!   `(buffer, dtype, shape, order)`;
//! - `numpy.dtype` (`BUILD` state `(3, byte order, …)`), `numpy.core.multiarray.scalar`
//!   (`(dtype, raw bytes)`: a numpy scalar such as a `float64` fps);
//! - `_codecs.encode(text, 'latin1')` and `builtins.bytes()`: how protocol 2 writes bytes.
//!
//! Any other global is refused with its name and byte offset. Values live in one arena and
//! the stack, memo and containers hold indices into it, so `GET` copies nothing: every
//! allocation is bounded by the input's size (each opcode adds at most one node, each node
//! holds at most what its opcode read), and nothing recurses.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::borrow::Cow;
use std::collections::HashMap;

/// Deepest nesting of `MARK`s accepted (Python has none; a dict of arrays needs 3).
const MAX_MARKS: usize = 1000;

/// An index into the arena.
pub(crate) type Id = usize;

/// The callables a pickle may name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Callable {
    /// `_reconstruct` or `ndarray`: an empty array, filled by `BUILD`.
    NewArray,
    /// `_frombuffer(buffer, dtype, shape, order)`.
    FromBuffer,
    Dtype,
    Scalar,
    /// `_codecs.encode(text, 'latin1')`.
    Latin1,
    /// `bytes()`.
    EmptyBytes,
}

/// One value.
#[derive(Debug, Clone)]
pub(crate) enum Node<'a> {
    None,
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(Cow<'a, str>),
    Bytes(Cow<'a, [u8]>),
    Tuple(Vec<Id>),
    List(Vec<Id>),
    Dict(Vec<(Id, Id)>),
    Global(Callable),
    /// A numpy array: its `BUILD` state once built.
    Array {
        state: Option<Id>,
    },
    /// `_frombuffer`'s arguments.
    Buffer {
        buffer: Id,
        dtype: Id,
        shape: Id,
        order: Id,
    },
    /// A dtype: its code (`'f8'`, `'<f4'`) and the byte order of its `BUILD` state.
    Dtype {
        code: Id,
        order: Option<Id>,
    },
    /// A numpy scalar: dtype and raw bytes.
    Scalar {
        dtype: Id,
        bytes: Id,
    },
}

/// A failure and the byte offset of the opcode.
#[derive(Debug)]
pub(crate) struct UnpickleError {
    pub offset: usize,
    pub message: String,
}

impl std::fmt::Display for UnpickleError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "byte {}: {}", self.offset, self.message)
    }
}

/// The values of one pickle; `root` is what `STOP` returned.
#[derive(Debug)]
pub(crate) struct Pickle<'a> {
    nodes: Vec<Node<'a>>,
    pub root: Id,
}

impl<'a> Pickle<'a> {
    pub(crate) fn get(&self, id: Id) -> Option<&Node<'a>> {
        self.nodes.get(id)
    }
}

struct Vm<'a> {
    input: &'a [u8],
    pos: usize,
    /// Offset of the opcode being run (for errors).
    at: usize,
    nodes: Vec<Node<'a>>,
    stack: Vec<Id>,
    marks: Vec<usize>,
    memo: HashMap<u64, Id>,
}

/// Runs the pickle in `input` to its `STOP`.
pub(crate) fn unpickle(input: &[u8]) -> Result<Pickle<'_>, UnpickleError> {
    let mut vm = Vm {
        input,
        pos: 0,
        at: 0,
        nodes: Vec::new(),
        stack: Vec::new(),
        marks: Vec::new(),
        memo: HashMap::new(),
    };
    loop {
        vm.at = vm.pos;
        let op = vm.take(1)?.first().copied().unwrap_or(0);
        if op == b'.' {
            let root = vm.pop()?;
            return Ok(Pickle { nodes: vm.nodes, root });
        }
        vm.step(op)?;
    }
}

impl<'a> Vm<'a> {
    fn fail<T>(&self, message: impl Into<String>) -> Result<T, UnpickleError> {
        Err(UnpickleError { offset: self.at, message: message.into() })
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], UnpickleError> {
        let input: &'a [u8] = self.input;
        match self.pos.checked_add(n).and_then(|end| input.get(self.pos..end).map(|s| (s, end))) {
            Some((slice, end)) => {
                self.pos = end;
                Ok(slice)
            }
            None => self.fail(format!("truncated: needs {n} more bytes, the file ends first")),
        }
    }

    fn uint(&mut self, n: usize) -> Result<u64, UnpickleError> {
        Ok(self.take(n)?.iter().rev().fold(0u64, |a, &b| (a << 8) | u64::from(b)))
    }

    /// A length read from the file, checked against what is left of it.
    fn len(&mut self, n: usize) -> Result<usize, UnpickleError> {
        let len = self.uint(n)?;
        let left = self.input.len().saturating_sub(self.pos);
        match usize::try_from(len) {
            Ok(len) if len <= left => Ok(len),
            _ => self.fail(format!("a length of {len} bytes, only {left} left in the file")),
        }
    }

    fn line(&mut self) -> Result<&'a str, UnpickleError> {
        let rest = self.input.get(self.pos..).unwrap_or_default();
        let Some(end) = rest.iter().position(|&b| b == b'\n') else {
            return self.fail("a text argument without its newline");
        };
        let line = rest.get(..end).unwrap_or_default();
        self.pos += end + 1;
        match std::str::from_utf8(line) {
            Ok(s) => Ok(s),
            Err(_) => self.fail("a text argument that is not UTF-8"),
        }
    }

    fn push(&mut self, node: Node<'a>) {
        self.stack.push(self.nodes.len());
        self.nodes.push(node);
    }

    fn pop(&mut self) -> Result<Id, UnpickleError> {
        match self.stack.pop() {
            Some(id) => Ok(id),
            None => self.fail("stack underflow"),
        }
    }

    fn top(&self) -> Result<Id, UnpickleError> {
        match self.stack.last() {
            Some(&id) => Ok(id),
            None => self.fail("stack underflow"),
        }
    }

    /// The items pushed since the last `MARK`, which is removed.
    fn pop_mark(&mut self) -> Result<Vec<Id>, UnpickleError> {
        let Some(mark) = self.marks.pop() else { return self.fail("no MARK before this opcode") };
        if mark > self.stack.len() {
            return self.fail("the stack was popped past its MARK");
        }
        Ok(self.stack.split_off(mark))
    }

    fn pop_n(&mut self, n: usize) -> Result<Vec<Id>, UnpickleError> {
        let Some(start) = self.stack.len().checked_sub(n) else {
            return self.fail("stack underflow");
        };
        if self.marks.last().is_some_and(|&m| m > start) {
            return self.fail("a tuple reaches past a MARK");
        }
        Ok(self.stack.split_off(start))
    }

    fn text(&mut self, n: usize) -> Result<(), UnpickleError> {
        let len = self.len(n)?;
        let raw = self.take(len)?;
        match std::str::from_utf8(raw) {
            Ok(s) => {
                self.push(Node::Str(Cow::Borrowed(s)));
                Ok(())
            }
            Err(_) => self.fail("a string that is not UTF-8"),
        }
    }

    fn bytes(&mut self, n: usize) -> Result<(), UnpickleError> {
        let len = self.len(n)?;
        let raw = self.take(len)?;
        self.push(Node::Bytes(Cow::Borrowed(raw)));
        Ok(())
    }

    fn memo_put(&mut self, key: u64) -> Result<(), UnpickleError> {
        let top = self.top()?;
        self.memo.insert(key, top);
        Ok(())
    }

    fn memo_get(&mut self, key: u64) -> Result<(), UnpickleError> {
        match self.memo.get(&key) {
            Some(&id) => {
                self.stack.push(id);
                Ok(())
            }
            None => self.fail(format!("memo key {key} was never stored")),
        }
    }

    fn decimal(&mut self) -> Result<u64, UnpickleError> {
        let line = self.line()?;
        match line.trim().parse() {
            Ok(v) => Ok(v),
            Err(_) => self.fail(format!("bad memo key {line:?}")),
        }
    }

    fn step(&mut self, op: u8) -> Result<(), UnpickleError> {
        match op {
            0x80 => {
                let proto = self.uint(1)?;
                if proto > 5 {
                    return self.fail(format!("pickle protocol {proto} (at most 5 is known)"));
                }
            }
            0x95 => {
                self.uint(8)?; // FRAME: a length hint for buffered readers
            }
            b'(' => {
                if self.marks.len() >= MAX_MARKS {
                    return self.fail(format!("more than {MAX_MARKS} nested MARKs"));
                }
                self.marks.push(self.stack.len());
            }
            b'0' => {
                self.pop()?;
            }
            b'1' => {
                self.pop_mark()?;
            }
            b'N' => self.push(Node::None),
            0x88 => self.push(Node::Bool(true)),
            0x89 => self.push(Node::Bool(false)),
            b'J' => {
                let v = self.uint(4)? as u32 as i32;
                self.push(Node::Int(i64::from(v)));
            }
            b'K' => {
                let v = self.uint(1)?;
                self.push(Node::Int(v as i64));
            }
            b'M' => {
                let v = self.uint(2)?;
                self.push(Node::Int(v as i64));
            }
            0x8a => self.long1()?,
            b'G' => {
                let raw = self.take(8)?;
                let v = f64::from_be_bytes(raw.try_into().unwrap_or([0; 8]));
                self.push(Node::Float(v));
            }
            b'X' => self.text(4)?,
            0x8c => self.text(1)?,
            0x8d => self.text(8)?,
            b'B' => self.bytes(4)?,
            b'C' => self.bytes(1)?,
            0x8e | 0x96 => self.bytes(8)?,
            b'}' => self.push(Node::Dict(Vec::new())),
            b']' => self.push(Node::List(Vec::new())),
            b')' => self.push(Node::Tuple(Vec::new())),
            b't' => {
                let items = self.pop_mark()?;
                self.push(Node::Tuple(items));
            }
            b'l' => {
                let items = self.pop_mark()?;
                self.push(Node::List(items));
            }
            0x85..=0x87 => {
                let items = self.pop_n(usize::from(op - 0x84))?;
                self.push(Node::Tuple(items));
            }
            b'a' => {
                let item = self.pop()?;
                self.extend_list(vec![item])?;
            }
            b'e' => {
                let items = self.pop_mark()?;
                self.extend_list(items)?;
            }
            b's' => {
                let items = self.pop_n(2)?;
                self.extend_dict(items)?;
            }
            b'u' => {
                let items = self.pop_mark()?;
                self.extend_dict(items)?;
            }
            b'p' => {
                let key = self.decimal()?;
                self.memo_put(key)?;
            }
            b'q' => {
                let key = self.uint(1)?;
                self.memo_put(key)?;
            }
            b'r' => {
                let key = self.uint(4)?;
                self.memo_put(key)?;
            }
            0x94 => {
                let key = self.memo.len() as u64;
                self.memo_put(key)?;
            }
            b'g' => {
                let key = self.decimal()?;
                self.memo_get(key)?;
            }
            b'h' => {
                let key = self.uint(1)?;
                self.memo_get(key)?;
            }
            b'j' => {
                let key = self.uint(4)?;
                self.memo_get(key)?;
            }
            b'c' => {
                let module = self.line()?;
                let name = self.line()?;
                self.global(module, name)?;
            }
            0x93 => {
                let name = self.pop()?;
                let module = self.pop()?;
                match (self.nodes.get(module), self.nodes.get(name)) {
                    (Some(Node::Str(m)), Some(Node::Str(n))) => {
                        let (m, n) = (m.clone(), n.clone());
                        self.global(&m, &n)?;
                    }
                    _ => return self.fail("STACK_GLOBAL without two strings"),
                }
            }
            b'R' => self.reduce()?,
            b'b' => self.build()?,
            _ => return self.fail(unsupported(op)),
        }
        Ok(())
    }

    fn long1(&mut self) -> Result<(), UnpickleError> {
        let n = self.len(1)?;
        let raw = self.take(n)?;
        if n > 8 {
            return self.fail(format!("an integer of {n} bytes (at most 8 are read)"));
        }
        // Little-endian two's complement, sign-extended from its last byte.
        let negative = raw.last().is_some_and(|&b| b & 0x80 != 0);
        let mut v: u64 = if negative { u64::MAX } else { 0 };
        for (k, &b) in raw.iter().enumerate() {
            v = (v & !(0xff << (8 * k))) | (u64::from(b) << (8 * k));
        }
        self.push(Node::Int(v as i64));
        Ok(())
    }

    fn extend_list(&mut self, items: Vec<Id>) -> Result<(), UnpickleError> {
        let list = self.top()?;
        match self.nodes.get_mut(list) {
            Some(Node::List(v)) => {
                v.extend(items);
                Ok(())
            }
            _ => self.fail("APPEND to something that is not a list"),
        }
    }

    fn extend_dict(&mut self, items: Vec<Id>) -> Result<(), UnpickleError> {
        if !items.len().is_multiple_of(2) {
            return self.fail("SETITEMS with a key and no value");
        }
        let dict = self.top()?;
        match self.nodes.get_mut(dict) {
            Some(Node::Dict(v)) => {
                v.extend(items.chunks_exact(2).filter_map(|kv| Some((*kv.first()?, *kv.get(1)?))));
                Ok(())
            }
            _ => self.fail("SETITEM on something that is not a dict"),
        }
    }

    fn global(&mut self, module: &str, name: &str) -> Result<(), UnpickleError> {
        let callable = match (module, name) {
            ("numpy.core.multiarray" | "numpy._core.multiarray", "_reconstruct")
            | ("numpy", "ndarray") => Callable::NewArray,
            ("numpy.core.numeric" | "numpy._core.numeric", "_frombuffer") => Callable::FromBuffer,
            ("numpy", "dtype") => Callable::Dtype,
            ("numpy.core.multiarray" | "numpy._core.multiarray", "scalar") => Callable::Scalar,
            ("_codecs", "encode") => Callable::Latin1,
            ("__builtin__" | "builtins", "bytes") => Callable::EmptyBytes,
            _ => {
                return self.fail(format!(
                    "the pickle calls `{module}.{name}`, which is not a numpy array, dtype or \
                     scalar: refused (nothing is executed)"
                ))
            }
        };
        self.push(Node::Global(callable));
        Ok(())
    }

    fn reduce(&mut self) -> Result<(), UnpickleError> {
        let args = self.pop()?;
        let callable = self.pop()?;
        let (Some(Node::Global(callable)), Some(Node::Tuple(args))) =
            (self.nodes.get(callable), self.nodes.get(args))
        else {
            return self.fail("REDUCE without a known callable and an argument tuple");
        };
        let node = match (*callable, args.as_slice()) {
            (Callable::NewArray, _) => Node::Array { state: None },
            (Callable::FromBuffer, &[buffer, dtype, shape, order]) => {
                Node::Buffer { buffer, dtype, shape, order }
            }
            (Callable::Dtype, &[code, ..]) => Node::Dtype { code, order: None },
            (Callable::Scalar, &[dtype, bytes]) => Node::Scalar { dtype, bytes },
            (Callable::Latin1, &[text, encoding]) => self.latin1(text, encoding)?,
            (Callable::EmptyBytes, &[]) => Node::Bytes(Cow::Borrowed(&[])),
            (c, a) => return self.fail(format!("{c:?} with {} arguments", a.len())),
        };
        self.push(node);
        Ok(())
    }

    /// `_codecs.encode(text, 'latin1')`: protocol 2's bytes, one code point per byte.
    fn latin1(&self, text: Id, encoding: Id) -> Result<Node<'a>, UnpickleError> {
        let (Some(Node::Str(text)), Some(Node::Str(encoding))) =
            (self.nodes.get(text), self.nodes.get(encoding))
        else {
            return self.fail("_codecs.encode without two strings");
        };
        if !matches!(encoding.as_ref(), "latin1" | "latin-1" | "iso-8859-1") {
            return self.fail(format!("_codecs.encode to {encoding:?} (only latin1 is read)"));
        }
        let bytes: Option<Vec<u8>> =
            text.chars().map(|c| u8::try_from(u32::from(c)).ok()).collect();
        match bytes {
            Some(b) => Ok(Node::Bytes(Cow::Owned(b))),
            None => self.fail("latin1 text with a character above U+00FF"),
        }
    }

    fn build(&mut self) -> Result<(), UnpickleError> {
        let state = self.pop()?;
        let target = self.top()?;
        match self.nodes.get_mut(target) {
            Some(Node::Array { state: s @ None }) => *s = Some(state),
            Some(Node::Dtype { order: o @ None, .. }) => *o = Some(state),
            _ => return self.fail("BUILD on something that is not a new numpy array or dtype"),
        }
        Ok(())
    }
}

fn unsupported(op: u8) -> String {
    let shown =
        if op.is_ascii_graphic() { format!(" ({:?})", char::from(op)) } else { String::new() };
    format!(
        "opcode 0x{op:02x}{shown} is not one Python's pickle writes for a dict of numpy arrays \
         (protocols 2 to 5)"
    )
}

/// A numeric numpy dtype: kind (`f`, `i`, `u`, `b`), size in bytes, byte order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Dtype {
    kind: char,
    size: usize,
    big_endian: bool,
}

impl Dtype {
    fn value(self, raw: &[u8]) -> f64 {
        let mut b = [0u8; 8];
        for (k, &byte) in raw.iter().take(8).enumerate() {
            let at = if self.big_endian { self.size.checked_sub(k + 1) } else { Some(k) };
            if let Some(slot) = at.and_then(|at| b.get_mut(at)) {
                *slot = byte;
            }
        }
        match (self.kind, self.size) {
            ('f', 8) => f64::from_le_bytes(b),
            ('f', 4) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            ('i', n) => {
                // Sign-extend from the top byte of the n-byte integer.
                let shift = 64 - 8 * n as u32;
                ((i64::from_le_bytes(b) << shift) >> shift) as f64
            }
            _ => u64::from_le_bytes(b) as f64,
        }
    }
}

impl Pickle<'_> {
    /// The value under the string key `key` of the dict `dict`.
    pub(crate) fn dict_get(&self, dict: Id, key: &str) -> Option<Id> {
        let Some(Node::Dict(items)) = self.get(dict) else { return None };
        items
            .iter()
            .rev()
            .find(|(k, _)| matches!(self.get(*k), Some(Node::Str(s)) if s == key))
            .map(|&(_, v)| v)
    }

    /// The string keys of the dict `dict`.
    pub(crate) fn dict_keys(&self, dict: Id) -> Vec<String> {
        let Some(Node::Dict(items)) = self.get(dict) else { return Vec::new() };
        items
            .iter()
            .filter_map(|(k, _)| match self.get(*k) {
                Some(Node::Str(s)) => Some(s.to_string()),
                _ => None,
            })
            .collect()
    }

    /// A Python or numpy number (an int, a float, a numpy scalar or a one-element array).
    pub(crate) fn number(&self, id: Id) -> Result<f64, String> {
        match self.get(id) {
            Some(Node::Int(v)) => Ok(*v as f64),
            Some(Node::Float(v)) => Ok(*v),
            Some(Node::Bool(v)) => Ok(f64::from(u8::from(*v))),
            Some(Node::Scalar { dtype, bytes }) => {
                let dtype = self.dtype(*dtype)?;
                match self.get(*bytes) {
                    Some(Node::Bytes(raw)) if raw.len() == dtype.size => Ok(dtype.value(raw)),
                    _ => Err(format!("a numpy scalar without its {} bytes", dtype.size)),
                }
            }
            Some(Node::Array { .. } | Node::Buffer { .. }) => match self.array(id)? {
                (_, data) if data.len() == 1 => Ok(data.first().copied().unwrap_or(f64::NAN)),
                (shape, _) => Err(format!("an array of shape {shape:?}, not one number")),
            },
            Some(other) => Err(format!("{} is not a number", describe(other))),
            None => Err("a dangling reference".to_owned()),
        }
    }

    /// Whether `id` is `None`.
    pub(crate) fn is_none(&self, id: Id) -> bool {
        matches!(self.get(id), Some(Node::None))
    }

    fn str(&self, id: Id) -> Option<&str> {
        match self.get(id) {
            Some(Node::Str(s)) => Some(s),
            _ => None,
        }
    }

    fn dtype(&self, id: Id) -> Result<Dtype, String> {
        let Some(Node::Dtype { code, order }) = self.get(id) else {
            return Err("an array or scalar without a numpy dtype".to_owned());
        };
        let code = self.str(*code).ok_or("a dtype whose code is not a string")?;
        // The order is a prefix of the code (`'<f8'`) or the 2nd item of the BUILD state.
        let state_order = order.and_then(|o| match self.get(o) {
            Some(Node::Tuple(items)) => items.get(1).and_then(|&i| self.str(i)),
            _ => None,
        });
        let (prefix, rest) = match code.chars().next() {
            Some(c @ ('<' | '>' | '=' | '|')) => (Some(c), code.get(1..).unwrap_or_default()),
            _ => (None, code),
        };
        let big_endian = prefix.or_else(|| state_order.and_then(|s| s.chars().next())) == Some('>');
        let kind = rest.chars().next().unwrap_or(' ');
        let size: usize = rest.get(1..).and_then(|s| s.parse().ok()).unwrap_or(0);
        match (kind, size) {
            ('f', 4 | 8) | ('i' | 'u', 1 | 2 | 4 | 8) | ('b', 1) => {
                Ok(Dtype { kind, size, big_endian })
            }
            _ => Err(format!("dtype {code:?} (float, int or bool arrays are read)")),
        }
    }

    fn shape(&self, id: Id) -> Result<Vec<usize>, String> {
        let Some(Node::Tuple(dims)) = self.get(id) else {
            return Err("an array shape that is not a tuple".to_owned());
        };
        dims.iter()
            .map(|&d| match self.get(d) {
                Some(&Node::Int(n)) => usize::try_from(n).map_err(|_| format!("dimension {n}")),
                _ => Err("a dimension that is not an integer".to_owned()),
            })
            .collect()
    }

    /// A numpy array as (shape, values in C order), converted to `f64`.
    pub(crate) fn array(&self, id: Id) -> Result<(Vec<usize>, Vec<f64>), String> {
        let RawArray { shape, dtype, raw, fortran } = match self.get(id) {
            Some(Node::Array { state: Some(state) }) => self.array_state(*state)?,
            Some(Node::Array { state: None }) => return Err("an array never built".to_owned()),
            Some(&Node::Buffer { buffer, dtype, shape, order }) => {
                let Some(Node::Bytes(raw)) = self.get(buffer) else {
                    return Err("_frombuffer without a buffer".to_owned());
                };
                let fortran = match self.str(order) {
                    Some("C") => false,
                    Some("F") => true,
                    _ => return Err("_frombuffer's order is neither 'C' nor 'F'".to_owned()),
                };
                RawArray {
                    shape: self.shape(shape)?,
                    dtype: self.dtype(dtype)?,
                    raw: raw.as_ref(),
                    fortran,
                }
            }
            Some(other) => return Err(format!("{} is not a numpy array", describe(other))),
            None => return Err("a dangling reference".to_owned()),
        };
        let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
        if count.and_then(|c| c.checked_mul(dtype.size)) != Some(raw.len()) {
            return Err(format!(
                "an array of shape {shape:?} with {} bytes of data ({}-byte elements)",
                raw.len(),
                dtype.size
            ));
        }
        let values: Vec<f64> = raw.chunks_exact(dtype.size).map(|c| dtype.value(c)).collect();
        let values = if fortran { c_order(&shape, &values) } else { values };
        Ok((shape, values))
    }

    /// numpy's `__setstate__` tuple: `(version, shape, dtype, is_fortran, raw)` (or without the
    /// version, as numpy before 1.0 wrote it).
    fn array_state(&self, state: Id) -> Result<RawArray<'_>, String> {
        let items = match self.get(state) {
            Some(Node::Tuple(items)) => items.as_slice(),
            _ => return Err("an array state that is not a tuple".to_owned()),
        };
        let (shape, dtype, fortran, raw) = match items {
            &[_, shape, dtype, fortran, raw] | &[shape, dtype, fortran, raw] => {
                (shape, dtype, fortran, raw)
            }
            _ => return Err(format!("an array state of {} items (expected 5)", items.len())),
        };
        let fortran = match self.get(fortran) {
            Some(&Node::Bool(b)) => b,
            Some(&Node::Int(i)) => i != 0,
            _ => return Err("an array state whose Fortran flag is not a bool".to_owned()),
        };
        let Some(Node::Bytes(raw)) = self.get(raw) else {
            return Err("an array whose data is not bytes (object arrays are not read)".to_owned());
        };
        Ok(RawArray {
            shape: self.shape(shape)?,
            dtype: self.dtype(dtype)?,
            raw: raw.as_ref(),
            fortran,
        })
    }
}

/// An array's description and bytes, before conversion.
struct RawArray<'p> {
    shape: Vec<usize>,
    dtype: Dtype,
    raw: &'p [u8],
    fortran: bool,
}

/// Fortran-order `values` of `shape` in C order (the first index varies fastest in the
/// input, the last in the output).
fn c_order(shape: &[usize], values: &[f64]) -> Vec<f64> {
    let mut strides = Vec::with_capacity(shape.len());
    let mut stride = 1;
    for &d in shape {
        strides.push(stride);
        stride *= d;
    }
    let mut index = vec![0usize; shape.len()];
    let mut out = Vec::with_capacity(values.len());
    for _ in 0..values.len() {
        let at: usize = index.iter().zip(&strides).map(|(i, s)| i * s).sum();
        out.push(values.get(at).copied().unwrap_or(f64::NAN));
        // Next C-order index: the last dimension first.
        for (i, &d) in index.iter_mut().zip(shape).rev() {
            *i += 1;
            if *i < d {
                break;
            }
            *i = 0;
        }
    }
    out
}

fn describe(node: &Node<'_>) -> &'static str {
    match node {
        Node::None => "None",
        Node::Bool(_) => "a bool",
        Node::Int(_) => "an int",
        Node::Float(_) => "a float",
        Node::Str(_) => "a string",
        Node::Bytes(_) => "bytes",
        Node::Tuple(_) => "a tuple",
        Node::List(_) => "a list",
        Node::Dict(_) => "a dict",
        Node::Global(_) => "a callable",
        Node::Array { .. } | Node::Buffer { .. } => "a numpy array",
        Node::Dtype { .. } => "a numpy dtype",
        Node::Scalar { .. } => "a numpy scalar",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_forbidden_global_is_refused_with_its_offset() {
        // pickle.dumps of a class whose __reduce__ returns (os.system, ("echo pwned",)), protocol 2.
        let evil = b"\x80\x02cposix\nsystem\nq\x00X\x0a\x00\x00\x00echo pwnedq\x01\x85q\x02Rq\x03.";
        let err = unpickle(evil).unwrap_err();
        assert_eq!(err.offset, 2);
        assert!(err.to_string().contains("`posix.system`"), "{err}");
        let stacked = b"\x80\x04\x8c\x02os\x8c\x06system\x93\x8c\x02ls\x85R.";
        let err = unpickle(stacked).unwrap_err();
        assert_eq!(err.offset, 14);
        assert!(err.to_string().contains("`os.system`"), "{err}");
    }

    #[test]
    fn truncated_and_unknown_input_are_errors() {
        assert!(unpickle(b"").is_err());
        assert!(unpickle(b"\x80\x04X\xff\xff\xff\x7fabc").unwrap_err().message.contains("length"));
        assert!(unpickle(b"\x80\x04\x81.").unwrap_err().message.contains("0x81"));
        assert!(unpickle(b"\x80\x04h\x05.").unwrap_err().message.contains("memo key 5"));
        assert!(unpickle(&[b'('; 2000]).unwrap_err().message.contains("nested MARKs"));
        assert!(unpickle(b"\x80\x04t.").unwrap_err().message.contains("MARK"));
    }

    #[test]
    fn memo_gets_share_one_node() {
        // [x, x] where x = 'abc' through BINPUT / BINGET: one node, two references.
        let p = unpickle(b"\x80\x02](X\x03\x00\x00\x00abcq\x00h\x00e.").unwrap();
        let Some(Node::List(items)) = p.get(p.root) else { panic!() };
        assert_eq!(items.len(), 2);
        assert_eq!(items[0], items[1]);
    }

    #[test]
    fn long1_reads_twos_complement() {
        let p = unpickle(b"\x8a\x02\x00\xff.").unwrap();
        assert!(matches!(p.get(p.root), Some(Node::Int(-256))));
        let p = unpickle(b"\x8a\x01\x7f.").unwrap();
        assert!(matches!(p.get(p.root), Some(Node::Int(127))));
    }

    #[test]
    fn fortran_order_becomes_c_order() {
        // [[1, 2, 3], [4, 5, 6]] in Fortran order is 1 4 2 5 3 6.
        assert_eq!(
            c_order(&[2, 3], &[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]),
            [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        );
        let values: Vec<f64> = (0..24).map(f64::from).collect();
        let c = c_order(&[2, 3, 4], &values);
        // Element (i, j, k) is at i + 2j + 6k in Fortran order.
        let (i, j, k) = (1, 2, 3);
        assert_eq!(c[(i * 3 + j) * 4 + k], (i + 2 * j + 6 * k) as f64);
    }
}

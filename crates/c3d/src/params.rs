//! The parameter section: groups of typed, dimensioned parameters.

use crate::header::{encode_f32, encode_u16, latin1, to_latin1, BLOCK, KEY};
use crate::processor::Processor;
use crate::Error;

/// Typed parameter data, row-major with the first dimension varying fastest (as stored).
#[derive(Clone, Debug, PartialEq)]
pub enum Data {
    /// Type −1: characters (Latin-1), strings of `dims[0]` characters.
    Char(Vec<u8>),
    /// Type 1: unsigned bytes.
    Byte(Vec<u8>),
    /// Type 2: 16-bit integers (some parameters are unsigned by convention).
    Int16(Vec<i16>),
    /// Type 4: floats.
    Float(Vec<f32>),
}

impl Data {
    fn type_byte(&self) -> i8 {
        match self {
            Data::Char(_) => -1,
            Data::Byte(_) => 1,
            Data::Int16(_) => 2,
            Data::Float(_) => 4,
        }
    }

    fn len(&self) -> usize {
        match self {
            Data::Char(v) | Data::Byte(v) => v.len(),
            Data::Int16(v) => v.len(),
            Data::Float(v) => v.len(),
        }
    }
}

/// A parameter's value: dimensions and data.
#[derive(Clone, Debug, PartialEq)]
pub struct Value {
    /// Dimensions (empty for a scalar), each at most 255.
    pub dims: Vec<usize>,
    /// The elements, `dims.iter().product()` of them.
    pub data: Data,
}

impl Value {
    /// A scalar 16-bit integer.
    #[must_use]
    pub fn int16(v: i16) -> Value {
        Value { dims: vec![], data: Data::Int16(vec![v]) }
    }

    /// A scalar float.
    #[must_use]
    pub fn float(v: f32) -> Value {
        Value { dims: vec![], data: Data::Float(vec![v]) }
    }

    /// A 1-D array of 16-bit integers.
    #[must_use]
    pub fn int16s(v: Vec<i16>) -> Value {
        Value { dims: vec![v.len()], data: Data::Int16(v) }
    }

    /// A 1-D array of floats.
    #[must_use]
    pub fn floats(v: Vec<f32>) -> Value {
        Value { dims: vec![v.len()], data: Data::Float(v) }
    }

    /// One string (a 1-D char array).
    #[must_use]
    pub fn string(s: &str) -> Value {
        let bytes = to_latin1(s);
        Value { dims: vec![bytes.len()], data: Data::Char(bytes) }
    }

    /// Strings padded with blanks to the longest (a 2-D char array).
    #[must_use]
    pub fn strings<S: AsRef<str>>(items: &[S]) -> Value {
        let rows: Vec<Vec<u8>> = items.iter().map(|s| to_latin1(s.as_ref())).collect();
        let width = rows.iter().map(Vec::len).max().unwrap_or(0).max(1);
        let mut bytes = Vec::with_capacity(width * rows.len());
        for r in &rows {
            bytes.extend_from_slice(r);
            bytes.resize(bytes.len() + width - r.len(), b' ');
        }
        Value { dims: vec![width, rows.len()], data: Data::Char(bytes) }
    }

    /// The elements as floats (integers and bytes converted).
    #[must_use]
    pub fn f32s(&self) -> Vec<f32> {
        match &self.data {
            Data::Float(v) => v.clone(),
            Data::Int16(v) => v.iter().map(|&x| f32::from(x)).collect(),
            Data::Byte(v) => v.iter().map(|&x| f32::from(x)).collect(),
            Data::Char(_) => vec![],
        }
    }

    /// The elements as signed 16-bit integers (floats rounded and saturated).
    #[must_use]
    pub fn i16s(&self) -> Vec<i16> {
        match &self.data {
            Data::Int16(v) => v.clone(),
            Data::Byte(v) => v.iter().map(|&x| i16::from(x)).collect(),
            Data::Float(v) => v.iter().map(|&x| x.round() as i16).collect(),
            Data::Char(_) => vec![],
        }
    }

    /// The elements as unsigned 16-bit integers: the manual's reading of counts, which are
    /// unsigned when an `int16` reads negative.
    #[must_use]
    pub fn u16s(&self) -> Vec<u16> {
        match &self.data {
            Data::Int16(v) => v.iter().map(|&x| x as u16).collect(),
            Data::Byte(v) => v.iter().map(|&x| u16::from(x)).collect(),
            Data::Float(v) => v.iter().map(|&x| x.round() as u16).collect(),
            Data::Char(_) => vec![],
        }
    }

    /// The first element as a float.
    #[must_use]
    pub fn first_f32(&self) -> Option<f32> {
        self.f32s().first().copied()
    }

    /// The first element as an unsigned 16-bit count.
    #[must_use]
    pub fn first_u16(&self) -> Option<u16> {
        self.u16s().first().copied()
    }

    /// A char array as strings: rows of `dims[0]` characters, trailing blanks and NULs removed.
    /// A 1-D (or scalar) char array is one string.
    #[must_use]
    pub fn strings_value(&self) -> Vec<String> {
        let Data::Char(bytes) = &self.data else { return vec![] };
        let width = match self.dims.first() {
            Some(&w) if self.dims.len() >= 2 && w > 0 => w,
            _ => return vec![trim(bytes)],
        };
        bytes.chunks(width).map(trim).collect()
    }

    /// A char array as one string (all rows joined), trailing blanks removed.
    #[must_use]
    pub fn string_value(&self) -> Option<String> {
        match &self.data {
            Data::Char(bytes) => Some(trim(bytes)),
            _ => None,
        }
    }
}

fn trim(bytes: &[u8]) -> String {
    latin1(bytes).trim_end_matches([' ', '\0']).to_string()
}

/// One parameter of a group.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Name as stored (C3D names are upper case; look-ups ignore case).
    pub name: String,
    /// Free text.
    pub description: String,
    /// Locked (negative name length in the file).
    pub locked: bool,
    /// Dimensions and data.
    pub value: Value,
}

/// A parameter group (`POINT`, `ANALOG`, `EVENT`, …) in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// Group number (1–127); parameters refer to it.
    pub id: u8,
    /// Name as stored.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Locked (negative name length in the file).
    pub locked: bool,
    /// Parameters in file order.
    pub parameters: Vec<Parameter>,
}

impl Group {
    /// A parameter by name (case-insensitive).
    #[must_use]
    pub fn get(&self, name: &str) -> Option<&Parameter> {
        self.parameters.iter().find(|p| p.name.eq_ignore_ascii_case(name))
    }
}

/// All groups of the parameter section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parameters {
    /// Groups in file order.
    pub groups: Vec<Group>,
}

impl Parameters {
    /// A group by name (case-insensitive).
    #[must_use]
    pub fn group(&self, name: &str) -> Option<&Group> {
        self.groups.iter().find(|g| g.name.eq_ignore_ascii_case(name))
    }

    /// A parameter's value by group and name (case-insensitive).
    #[must_use]
    pub fn get(&self, group: &str, name: &str) -> Option<&Value> {
        self.group(group)?.get(name).map(|p| &p.value)
    }

    /// A parameter and its continuations (`LABELS`, `LABELS2`, `LABELS3`, …) as strings.
    #[must_use]
    pub fn strings(&self, group: &str, name: &str) -> Vec<String> {
        self.continued(group, name).flat_map(Value::strings_value).collect()
    }

    /// A parameter and its continuations as floats.
    #[must_use]
    pub fn f32s(&self, group: &str, name: &str) -> Vec<f32> {
        self.continued(group, name).flat_map(Value::f32s).collect()
    }

    /// A parameter and its continuations as signed integers.
    #[must_use]
    pub fn i16s(&self, group: &str, name: &str) -> Vec<i16> {
        self.continued(group, name).flat_map(Value::i16s).collect()
    }

    fn continued<'a>(&'a self, group: &str, name: &'a str) -> impl Iterator<Item = &'a Value> {
        let g = self.group(group);
        std::iter::once(name.to_string())
            .chain((2..).map(move |i| format!("{name}{i}")))
            .map(move |n| g.and_then(|g| g.get(&n)).map(|p| &p.value))
            .take_while(Option::is_some)
            .flatten()
    }

    /// Sets a parameter, creating the group (with the next free id) and parameter if needed.
    pub fn set(&mut self, group: &str, name: &str, value: Value) {
        let g = self.group_mut_or_insert(group);
        match g.parameters.iter_mut().find(|p| p.name.eq_ignore_ascii_case(name)) {
            Some(p) => p.value = value,
            None => g.parameters.push(Parameter {
                name: name.to_ascii_uppercase(),
                description: String::new(),
                locked: false,
                value,
            }),
        }
    }

    /// Removes a parameter and its continuations (`NAME2`, `NAME3`, …); returns whether any was
    /// there.
    pub fn remove(&mut self, group: &str, name: &str) -> bool {
        let Some(g) = self.groups.iter_mut().find(|g| g.name.eq_ignore_ascii_case(group)) else {
            return false;
        };
        let before = g.parameters.len();
        let is_continuation = |p: &str| {
            p.get(..name.len()).is_some_and(|head| head.eq_ignore_ascii_case(name))
                && p.get(name.len()..).and_then(|n| n.parse::<u32>().ok()).is_some_and(|n| n >= 2)
        };
        g.parameters.retain(|p| !(p.name.eq_ignore_ascii_case(name) || is_continuation(&p.name)));
        g.parameters.len() != before
    }

    fn group_mut_or_insert(&mut self, name: &str) -> &mut Group {
        if let Some(i) = self.groups.iter().position(|g| g.name.eq_ignore_ascii_case(name)) {
            // `i` was just found in `groups`.
            #[allow(clippy::indexing_slicing)]
            return &mut self.groups[i];
        }
        let id = (1..=127u8).find(|id| self.groups.iter().all(|g| g.id != *id)).unwrap_or(127);
        self.groups.push(Group {
            id,
            name: name.to_ascii_uppercase(),
            description: String::new(),
            locked: false,
            parameters: vec![],
        });
        let last = self.groups.len() - 1;
        // Just pushed: `groups` is not empty.
        #[allow(clippy::indexing_slicing)]
        &mut self.groups[last]
    }
}

/// One item of the section before groups and parameters are matched up.
enum Item {
    Group(Group),
    Param(u8, Parameter),
}

/// Decodes a parameter section (`buf` starts at its first byte). Returns the parameters and
/// warnings about items that had to be skipped; fails only when nothing can be read.
pub(crate) fn parse(
    buf: &[u8],
    p: Processor,
    base: u64,
) -> Result<(Parameters, Vec<String>), Error> {
    let mut warnings = Vec::new();
    let mut items = Vec::new();
    let mut pos = 4usize;
    // Some writers leave the last item's offset pointing past the section: that ends it.
    while let (Some(&len_byte), Some(&id_byte)) = (buf.get(pos), buf.get(pos + 1)) {
        let (name_len, id) = (len_byte as i8, id_byte as i8);
        if name_len == 0 || id == 0 {
            break;
        }
        match parse_item(buf, pos, p) {
            Ok((item, next)) => {
                items.push(item);
                match next {
                    Next::Last => break,
                    Next::At(n) => pos = n,
                    Next::Invalid(offset) => {
                        warnings.push(format!(
                            "parameter item at byte {} has an invalid offset {offset} to the next item; \
                             parameters after it are ignored",
                            base + pos as u64
                        ));
                        break;
                    }
                }
            }
            Err(message) => {
                warnings.push(format!(
                    "parameter item at byte {} is corrupt ({message}); parameters after it are ignored",
                    base + pos as u64
                ));
                break;
            }
        }
    }
    if items.is_empty() && !warnings.is_empty() {
        return Err(Error::Parameters { offset: base + 4, message: warnings.join("; ") });
    }
    Ok((assemble(items, &mut warnings), warnings))
}

enum Next {
    Last,
    At(usize),
    Invalid(i16),
}

fn parse_item(buf: &[u8], pos: usize, p: Processor) -> Result<(Item, Next), String> {
    let take = |at: usize, n: usize| {
        at.checked_add(n)
            .and_then(|end| buf.get(at..end))
            .ok_or_else(|| "it runs past the end of the section".to_string())
    };
    let head = take(pos, 2)?;
    let (name_len, id) =
        (head.first().copied().unwrap_or(0) as i8, head.get(1).copied().unwrap_or(0) as i8);
    let locked = name_len < 0;
    let n = usize::from(name_len.unsigned_abs());
    let name = latin1(take(pos + 2, n)?);
    let off_at = pos + 2 + n;
    let o = take(off_at, 2)?;
    let offset = p.i16(crate::processor::take(o));
    let next = match offset {
        0 => Next::Last,
        o if o > 0 && off_at + o as usize > pos + 2 => Next::At(off_at + o as usize),
        o => Next::Invalid(o),
    };
    let mut at = off_at + 2;
    if id < 0 {
        let description = read_description(buf, &mut at)?;
        let group = Group { id: id.unsigned_abs(), name, description, locked, parameters: vec![] };
        return Ok((Item::Group(group), next));
    }
    let t = take(at, 2)?;
    let [type_byte, ndims] = crate::processor::take::<2>(t);
    let (type_byte, ndims) = (type_byte as i8, usize::from(ndims));
    at += 2;
    let dims: Vec<usize> = take(at, ndims)?.iter().map(|&d| usize::from(d)).collect();
    at += ndims;
    let too_big = || format!("parameter {name} has dimensions {dims:?} larger than the section");
    let count = dims.iter().try_fold(1usize, |n, &d| n.checked_mul(d)).ok_or_else(too_big)?;
    let size = match type_byte {
        -1 | 1 => 1,
        2 => 2,
        4 => 4,
        other => return Err(format!("parameter {name} has unknown type {other}")),
    };
    let bytes = count.checked_mul(size).ok_or_else(too_big)?;
    let raw = take(at, bytes)?;
    at += bytes;
    let data = match type_byte {
        -1 => Data::Char(raw.to_vec()),
        1 => Data::Byte(raw.to_vec()),
        2 => Data::Int16(raw.chunks_exact(2).map(|c| p.i16(crate::processor::take(c))).collect()),
        _ => Data::Float(raw.chunks_exact(4).map(|c| p.f32(crate::processor::take(c))).collect()),
    };
    // A missing description at the very end is tolerated (some writers omit it).
    let description = read_description(buf, &mut at).unwrap_or_default();
    let param = Parameter { name, description, locked, value: Value { dims, data } };
    Ok((Item::Param(id as u8, param), next))
}

fn read_description(buf: &[u8], at: &mut usize) -> Result<String, String> {
    let len = usize::from(*buf.get(*at).ok_or("description length past the end")?);
    let text = buf.get(*at + 1..*at + 1 + len).ok_or("description past the end")?;
    *at += 1 + len;
    Ok(latin1(text))
}

fn assemble(items: Vec<Item>, warnings: &mut Vec<String>) -> Parameters {
    let mut groups: Vec<Group> = Vec::new();
    let mut orphans = Vec::new();
    for item in items {
        match item {
            Item::Group(g) if g.name.is_empty() => {
                warnings.push(format!("group {} has no name; skipped", g.id));
            }
            Item::Group(g) if groups.iter().any(|h| h.id == g.id) => {
                warnings.push(format!(
                    "group {} ({}) appears twice; the second is ignored",
                    g.id, g.name
                ));
            }
            Item::Group(g) => groups.push(g),
            Item::Param(id, param) => orphans.push((id, param)),
        }
    }
    for (id, param) in orphans {
        match groups.iter_mut().find(|g| g.id == id) {
            Some(g) if g.get(&param.name).is_some() => warnings.push(format!(
                "parameter {}:{} appears twice; the second is ignored",
                g.name, param.name
            )),
            Some(g) => g.parameters.push(param),
            None => warnings
                .push(format!("parameter {} belongs to no group (id {id}); skipped", param.name)),
        }
    }
    Parameters { groups }
}

/// Encodes the section (header bytes included), padded to whole blocks.
pub(crate) fn encode(params: &Parameters, p: Processor) -> Result<Vec<u8>, Error> {
    let mut out = vec![1, KEY, 0, p.to_byte()];
    let mut items: Vec<Vec<u8>> = Vec::new();
    for g in &params.groups {
        items.push(encode_group(g)?);
        for param in &g.parameters {
            items.push(encode_param(g.id, param, p)?);
        }
    }
    let last = items.len().saturating_sub(1);
    for (i, item) in items.iter_mut().enumerate() {
        let name_len = usize::from((item.first().copied().unwrap_or(0) as i8).unsigned_abs());
        let off_at = 2 + name_len;
        // Offset from the offset field to the next item's first byte.
        let offset = if i == last { 0 } else { (item.len() - off_at) as u16 };
        if let Some(field) = item.get_mut(off_at..off_at + 2) {
            field.copy_from_slice(&encode_u16(p, offset));
        }
        out.extend_from_slice(item);
    }
    out.extend_from_slice(&[0, 0]);
    let blocks = out.len().div_ceil(BLOCK);
    let count = u8::try_from(blocks).map_err(|_| {
        Error::Write(format!("parameter section needs {blocks} blocks (at most 255)"))
    })?;
    if let Some(slot) = out.get_mut(2) {
        *slot = count;
    }
    out.resize(blocks * BLOCK, 0);
    Ok(out)
}

fn name_bytes(name: &str, locked: bool) -> Result<(u8, Vec<u8>), Error> {
    let bytes = to_latin1(&name.to_ascii_uppercase());
    if bytes.is_empty() || bytes.len() > 127 {
        return Err(Error::Write(format!(
            "parameter or group name {name:?} must have 1 to 127 characters"
        )));
    }
    let len = bytes.len() as i8;
    Ok(((if locked { -len } else { len }) as u8, bytes))
}

fn push_description(item: &mut Vec<u8>, description: &str) {
    let mut d = to_latin1(description);
    d.truncate(255);
    item.push(d.len() as u8);
    item.extend_from_slice(&d);
}

fn encode_group(g: &Group) -> Result<Vec<u8>, Error> {
    let (len, name) = name_bytes(&g.name, g.locked)?;
    if g.id == 0 || g.id > 127 {
        return Err(Error::Write(format!("group {} has id {} (must be 1 to 127)", g.name, g.id)));
    }
    let mut item = vec![len, (-(g.id as i8)) as u8];
    item.extend_from_slice(&name);
    item.extend_from_slice(&[0, 0]);
    push_description(&mut item, &g.description);
    Ok(item)
}

fn encode_param(group: u8, param: &Parameter, p: Processor) -> Result<Vec<u8>, Error> {
    let (len, name) = name_bytes(&param.name, param.locked)?;
    let v = &param.value;
    let count: usize = v.dims.iter().product();
    if v.dims.len() > 7 || v.dims.iter().any(|&d| d > 255) || count != v.data.len() {
        return Err(Error::Write(format!(
            "parameter {} has dimensions {:?} for {} elements (at most 7 dimensions of 255)",
            param.name,
            v.dims,
            v.data.len()
        )));
    }
    let mut item = vec![len, group];
    item.extend_from_slice(&name);
    item.extend_from_slice(&[0, 0]);
    item.push(v.data.type_byte() as u8);
    item.push(v.dims.len() as u8);
    item.extend(v.dims.iter().map(|&d| d as u8));
    match &v.data {
        Data::Char(b) | Data::Byte(b) => item.extend_from_slice(b),
        Data::Int16(x) => x.iter().for_each(|&x| item.extend_from_slice(&encode_u16(p, x as u16))),
        Data::Float(x) => x.iter().for_each(|&x| item.extend_from_slice(&encode_f32(p, x))),
    }
    push_description(&mut item, &param.description);
    Ok(item)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Parameters {
        let mut ps = Parameters::default();
        ps.set("POINT", "USED", Value::int16(3));
        ps.set("POINT", "LABELS", Value::strings(&["A", "BB", "CCC"]));
        ps.set("POINT", "RATE", Value::float(65.05));
        ps.set("ANALOG", "OFFSET", Value::int16s(vec![-1, 2, 3]));
        ps.set("ANALOG", "FLAGS", Value { dims: vec![2], data: Data::Byte(vec![0, 255]) });
        ps.groups[0].description = "3-D point parameters".into();
        ps.groups[0].parameters[0].description = "points used".into();
        ps.groups[0].parameters[0].locked = true;
        ps
    }

    #[test]
    fn section_round_trip_all_processors() {
        let ps = sample();
        for p in [Processor::Intel, Processor::Dec, Processor::Mips] {
            let bytes = encode(&ps, p).unwrap();
            assert_eq!(bytes.len() % BLOCK, 0);
            assert_eq!(bytes[3], p.to_byte());
            let (back, warnings) = parse(&bytes, p, 0).unwrap();
            assert!(warnings.is_empty(), "{warnings:?}");
            assert_eq!(back, ps);
        }
    }

    #[test]
    fn strings_and_continuations() {
        let mut ps = sample();
        ps.set("POINT", "LABELS2", Value::strings(&["D"]));
        assert_eq!(ps.strings("point", "labels"), ["A", "BB", "CCC", "D"]);
        assert!(ps.remove("POINT", "LABELS"));
        assert!(ps.get("POINT", "LABELS2").is_none());
        assert_eq!(ps.get("point", "used").unwrap().first_u16(), Some(3));
    }

    #[test]
    fn negative_counts_are_unsigned() {
        assert_eq!(Value::int16(-1).first_u16(), Some(65535));
    }

    #[test]
    fn truncated_section_is_a_warning_or_error_not_a_panic() {
        let bytes = encode(&sample(), Processor::Intel).unwrap();
        for cut in 0..bytes.len() {
            let _ = parse(&bytes[..cut], Processor::Intel, 0);
        }
    }
}

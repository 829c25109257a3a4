//! The BVH reader: a hand-written byte scanner over the whole file.
//!
//! Grammar (Biovision's, as exporters really write it):
//!
//! ```text
//! file     = "HIERARCHY" root+ "MOTION" "Frames:" int "Frame Time:" number row*
//! root     = "ROOT" name "{" body "}"
//! body     = ("OFFSET" number{3} | "CHANNELS" int channel* | joint | end)*
//! joint    = "JOINT" name "{" body "}"
//! end      = "End Site" "{" "OFFSET" number{3} "}"
//! row      = number{channels} newline        (one frame per line; blank lines ignored)
//! ```
//!
//! A name is the rest of its line (3ds Max writes `Bip01 L Thigh`), so any punctuation
//! (`mixamorig:Hips`) is fine. Keywords are matched case-insensitively. The hierarchy is
//! parsed with an explicit stack, so deep nesting cannot overflow the call stack.

use crate::error::{Error, Pos};
use crate::float::{is_space, parse_number, token_end};
use crate::skeleton::{Bvh, Channel, Joint, JointId, JointKind, Motion, Skeleton};
use crate::warning::Warning;

/// Parse a whole BVH file held in memory (see [`parse_with_warnings`] for what it
/// tolerates and reports).
pub fn parse(src: &[u8]) -> Result<Bvh, Error> {
    parse_with_warnings(src).map(|(bvh, _)| bvh)
}

/// Parse a whole BVH file held in memory, with the quirks that were read anyway.
///
/// Real exporters' files parse (each case has a fixture in `tests/data/quirk_*`): names padded
/// with spaces or tabs (trimmed), tabs wherever a space may be (after `Frames:` and
/// `Frame Time:`, between values), three-digit exponents (`1e-015`, from MSVC's `printf`),
/// joints with channels and no End Site, any positive Frame Time (119.875 fps stays 119.875),
/// position channels on any joint (their meaning is `fk`'s business), scale channels (kept,
/// with a [`Warning::ScaleChannels`]) and a `Frames:` count that disagrees with the rows
/// present: the rows win, with a [`Warning::FrameCount`] (Biovision's exports are often one
/// off). Warnings: the frame count's first, then one per joint with scale channels.
pub fn parse_with_warnings(src: &[u8]) -> Result<(Bvh, Vec<Warning>), Error> {
    let mut p = Parser { src, pos: 0 };
    if src.starts_with(b"\xEF\xBB\xBF") {
        p.pos = 3; // UTF-8 byte order mark, as some Windows tools write
    }
    let mut scaled = Vec::new();
    let skeleton = p.hierarchy(&mut scaled)?;
    let (motion, frame_count) = p.motion(skeleton.num_channels())?;
    let bvh = Bvh { skeleton, motion };
    let mut warnings: Vec<Warning> = frame_count.into_iter().collect();
    warnings.extend(scale_warnings(src, &bvh, &scaled));
    Ok((bvh, warnings))
}

/// One warning per joint with scale channels: (joint index, offset of its `CHANNELS`).
fn scale_warnings(src: &[u8], bvh: &Bvh, scaled: &[(usize, usize)]) -> Vec<Warning> {
    let m = &bvh.motion;
    scaled
        .iter()
        .filter_map(|&(id, at)| {
            let joint = bvh.skeleton.joints.get(id)?;
            let columns = (joint.channels.iter().enumerate())
                .filter(|(_, c)| matches!(c, Channel::Scale(_)))
                .map(|(k, _)| joint.first_channel + k);
            let values = columns.flat_map(|c| {
                (0..m.num_frames).filter_map(move |f| m.values.get(f * m.num_channels + c).copied())
            });
            let range = values
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
            let (min, max) = if range.0 <= range.1 { range } else { (1.0, 1.0) };
            let pos = Pos::from_offset(src, at);
            Some(Warning::ScaleChannels { pos, joint: joint.name.clone(), min, max })
        })
        .collect()
}

struct Parser<'a> {
    src: &'a [u8],
    pos: usize,
}

/// A joint whose `{` has been read and whose `}` has not.
struct Open {
    id: usize,
    brace: usize,
    has_offset: bool,
    has_channels: bool,
    has_children: bool,
}

fn is_inline_space(b: u8) -> bool {
    is_space(b) && b != b'\n'
}

fn is_keyword(token: &[u8], keyword: &str) -> bool {
    token.eq_ignore_ascii_case(keyword.as_bytes())
}

/// How an unexpected token is shown in a message.
fn describe(token: Option<&[u8]>) -> String {
    match token {
        None => "end of file".to_owned(),
        Some(t) => {
            let text = String::from_utf8_lossy(t.get(..40).unwrap_or(t));
            let more = if t.len() > 40 { "…" } else { "" };
            format!("`{text}{more}`")
        }
    }
}

impl<'a> Parser<'a> {
    fn at(&self, offset: usize) -> Pos {
        Pos::from_offset(self.src, offset)
    }

    fn skip_space(&mut self) {
        while self.src.get(self.pos).is_some_and(|&b| is_space(b)) {
            self.pos += 1;
        }
    }

    fn skip_inline_space(&mut self) {
        while self.src.get(self.pos).is_some_and(|&b| is_inline_space(b)) {
            self.pos += 1;
        }
    }

    /// The next token and its offset; `None` at end of file (offset = file length).
    fn token(&mut self) -> (usize, Option<&'a [u8]>) {
        self.skip_space();
        let start = self.pos;
        if start >= self.src.len() {
            return (start, None);
        }
        self.pos = token_end(self.src, start);
        (start, Some(self.src.get(start..self.pos).unwrap_or_default()))
    }

    fn peek(&mut self) -> (usize, Option<&'a [u8]>) {
        let saved = self.pos;
        let hit = self.token();
        self.pos = saved;
        hit
    }

    fn expected(&self, at: usize, expected: &'static str, found: Option<&[u8]>) -> Error {
        Error::Expected { pos: self.at(at), expected, found: describe(found) }
    }

    fn expect_keyword(
        &mut self,
        keyword: &'static str,
        expected: &'static str,
    ) -> Result<(), Error> {
        match self.token() {
            (_, Some(t)) if is_keyword(t, keyword) => Ok(()),
            (at, t) => Err(self.expected(at, expected, t)),
        }
    }

    /// The rest of the current line without surrounding blanks; the offset is its start.
    fn rest_of_line(&mut self) -> (usize, &'a [u8]) {
        self.skip_inline_space();
        let start = self.pos;
        let end = self
            .src
            .get(start..)
            .unwrap_or_default()
            .iter()
            .position(|&b| b == b'\n')
            .map_or(self.src.len(), |n| start + n);
        self.pos = end;
        (start, trim_end_space(self.src.get(start..end).unwrap_or_default()))
    }

    /// A number token that must be finite.
    fn number(&mut self, expected: &'static str) -> Result<f64, Error> {
        let (at, token) = self.token();
        let Some(token) = token else {
            return Err(self.expected(at, expected, None));
        };
        self.finite(at, token.len())
    }

    /// Parse the token at `at` (of length `len`) as a finite number.
    fn finite(&self, at: usize, len: usize) -> Result<f64, Error> {
        match parse_number(self.src, at) {
            Some((v, _)) if v.is_finite() => Ok(v),
            parsed => Err(self.number_error(at, len, parsed.is_some())),
        }
    }

    /// The error for a token that is not a finite number (`parsed`: it is NaN or infinite).
    fn number_error(&self, at: usize, len: usize, parsed: bool) -> Error {
        let text = self.src.get(at..at + len).unwrap_or_default();
        let token = String::from_utf8_lossy(text.get(..40).unwrap_or(text)).into_owned();
        let pos = self.at(at);
        if parsed {
            Error::NonFinite { pos, token }
        } else {
            Error::NotANumber { pos, token }
        }
    }

    /// A non-negative integer token.
    fn count(&mut self, expected: &'static str) -> Result<usize, Error> {
        let (at, token) = self.token();
        self.integer(at, token, expected)
    }

    fn integer(
        &self,
        at: usize,
        token: Option<&[u8]>,
        expected: &'static str,
    ) -> Result<usize, Error> {
        let value =
            token.and_then(|t| std::str::from_utf8(t).ok()).and_then(|t| t.parse::<usize>().ok());
        value.ok_or_else(|| self.expected(at, expected, token))
    }

    // ---- HIERARCHY -------------------------------------------------------------------------

    /// The HIERARCHY block; joints with scale channels go to `scaled` as (joint index,
    /// offset of their `CHANNELS` keyword).
    fn hierarchy(&mut self, scaled: &mut Vec<(usize, usize)>) -> Result<Skeleton, Error> {
        self.expect_keyword("HIERARCHY", "`HIERARCHY`")?;
        let mut skeleton = Skeleton::default();
        loop {
            match self.token() {
                (_, Some(t)) if is_keyword(t, "ROOT") => self.joint_tree(&mut skeleton, scaled)?,
                (_, Some(t)) if is_keyword(t, "MOTION") && !skeleton.joints.is_empty() => {
                    return Ok(skeleton)
                }
                (at, Some(b"}")) => return Err(Error::ExtraBrace { pos: self.at(at) }),
                (at, t) if skeleton.joints.is_empty() => return Err(self.expected(at, "`ROOT`", t)),
                (at, t) => return Err(self.expected(at, "`ROOT` or `MOTION`", t)),
            }
        }
    }

    /// One ROOT and everything below it (the `ROOT` keyword has been read).
    fn joint_tree(
        &mut self,
        skeleton: &mut Skeleton,
        scaled: &mut Vec<(usize, usize)>,
    ) -> Result<(), Error> {
        let mut stack = vec![self.open(skeleton, JointKind::Root, None)?];
        while let Some(top) = stack.last_mut() {
            let id = top.id;
            // `id` was pushed by `open`, which added the joint: it exists.
            let kind = skeleton.joints.get(id).map_or(JointKind::End, |j| j.kind);
            let (at, token) = self.token();
            match token {
                Some(t) if is_keyword(t, "OFFSET") => {
                    if top.has_offset {
                        return Err(Error::Invalid { pos: self.at(at), what: "duplicate OFFSET" });
                    }
                    top.has_offset = true;
                    let offset = self.offset()?;
                    if let Some(joint) = skeleton.joints.get_mut(id) {
                        joint.offset = offset;
                    }
                }
                Some(t) if is_keyword(t, "CHANNELS") && kind != JointKind::End => {
                    if top.has_channels {
                        return Err(Error::Invalid {
                            pos: self.at(at),
                            what: "duplicate CHANNELS",
                        });
                    }
                    if top.has_children {
                        // Columns follow the order of CHANNELS lines; keep it the tree's order.
                        let what = "CHANNELS after a child joint";
                        return Err(Error::Invalid { pos: self.at(at), what });
                    }
                    top.has_channels = true;
                    let channels = self.channels(at)?;
                    if channels.iter().any(|c| matches!(c, Channel::Scale(_))) {
                        scaled.push((id, at));
                    }
                    let first = skeleton.num_channels();
                    if let Some(joint) = skeleton.joints.get_mut(id) {
                        joint.first_channel = first;
                        joint.channels = channels;
                    }
                }
                Some(t) if is_keyword(t, "JOINT") && kind != JointKind::End => {
                    top.has_children = true;
                    let child = self.open(skeleton, JointKind::Joint, Some(id))?;
                    stack.push(child);
                }
                Some(t) if is_keyword(t, "End") && kind != JointKind::End => {
                    top.has_children = true;
                    self.expect_keyword("Site", "`Site` after `End`")?;
                    let child = self.open(skeleton, JointKind::End, Some(id))?;
                    stack.push(child);
                }
                Some(b"}") => {
                    if !top.has_offset {
                        return Err(self.expected(at, "OFFSET", token));
                    }
                    stack.pop();
                }
                Some(b"{") => return Err(Error::UnexpectedBrace { pos: self.at(at) }),
                Some(t) if is_keyword(t, "MOTION") || is_keyword(t, "ROOT") => {
                    return Err(self.missing_brace(skeleton, top.id, top.brace, at, token));
                }
                None => return Err(self.missing_brace(skeleton, top.id, top.brace, at, token)),
                Some(_) if kind == JointKind::End => {
                    return Err(self.expected(at, "OFFSET or `}` in End Site", token))
                }
                Some(_) => {
                    return Err(self.expected(
                        at,
                        "OFFSET, CHANNELS, JOINT, End Site or `}`",
                        token,
                    ))
                }
            }
        }
        Ok(())
    }

    fn missing_brace(
        &self,
        skeleton: &Skeleton,
        id: usize,
        brace: usize,
        at: usize,
        token: Option<&[u8]>,
    ) -> Error {
        Error::MissingBrace {
            pos: self.at(at),
            joint: skeleton.joints.get(id).map(|j| j.name.clone()).unwrap_or_default(),
            open: self.at(brace),
            found: describe(token),
        }
    }

    /// A joint's name (the rest of the line) and its `{`; pushes the joint.
    fn open(
        &mut self,
        skeleton: &mut Skeleton,
        kind: JointKind,
        parent: Option<usize>,
    ) -> Result<Open, Error> {
        let (at, mut name) = self.rest_of_line();
        let mut brace = None;
        // `JOINT Hips {` on one line.
        if let Some((b'{', head)) = name.split_last() {
            if head.last().is_none_or(|&b| is_space(b)) {
                brace = Some(at + head.len());
                name = trim_end_space(head);
            }
        }
        let name = match kind {
            JointKind::End => {
                if !name.is_empty() {
                    return Err(self.expected(at, "`{` after End Site", Some(name)));
                }
                let parent =
                    parent.and_then(|p| skeleton.joints.get(p)).map_or("", |j| j.name.as_str());
                format!("{parent}_End")
            }
            _ if name.is_empty() => {
                let found = "end of line".to_owned();
                return Err(Error::Expected { pos: self.at(at), expected: "a joint name", found });
            }
            _ => String::from_utf8_lossy(name).into_owned(),
        };
        let brace = match brace {
            Some(b) => b,
            None => match self.token() {
                (b, Some(b"{")) => b,
                (b, t) => return Err(self.expected(b, "`{`", t)),
            },
        };
        let id = skeleton.joints.len();
        skeleton.joints.push(Joint {
            name,
            kind,
            parent: parent.map(JointId),
            offset: [0.0; 3],
            channels: Vec::new(),
            first_channel: skeleton.num_channels(),
        });
        Ok(Open { id, brace, has_offset: false, has_channels: false, has_children: false })
    }

    fn offset(&mut self) -> Result<[f64; 3], Error> {
        Ok([
            self.number("an OFFSET number")?,
            self.number("an OFFSET number")?,
            self.number("an OFFSET number")?,
        ])
    }

    /// `n name{n}` after `CHANNELS` (at `keyword`). The names end at the first keyword, `{`,
    /// `}` or end of file, or at the end of the line once `n` have been read.
    fn channels(&mut self, keyword: usize) -> Result<Vec<Channel>, Error> {
        let declared = self.count("a channel count")?;
        let mut channels = Vec::with_capacity(declared.min(9));
        loop {
            let (at, token) = self.peek();
            let Some(t) = token else { break };
            let same_line = !self.src.get(self.pos..at).unwrap_or_default().contains(&b'\n');
            if channels.len() >= declared && !same_line {
                break;
            }
            let name = std::str::from_utf8(t).ok();
            match name.and_then(Channel::from_name) {
                Some(c) => channels.push(c),
                None if is_structural(t) => break,
                None if channels.len() >= declared => break,
                None => {
                    let name = String::from_utf8_lossy(t).into_owned();
                    return Err(Error::UnknownChannel { pos: self.at(at), name });
                }
            }
            self.pos = at + t.len();
        }
        if channels.len() != declared {
            return Err(Error::ChannelCount {
                pos: self.at(keyword),
                declared,
                found: channels.len(),
            });
        }
        Ok(channels)
    }

    // ---- MOTION ----------------------------------------------------------------------------

    /// The MOTION block, and the warning for a `Frames:` count that the rows contradict.
    fn motion(&mut self, num_channels: usize) -> Result<(Motion, Option<Warning>), Error> {
        let (declared, count_at) = self.labelled_count()?;
        let frame_time = self.frame_time()?;
        self.end_of_line()?;
        let (values, num_frames) = self.rows(declared, num_channels)?;
        let warning = (num_frames != declared).then(|| Warning::FrameCount {
            pos: self.at(count_at),
            declared,
            found: num_frames,
        });
        Ok((Motion { frame_time, num_frames, num_channels, values }, warning))
    }

    /// `Frames: n` (also `Frames:n`): the count and its offset.
    fn labelled_count(&mut self) -> Result<(usize, usize), Error> {
        let (at, token) = self.token();
        let expected = "a frame count after `Frames:`";
        match token.and_then(|t| strip_prefix_ignore_case(t, b"Frames:")) {
            Some([]) => {
                let (at, token) = self.token();
                Ok((self.integer(at, token, expected)?, at))
            }
            Some(rest) => Ok((self.integer(at + 7, Some(rest), expected)?, at + 7)),
            None => Err(self.expected(at, "`Frames:`", token)),
        }
    }

    /// `Frame Time: t` (also `Frame Time:t`), positive and finite.
    fn frame_time(&mut self) -> Result<f64, Error> {
        self.expect_keyword("Frame", "`Frame Time:`")?;
        let (label, token) = self.token();
        let (at, value) = match token.and_then(|t| strip_prefix_ignore_case(t, b"Time:")) {
            Some([]) => match self.token() {
                (at, Some(t)) => (at, self.finite(at, t.len())?),
                (at, None) => return Err(self.expected(at, "a frame time", None)),
            },
            Some(rest) => (label + 5, self.finite(label + 5, rest.len())?),
            None => return Err(self.expected(label, "`Time:` after `Frame`", token)),
        };
        if value > 0.0 {
            Ok(value)
        } else {
            Err(Error::Invalid { pos: self.at(at), what: "frame time must be positive" })
        }
    }

    fn end_of_line(&mut self) -> Result<(), Error> {
        self.skip_inline_space();
        match self.src.get(self.pos) {
            None => Ok(()),
            Some(b'\n') => {
                self.pos += 1;
                Ok(())
            }
            Some(_) => {
                let (at, token) = self.token();
                Err(self.expected(at, "end of line", token))
            }
        }
    }

    /// The motion rows, straight into one `frames × channels` buffer, and how many there
    /// are. `declared` (the `Frames:` count) only sizes the buffer: the rows present count.
    fn rows(&mut self, declared: usize, num_channels: usize) -> Result<(Vec<f64>, usize), Error> {
        if num_channels == 0 {
            // Rows would be empty lines, which cannot be counted: allow no frames at all.
            let (at, token) = self.token();
            return match token {
                Some(_) => {
                    Err(self.expected(at, "end of file (the skeleton has no channels)", token))
                }
                None if declared > 0 => {
                    Err(Error::Invalid { pos: self.at(at), what: "frames but no channels" })
                }
                None => Ok((Vec::new(), 0)),
            };
        }
        // Never trust the header for the allocation: each value takes at least two bytes.
        let room = (self.src.len() - self.pos) / 2 + 1;
        let mut values = Vec::with_capacity(declared.saturating_mul(num_channels).min(room));
        let mut frame = 0;
        loop {
            self.skip_inline_space();
            match self.src.get(self.pos) {
                None => break,
                Some(b'\n') => {
                    self.pos += 1;
                    continue;
                }
                Some(_) => {}
            }
            frame += 1;
            self.row(&mut values, frame, num_channels)?;
        }
        Ok((values, frame))
    }

    /// One row (frame number `frame`, from 1) ending at a newline or the end of the file.
    #[inline]
    fn row(
        &mut self,
        values: &mut Vec<f64>,
        frame: usize,
        num_channels: usize,
    ) -> Result<(), Error> {
        let src = self.src;
        let mut pos = self.pos;
        let mut found = 0;
        loop {
            while src.get(pos).is_some_and(|&b| is_inline_space(b)) {
                pos += 1;
            }
            match src.get(pos) {
                None => break,
                Some(b'\n') => {
                    pos += 1;
                    break;
                }
                Some(_) => {}
            }
            if found == num_channels {
                return Err(self.long_row(pos, frame, num_channels));
            }
            match parse_number(src, pos) {
                Some((v, end)) if v.is_finite() => {
                    values.push(v);
                    pos = end;
                }
                parsed => {
                    return Err(self.number_error(pos, token_end(src, pos) - pos, parsed.is_some()))
                }
            }
            found += 1;
        }
        self.pos = pos;
        if found < num_channels {
            let before = src.get(..pos).unwrap_or(src);
            let end = if before.ends_with(b"\n") { pos - 1 } else { pos };
            let before = src.get(..end).unwrap_or(src);
            let end = before.iter().rposition(|&b| !is_space(b)).map_or(end, |i| i + 1);
            return Err(Error::FrameLength {
                pos: self.at(end),
                frame,
                found,
                expected: num_channels,
            });
        }
        Ok(())
    }

    /// The error for a row with more than `expected` values; `extra` is the first extra one.
    fn long_row(&self, extra: usize, frame: usize, expected: usize) -> Error {
        let line_end = self
            .src
            .get(extra..)
            .unwrap_or_default()
            .iter()
            .position(|&b| b == b'\n')
            .map_or(self.src.len(), |n| extra + n);
        let more = self
            .src
            .get(extra..line_end)
            .unwrap_or_default()
            .split(|&b| is_space(b))
            .filter(|t| !t.is_empty())
            .count();
        Error::FrameLength { pos: self.at(extra), frame, found: expected + more, expected }
    }
}

fn is_structural(token: &[u8]) -> bool {
    ["JOINT", "End", "OFFSET", "CHANNELS", "ROOT", "MOTION", "{", "}"]
        .iter()
        .any(|k| is_keyword(token, k))
}

/// Without trailing whitespace (our set, which includes vertical tab, unlike `trim_ascii`).
fn trim_end_space(mut text: &[u8]) -> &[u8] {
    while let Some((&last, head)) = text.split_last() {
        if !is_space(last) {
            break;
        }
        text = head;
    }
    text
}

fn strip_prefix_ignore_case<'t>(token: &'t [u8], prefix: &[u8]) -> Option<&'t [u8]> {
    let head = token.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix).then(|| token.get(prefix.len()..)).flatten()
}

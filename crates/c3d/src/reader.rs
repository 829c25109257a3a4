//! Streaming reader: header and parameters up front, then one frame at a time.

use std::io::{Read, Seek, SeekFrom};

use crate::header::{Header, BLOCK, KEY};
use crate::layout::{DataFormat, Layout};
use crate::params::{self, Parameters};
use crate::processor::{take as word_bytes, Processor};
use crate::Error;

/// One marker sample. Invalid samples (residual word −1) are `None` in [`Frame::points`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Position in file units (usually mm) and lab axes.
    pub position: [f32; 3],
    /// Residual: the stored byte × |`POINT:SCALE`|; 0 means interpolated or modelled.
    pub residual: f32,
    /// Camera mask: bit `k` set when camera `k + 1` saw the marker (7 bits).
    pub cameras: u8,
}

/// One frame of the data section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Zero-based index in the data section.
    pub index: usize,
    /// Frame number as the file counts (first frame + index).
    pub number: u32,
    /// One entry per point; `None` for invalid (missing) samples.
    pub points: Vec<Option<Point>>,
    /// Real analog values, sample-major: `samples_per_frame × channels`.
    pub analog: Vec<f32>,
}

/// Reads a C3D file frame by frame in constant memory.
#[derive(Debug)]
pub struct Reader<R> {
    inner: R,
    header: Header,
    parameters: Parameters,
    layout: Layout,
    warnings: Vec<String>,
    buffer: Vec<u8>,
    next: usize,
}

impl<R: Read + Seek> Reader<R> {
    /// Reads header and parameters; the data section is read by [`Reader::read_frame`] or by
    /// iterating.
    pub fn new(mut inner: R) -> Result<Self, Error> {
        let file_len = inner.seek(SeekFrom::End(0))?;
        inner.seek(SeekFrom::Start(0))?;
        let mut block = [0u8; BLOCK];
        read_exact_or(&mut inner, &mut block, "the file is shorter than one 512-byte header")?;
        if block[1] != KEY {
            return Err(Error::NotC3d(format!(
                "header byte 2 is {:#04x}, not the key 0x50",
                block[1]
            )));
        }
        if block[0] == 0 {
            return Err(Error::NotC3d("the parameter section is at block 0".into()));
        }
        let param_start = (u64::from(block[0]) - 1) * BLOCK as u64;
        let mut start = [0u8; 4];
        inner.seek(SeekFrom::Start(param_start))?;
        read_exact_or(&mut inner, &mut start, "the parameter section is past the end of the file")?;
        let processor = Processor::from_byte(start[3]).ok_or(Error::Processor(start[3]))?;
        let header = Header::parse(&block, processor);
        // Read the declared blocks, or up to the data section if that is further; never past
        // the end of the file (a corrupt count must not allocate more than the file).
        let declared = param_start + u64::from(start[2].max(1)) * BLOCK as u64;
        let data_block = u64::from(header.data_start_block);
        let to_data =
            if data_block > u64::from(block[0]) { (data_block - 1) * BLOCK as u64 } else { 0 };
        let end = declared.max(to_data).min(file_len);
        let mut section = vec![0u8; (end - param_start) as usize];
        inner.seek(SeekFrom::Start(param_start))?;
        inner.read_exact(&mut section)?;
        let (parameters, mut warnings) = params::parse(&section, processor, param_start)?;
        let layout = Layout::derive(&header, &parameters, processor, file_len, &mut warnings)?;
        inner.seek(SeekFrom::Start(layout.data_start))?;
        Ok(Reader { inner, header, parameters, layout, warnings, buffer: vec![], next: 0 })
    }

    /// The header as stored.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The parameter section.
    pub fn parameters(&self) -> &Parameters {
        &self.parameters
    }

    /// The reconciled data layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Problems found so far that did not stop reading.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Reads the next frame into `frame` (reusing its buffers); `false` after the last frame.
    pub fn read_frame(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        if self.next >= self.layout.frame_count {
            return Ok(false);
        }
        self.buffer.resize(self.layout.frame_size(), 0);
        if let Err(e) = self.inner.read_exact(&mut self.buffer) {
            return Err(if e.kind() == std::io::ErrorKind::UnexpectedEof {
                Error::Truncated { frame: self.next, frames: self.layout.frame_count }
            } else {
                e.into()
            });
        }
        frame.index = self.next;
        frame.number = self.layout.first_frame.saturating_add(self.next as u32);
        decode_frame(&self.layout, &self.buffer, frame);
        self.next += 1;
        Ok(true)
    }

    /// Gives back the inner reader.
    pub fn into_inner(self) -> R {
        self.inner
    }

    pub(crate) fn into_parts(self) -> (Header, Parameters, Layout, Vec<String>) {
        (self.header, self.parameters, self.layout, self.warnings)
    }
}

impl<R: Read + Seek> Iterator for Reader<R> {
    type Item = Result<Frame, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        let mut frame = Frame::default();
        match self.read_frame(&mut frame) {
            Ok(true) => Some(Ok(frame)),
            Ok(false) => None,
            Err(e) => {
                self.next = self.layout.frame_count;
                Some(Err(e))
            }
        }
    }
}

fn read_exact_or<R: Read>(r: &mut R, buf: &mut [u8], what: &str) -> Result<(), Error> {
    r.read_exact(buf).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => Error::NotC3d(what.into()),
        _ => e.into(),
    })
}

/// Decodes one frame's bytes (exactly `layout.frame_size()` of them).
pub(crate) fn decode_frame(layout: &Layout, bytes: &[u8], frame: &mut Frame) {
    let p = layout.processor;
    let word = layout.word_size();
    let (point_bytes, analog_bytes) = bytes.split_at(4 * word * layout.point_count);
    let value = |c: &[u8]| match layout.format {
        DataFormat::Integer => f32::from(p.i16(word_bytes(c))),
        DataFormat::Float => p.f32(word_bytes(c)),
    };
    let at = |c: &[u8], k: usize| value(c.get(k * word..).unwrap_or_default());
    let scale = layout.point_scale.abs();
    frame.points.clear();
    frame.points.extend(point_bytes.chunks_exact(4 * word).map(|c| {
        let v = [at(c, 0), at(c, 1), at(c, 2), at(c, 3)];
        decode_point(v, layout.format, layout.point_scale, scale)
    }));
    let channels = layout.analog_channels.max(1);
    frame.analog.clear();
    frame.analog.extend(analog_bytes.chunks_exact(word).enumerate().map(|(i, c)| {
        let raw = match layout.format {
            DataFormat::Integer if layout.analog_unsigned => f64::from(p.u16(word_bytes(c))),
            DataFormat::Integer => f64::from(p.i16(word_bytes(c))),
            DataFormat::Float => f64::from(p.f32(word_bytes(c))),
        };
        let ch = i % channels;
        // `Layout` holds one scale and offset per channel.
        let scale = layout.analog_scales.get(ch).copied().unwrap_or(1.0);
        let offset = layout.analog_offsets.get(ch).copied().unwrap_or(0);
        let gain = f64::from(scale) * f64::from(layout.analog_gen_scale);
        ((raw - f64::from(offset)) * gain) as f32
    }));
}

/// The fourth word holds the camera mask (high byte, 7 bits) and the residual (low byte);
/// negative means invalid. Float files store that word's integer value as a float.
fn decode_point(v: [f32; 4], format: DataFormat, point_scale: f32, scale: f32) -> Option<Point> {
    let last = v[3] as i32;
    let xyz = match format {
        DataFormat::Integer => [v[0] * point_scale, v[1] * point_scale, v[2] * point_scale],
        DataFormat::Float => [v[0], v[1], v[2]],
    };
    if last < 0 || !v.iter().all(|x| x.is_finite()) {
        return None;
    }
    Some(Point {
        position: xyz,
        residual: (last & 0xff) as f32 * scale,
        cameras: ((last >> 8) & 0x7f) as u8,
    })
}

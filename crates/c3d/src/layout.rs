//! What the header and parameters say about the data section, reconciled.
//!
//! Parameter values win over their header copies (the header only has 16 bits and older
//! writers leave it stale); every disagreement that changes how data is read is a warning.

use crate::header::{Header, BLOCK};
use crate::params::Parameters;
use crate::processor::Processor;
use crate::Error;

/// How point (and analog) values are stored in the data section.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DataFormat {
    /// 16-bit integers; points scaled by `POINT:SCALE` (> 0).
    Integer,
    /// 32-bit floats (`POINT:SCALE` < 0; its magnitude scales residuals only).
    Float,
}

/// The reconciled description of the data section.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Byte order and float format.
    pub processor: Processor,
    /// Integer or float data.
    pub format: DataFormat,
    /// Points per frame (`POINT:USED`).
    pub point_count: usize,
    /// `POINT:SCALE`: sign gives the format, magnitude scales integers and residuals.
    pub point_scale: f32,
    /// Frames per second (`POINT:RATE`).
    pub point_rate: f32,
    /// Analog channels (`ANALOG:USED`).
    pub analog_channels: usize,
    /// Analog samples per channel per frame (`ANALOG:RATE / POINT:RATE`).
    pub analog_samples_per_frame: usize,
    /// Analog samples per second (`ANALOG:RATE`).
    pub analog_rate: f32,
    /// Signed or unsigned (`ANALOG:FORMAT = UNSIGNED`) integer analog data.
    pub analog_unsigned: bool,
    /// Per-channel `ANALOG:OFFSET` (0 where missing).
    pub analog_offsets: Vec<i32>,
    /// Per-channel `ANALOG:SCALE` (1 where missing).
    pub analog_scales: Vec<f32>,
    /// `ANALOG:GEN_SCALE` (1 where missing).
    pub analog_gen_scale: f32,
    /// Number of the first frame (`TRIAL:ACTUAL_START_FIELD` or header word 4).
    pub first_frame: u32,
    /// Frames the data section holds (announced count, cut to what the file holds).
    pub frame_count: usize,
    /// Byte offset of the first frame.
    pub data_start: u64,
}

impl Layout {
    /// Bytes per value of point data.
    #[must_use]
    pub fn word_size(&self) -> usize {
        match self.format {
            DataFormat::Integer => 2,
            DataFormat::Float => 4,
        }
    }

    /// Bytes per frame, points and analog.
    #[must_use]
    pub fn frame_size(&self) -> usize {
        self.word_size()
            * (4 * self.point_count + self.analog_channels * self.analog_samples_per_frame)
    }

    /// Reconciles header and parameters for a file of `file_len` bytes.
    pub(crate) fn derive(
        header: &Header,
        params: &Parameters,
        processor: Processor,
        file_len: u64,
        warnings: &mut Vec<String>,
    ) -> Result<Layout, Error> {
        let u16p = |g: &str, n: &str| params.get(g, n).and_then(|v| v.first_u16());
        let f32p = |g: &str, n: &str| params.get(g, n).and_then(|v| v.first_f32());
        let point_count = usize::from(u16p("POINT", "USED").unwrap_or(header.point_count));
        let point_scale = f32p("POINT", "SCALE").unwrap_or(header.scale);
        let format = if point_scale < 0.0 { DataFormat::Float } else { DataFormat::Integer };
        let point_rate = f32p("POINT", "RATE")
            .filter(|r| r.is_finite() && *r > 0.0)
            .unwrap_or(header.frame_rate);
        let (analog_channels, analog_samples_per_frame, analog_rate) =
            analog_shape(header, params, point_rate, warnings);
        let (analog_offsets, analog_scales, analog_gen_scale, analog_unsigned) =
            analog_transform(params, analog_channels);
        let (first_frame, announced) = frames(header, params);
        let data_block =
            u16p("POINT", "DATA_START").filter(|b| *b > 0).unwrap_or(header.data_start_block);
        if data_block == 0 {
            return Err(Error::Layout("the data section starts at block 0".into()));
        }
        let data_start = (u64::from(data_block) - 1) * BLOCK as u64;
        if u64::from(header.parameter_block) >= u64::from(data_block) {
            warnings.push(format!(
                "data section (block {data_block}) does not follow the parameter section (block {})",
                header.parameter_block
            ));
        }
        let mut layout = Layout {
            processor,
            format,
            point_count,
            point_scale,
            point_rate,
            analog_channels,
            analog_samples_per_frame,
            analog_rate,
            analog_unsigned,
            analog_offsets,
            analog_scales,
            analog_gen_scale,
            first_frame,
            frame_count: announced,
            data_start,
        };
        let frame_size = layout.frame_size() as u64;
        if frame_size == 0 && announced > 0 {
            warnings.push(format!("{announced} frames announced, but a frame holds no data"));
            layout.frame_count = 0;
        }
        if let Some(available) = file_len.saturating_sub(data_start).checked_div(frame_size) {
            let available = usize::try_from(available).unwrap_or(usize::MAX);
            if announced > available {
                warnings.push(format!(
                    "the file holds {available} of the {announced} frames it announces"
                ));
                layout.frame_count = available;
            }
        }
        Ok(layout)
    }
}

fn analog_shape(
    header: &Header,
    params: &Parameters,
    point_rate: f32,
    warnings: &mut Vec<String>,
) -> (usize, usize, f32) {
    let header_spf = usize::from(header.analog_samples_per_frame);
    let channels = match params.get("ANALOG", "USED").and_then(|v| v.first_u16()) {
        Some(n) => usize::from(n),
        None => usize::from(header.analog_per_frame).checked_div(header_spf).unwrap_or(0),
    };
    let rate = params
        .get("ANALOG", "RATE")
        .and_then(|v| v.first_f32())
        .filter(|r| r.is_finite() && *r > 0.0);
    if channels == 0 {
        return (0, 0, rate.unwrap_or(0.0));
    }
    let spf = match rate {
        Some(r) if point_rate.is_finite() && point_rate > 0.0 => {
            let ratio = f64::from(r) / f64::from(point_rate);
            if (ratio - ratio.round()).abs() > 1e-3 {
                warnings.push(format!(
                    "analog rate {r} Hz is not a multiple of the point rate {point_rate} Hz"
                ));
            }
            ratio.round().clamp(0.0, 65535.0) as usize
        }
        _ => header_spf,
    };
    let spf = if spf == 0 { usize::from(header.analog_per_frame) / channels } else { spf };
    if channels * spf != usize::from(header.analog_per_frame) {
        warnings.push(format!(
            "header says {} analog values per frame, parameters {channels} channels × {spf} samples; \
             the parameters are used",
            header.analog_per_frame
        ));
    }
    (channels, spf, rate.unwrap_or(point_rate * spf as f32))
}

fn analog_transform(params: &Parameters, channels: usize) -> (Vec<i32>, Vec<f32>, f32, bool) {
    let unsigned = params
        .get("ANALOG", "FORMAT")
        .and_then(|v| v.string_value())
        .is_some_and(|s| s.trim().eq_ignore_ascii_case("UNSIGNED"));
    let raw_offsets = params.i16s("ANALOG", "OFFSET");
    let offsets = (0..channels)
        .map(|c| match raw_offsets.get(c) {
            Some(&o) if unsigned => i32::from(o as u16),
            Some(&o) => i32::from(o),
            None => 0,
        })
        .collect();
    let raw_scales = params.f32s("ANALOG", "SCALE");
    let scales = (0..channels).map(|c| raw_scales.get(c).copied().unwrap_or(1.0)).collect();
    let gen = params.get("ANALOG", "GEN_SCALE").and_then(|v| v.first_f32()).unwrap_or(1.0);
    (offsets, scales, gen, unsigned)
}

/// First frame number and announced frame count.
fn frames(header: &Header, params: &Parameters) -> (u32, usize) {
    let field = |name: &str| {
        let w = params.get("TRIAL", name)?.u16s();
        match w.as_slice() {
            [lo, hi, ..] => Some(u32::from(*lo) + 65536 * u32::from(*hi)),
            _ => None,
        }
    };
    if let (Some(start), Some(end)) = (field("ACTUAL_START_FIELD"), field("ACTUAL_END_FIELD")) {
        if end >= start && end >= u32::from(header.last_frame) {
            return (start, (end - start) as usize + 1);
        }
    }
    let first = u32::from(header.first_frame);
    if let Some(n) = params.get("POINT", "FRAMES").and_then(|v| v.first_u16()) {
        return (first, usize::from(n));
    }
    let count = (u32::from(header.last_frame) + 1).saturating_sub(first);
    (first, count as usize)
}

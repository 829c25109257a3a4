//! Writing: a file from scratch or a read file rewritten, in any processor and data format.
//!
//! The data decide the parameters that describe them (`POINT:USED`, `FRAMES`, `SCALE`,
//! `RATE`, `DATA_START`, `LABELS`, `ANALOG:*`, `EVENT:*`, `TRIAL:ACTUAL_*_FIELD`); every other
//! parameter is written as it is in [`C3d::parameters`].

use std::io::Write;

use crate::header::{encode_f32, encode_u16, Header, HeaderEvent, BLOCK, MAX_HEADER_EVENTS};
use crate::layout::DataFormat;
use crate::model::{C3d, EventSource};
use crate::params::{self, Parameters, Value};
use crate::processor::Processor;
use crate::reader::Point;
use crate::Error;

/// Processor and data format of a file to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Format {
    /// Byte order and float format.
    pub processor: Processor,
    /// Integer (int16, scaled) or float data.
    pub data: DataFormat,
}

impl Format {
    /// Intel, float data: positions exact, residuals quantised to |`POINT:SCALE`|.
    pub const INTEL_FLOAT: Format = Format { processor: Processor::Intel, data: DataFormat::Float };
    /// Intel, scaled 16-bit integers: positions quantised to `POINT:SCALE`.
    pub const INTEL_INT: Format = Format { processor: Processor::Intel, data: DataFormat::Integer };
}

/// Largest integer the writer aims for when it chooses a scale (headroom below 32767).
const INT_RANGE: f32 = 32000.0;

/// Per-channel analog transform used for writing: `real = (raw − offset) × scale × gen_scale`.
struct AnalogTransform {
    offsets: Vec<i32>,
    scales: Vec<f32>,
    gen_scale: f32,
}

impl C3d {
    /// Writes the file. Integer output keeps the read `POINT:SCALE` (and analog scales) when
    /// every value fits, otherwise chooses one from the largest magnitude.
    pub fn write<W: Write>(&self, mut out: W, format: Format) -> Result<(), Error> {
        let frames = self.points.frame_count();
        let channels = self.analog.channel_count();
        let spf = if channels == 0 { 0 } else { self.analog.samples_per_frame };
        if self.analog.sample_count() != frames * spf && channels > 0 {
            return Err(Error::Write(format!(
                "{} analog samples per channel for {frames} frames of {spf} samples",
                self.analog.sample_count()
            )));
        }
        let scale = self.output_scale(format.data)?;
        let analog = self.analog_transform(format.data);
        let mut params = self.parameters.clone();
        self.describe(&mut params, scale, &analog, spf, 0);
        let section_len = params::encode(&params, format.processor)?.len();
        let data_block = 2 + section_len / BLOCK;
        self.describe(&mut params, scale, &analog, spf, data_block);
        let section = params::encode(&params, format.processor)?;
        let header = self.output_header(scale, spf, data_block)?;
        out.write_all(&header.to_bytes(format.processor))?;
        out.write_all(&section)?;
        let mut buf = Vec::new();
        let mut written = 0usize;
        for f in 0..frames {
            buf.clear();
            self.encode_frame(f, format, scale, &analog, &mut buf)?;
            out.write_all(&buf)?;
            written += buf.len();
        }
        // Pad the data section to whole blocks, as the format expects.
        let pad = written.next_multiple_of(BLOCK) - written;
        out.write_all(&vec![0u8; pad])?;
        out.flush()?;
        Ok(())
    }

    fn output_scale(&self, data: DataFormat) -> Result<f32, Error> {
        let magnitude = self.point_scale.abs();
        let max = self
            .points
            .data_iter()
            .flatten()
            .flat_map(|p| p.position.into_iter().chain([p.residual / 255.0 * INT_RANGE]))
            .try_fold(0f32, |m, v| if v.is_finite() { Ok(m.max(v.abs())) } else { Err(v) })
            .map_err(|v| Error::Write(format!("point data holds {v}")))?;
        match data {
            DataFormat::Float => {
                Ok(-if magnitude > 0.0 && magnitude.is_finite() { magnitude } else { 0.1 })
            }
            DataFormat::Integer => {
                if magnitude > 0.0 && magnitude.is_finite() && max / magnitude <= 32767.0 {
                    Ok(magnitude)
                } else if max > 0.0 {
                    Ok(max / INT_RANGE)
                } else {
                    Ok(0.1)
                }
            }
        }
    }

    fn analog_transform(&self, data: DataFormat) -> AnalogTransform {
        let n = self.analog.channel_count();
        let identity =
            AnalogTransform { offsets: vec![0; n], scales: vec![1.0; n], gen_scale: 1.0 };
        // Only an integer file's transform maps our values back onto whole numbers.
        if data == DataFormat::Float {
            return identity;
        }
        let p = &self.parameters;
        let (offsets, scales) = (p.i16s("ANALOG", "OFFSET"), p.f32s("ANALOG", "SCALE"));
        let gen_scale = p.get("ANALOG", "GEN_SCALE").and_then(|v| v.first_f32()).unwrap_or(1.0);
        let unsigned = p
            .get("ANALOG", "FORMAT")
            .and_then(|v| v.string_value())
            .is_some_and(|s| s.eq_ignore_ascii_case("UNSIGNED"));
        let mut t = AnalogTransform { offsets: vec![0; n], scales: vec![1.0; n], gen_scale: 1.0 };
        let reuse = self.format == DataFormat::Integer
            && !unsigned
            && offsets.len() >= n
            && scales.len() >= n
            && gen_scale.is_finite()
            && gen_scale != 0.0;
        if reuse {
            t = AnalogTransform {
                offsets: offsets.iter().take(n).map(|&o| i32::from(o)).collect(),
                scales: scales.iter().take(n).copied().collect(),
                gen_scale,
            };
        }
        for c in 0..n {
            let max = self.analog.channel(c).fold(0f32, |m, v| m.max(v.abs()));
            let keep = reuse
                && t.scales.get(c).is_some_and(|&s| s != 0.0)
                && self.analog.channel(c).all(|v| quantise_analog(v, c, &t).is_some());
            if !keep {
                let scale =
                    if max > 0.0 && max.is_finite() { max / INT_RANGE / t.gen_scale } else { 1.0 };
                if let (Some(o), Some(s)) = (t.offsets.get_mut(c), t.scales.get_mut(c)) {
                    (*o, *s) = (0, scale);
                }
            }
        }
        t
    }

    /// Sets the parameters that describe the data.
    fn describe(
        &self,
        params: &mut Parameters,
        scale: f32,
        analog: &AnalogTransform,
        spf: usize,
        data_block: usize,
    ) {
        let frames = self.points.frame_count();
        params.set("POINT", "USED", Value::int16(self.points.point_count() as u16 as i16));
        params.set("POINT", "FRAMES", Value::int16(frames.min(65535) as u16 as i16));
        params.set("POINT", "SCALE", Value::float(scale));
        params.set("POINT", "RATE", Value::float(self.point_rate));
        params.set("POINT", "DATA_START", Value::int16(data_block as u16 as i16));
        set_labels(params, "POINT", &self.points.labels);
        // Parameters every reader expects; a file made from scratch gets defaults.
        if params.get("POINT", "UNITS").is_none() {
            params.set("POINT", "UNITS", Value::string("mm"));
        }
        if params.get("POINT", "DESCRIPTIONS").is_none() {
            let blank = vec![String::new(); self.points.point_count()];
            set_split(params, "POINT", "DESCRIPTIONS", &blank, Value::strings);
        }
        let channels = self.analog.channel_count();
        if channels > 0 || params.group("ANALOG").is_some() {
            params.set("ANALOG", "USED", Value::int16(channels as u16 as i16));
            params.set("ANALOG", "RATE", Value::float(self.point_rate * spf as f32));
            set_labels(params, "ANALOG", &self.analog.labels);
            let blank = vec![String::new(); channels];
            for name in ["UNITS", "DESCRIPTIONS"] {
                if params.get("ANALOG", name).is_none() {
                    set_split(params, "ANALOG", name, &blank, Value::strings);
                }
            }
            params.remove("ANALOG", "SCALE");
            params.remove("ANALOG", "OFFSET");
            params.remove("ANALOG", "FORMAT");
            set_split(params, "ANALOG", "SCALE", &analog.scales, |v| Value::floats(v.to_vec()));
            let offsets: Vec<i16> = analog.offsets.iter().map(|&o| o as i16).collect();
            set_split(params, "ANALOG", "OFFSET", &offsets, |v| Value::int16s(v.to_vec()));
            params.set("ANALOG", "GEN_SCALE", Value::float(analog.gen_scale));
        }
        let last = self.first_frame.saturating_add(frames as u32).saturating_sub(1);
        let header_frames_fit = frames <= 65535 && (1..=65535).contains(&self.first_frame);
        if !header_frames_fit || params.get("TRIAL", "ACTUAL_START_FIELD").is_some() {
            let words =
                |v: u32| Value::int16s(vec![(v & 0xffff) as u16 as i16, (v >> 16) as u16 as i16]);
            params.set("TRIAL", "ACTUAL_START_FIELD", words(self.first_frame));
            params.set("TRIAL", "ACTUAL_END_FIELD", words(last));
        }
        self.describe_events(params);
    }

    fn describe_events(&self, params: &mut Parameters) {
        let events: Vec<_> =
            self.events.iter().filter(|e| e.source == EventSource::Parameters).collect();
        if events.is_empty() && params.group("EVENT").is_none() {
            return;
        }
        for name in ["LABELS", "CONTEXTS", "DESCRIPTIONS", "TIMES", "ICON_IDS", "GENERIC_FLAGS"] {
            params.remove("EVENT", name);
        }
        params.set("EVENT", "USED", Value::int16(events.len() as i16));
        if events.is_empty() {
            return;
        }
        let text = |f: fn(&crate::model::Event) -> &str| {
            events.iter().map(|e| f(e).to_string()).collect::<Vec<_>>()
        };
        params.set("EVENT", "LABELS", Value::strings(&text(|e| &e.label)));
        params.set("EVENT", "CONTEXTS", Value::strings(&text(|e| &e.context)));
        params.set("EVENT", "DESCRIPTIONS", Value::strings(&text(|e| &e.description)));
        // Minutes and seconds: whole minutes keep the seconds exact for short trials.
        let times: Vec<f32> = events
            .iter()
            .flat_map(|e| {
                let minutes = (e.time / 60.0).floor();
                if minutes > 0.0 {
                    [minutes, e.time - minutes * 60.0]
                } else {
                    [0.0, e.time]
                }
            })
            .collect();
        params.set(
            "EVENT",
            "TIMES",
            Value { dims: vec![2, events.len()], data: params::Data::Float(times) },
        );
    }

    fn output_header(&self, scale: f32, spf: usize, data_block: usize) -> Result<Header, Error> {
        let frames = self.points.frame_count();
        let analog_per_frame = self.analog.channel_count() * spf;
        let events: Vec<HeaderEvent> = self
            .events
            .iter()
            .filter(|e| e.source == EventSource::Header)
            .take(MAX_HEADER_EVENTS)
            .map(|e| HeaderEvent {
                label: e.label.clone(),
                time: e.time,
                display: e.display.unwrap_or(0),
            })
            .collect();
        let data_start_block = u16::try_from(data_block)
            .map_err(|_| Error::Write(format!("data section would start at block {data_block}")))?;
        let last = u64::from(self.first_frame) + frames as u64;
        Ok(Header {
            parameter_block: 2,
            point_count: self.points.point_count().min(65535) as u16,
            analog_per_frame: analog_per_frame.min(65535) as u16,
            first_frame: self.first_frame.clamp(1, 65535) as u16,
            last_frame: last.saturating_sub(1).min(65535) as u16,
            max_interpolation_gap: self.header.max_interpolation_gap,
            scale,
            data_start_block,
            analog_samples_per_frame: spf.min(65535) as u16,
            frame_rate: self.point_rate,
            long_event_labels: !events.is_empty() || self.header.long_event_labels,
            events,
        })
    }

    fn encode_frame(
        &self,
        f: usize,
        format: Format,
        scale: f32,
        analog: &AnalogTransform,
        out: &mut Vec<u8>,
    ) -> Result<(), Error> {
        let p = format.processor;
        let frame = self.points.frame(f).unwrap_or(&[]);
        for (i, point) in frame.iter().enumerate() {
            let words = encode_point(point.as_ref(), format.data, scale).ok_or_else(|| {
                Error::Write(format!("point {i} of frame {f} does not fit scale {scale}"))
            })?;
            for w in words {
                push_value(out, p, format.data, w);
            }
        }
        let channels = self.analog.channel_count();
        let spf = self.analog.samples_per_frame;
        for s in f * spf..(f + 1) * spf {
            for c in 0..channels {
                let v = self.analog.get(s, c).unwrap_or(0.0);
                match format.data {
                    DataFormat::Float => out.extend_from_slice(&encode_f32(p, v)),
                    DataFormat::Integer => {
                        let raw = quantise_analog(v, c, analog).ok_or_else(|| {
                            Error::Write(format!(
                                "analog channel {c} sample {s} does not fit 16 bits"
                            ))
                        })?;
                        out.extend_from_slice(&encode_u16(p, raw as u16));
                    }
                }
            }
        }
        Ok(())
    }
}

impl crate::model::Points {
    pub(crate) fn data_iter(&self) -> impl Iterator<Item = &Option<Point>> {
        (0..self.frame_count()).flat_map(move |f| self.frame(f).unwrap_or(&[]).iter())
    }
}

fn push_value(out: &mut Vec<u8>, p: Processor, data: DataFormat, v: f32) {
    match data {
        DataFormat::Float => out.extend_from_slice(&encode_f32(p, v)),
        DataFormat::Integer => out.extend_from_slice(&encode_u16(p, v as i16 as u16)),
    }
}

/// The four stored values of a point: x, y, z (raw) and the camera/residual word.
fn encode_point(point: Option<&Point>, data: DataFormat, scale: f32) -> Option<[f32; 4]> {
    let Some(pt) = point else { return Some([0.0, 0.0, 0.0, -1.0]) };
    let step = scale.abs();
    let residual = (pt.residual / step).round().clamp(0.0, 255.0);
    let word = f32::from(u16::from(pt.cameras & 0x7f) << 8) + residual;
    match data {
        DataFormat::Float => Some([pt.position[0], pt.position[1], pt.position[2], word]),
        DataFormat::Integer => {
            let q = |v: f32| Some((v / step).round()).filter(|r| r.abs() <= 32767.0);
            Some([q(pt.position[0])?, q(pt.position[1])?, q(pt.position[2])?, word])
        }
    }
}

fn quantise_analog(v: f32, c: usize, t: &AnalogTransform) -> Option<i16> {
    let gain = f64::from(*t.scales.get(c)?) * f64::from(t.gen_scale);
    let raw = (f64::from(v) / gain + f64::from(*t.offsets.get(c)?)).round();
    (raw.is_finite() && (-32768.0..=32767.0).contains(&raw)).then_some(raw as i16)
}

/// Sets `GROUP:LABELS` (and `LABELS2`, … beyond 255 entries).
fn set_labels(params: &mut Parameters, group: &str, labels: &[String]) {
    params.remove(group, "LABELS");
    set_split(params, group, "LABELS", labels, Value::strings);
}

/// Sets `NAME`, `NAME2`, … with at most 255 elements each.
fn set_split<T>(
    params: &mut Parameters,
    group: &str,
    name: &str,
    items: &[T],
    value: impl Fn(&[T]) -> Value,
) {
    if items.is_empty() {
        params.set(group, name, value(items));
        return;
    }
    for (i, chunk) in items.chunks(255).enumerate() {
        let n = if i == 0 { name.to_string() } else { format!("{name}{}", i + 1) };
        params.set(group, &n, value(chunk));
    }
}

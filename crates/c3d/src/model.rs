//! The whole file in memory.

use std::io::{Read, Seek};
use std::path::Path;

use crate::header::Header;
use crate::layout::DataFormat;
use crate::params::Parameters;
use crate::processor::Processor;
use crate::reader::{Frame, Point, Reader};
use crate::Error;

/// Marker trajectories: `frames × points`, `None` where a sample is invalid.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Points {
    /// One label per point (`POINT:LABELS`, `LABELS2`, …; empty where the file has none).
    pub labels: Vec<String>,
    frame_count: usize,
    data: Vec<Option<Point>>,
}

impl Points {
    /// `frame_count` frames of `labels.len()` missing samples.
    #[must_use]
    pub fn new(labels: Vec<String>, frame_count: usize) -> Points {
        let data = vec![None; labels.len() * frame_count];
        Points { labels, frame_count, data }
    }

    /// Number of frames.
    #[must_use]
    pub fn frame_count(&self) -> usize {
        self.frame_count
    }

    /// Points per frame.
    #[must_use]
    pub fn point_count(&self) -> usize {
        self.labels.len()
    }

    /// One frame's samples.
    #[must_use]
    pub fn frame(&self, frame: usize) -> Option<&[Option<Point>]> {
        let n = self.point_count();
        self.data.get(frame * n..(frame + 1) * n)
    }

    /// One sample; `None` when invalid or out of range.
    #[must_use]
    pub fn get(&self, frame: usize, point: usize) -> Option<Point> {
        self.frame(frame)?.get(point).copied().flatten()
    }

    /// Sets one sample; returns `false` (and changes nothing) when out of range.
    pub fn set(&mut self, frame: usize, point: usize, value: Option<Point>) -> bool {
        let n = self.point_count();
        if point >= n || frame >= self.frame_count {
            return false;
        }
        match self.data.get_mut(frame * n + point) {
            Some(slot) => {
                *slot = value;
                true
            }
            None => false,
        }
    }

    /// Index of a label (exact match after trimming).
    #[must_use]
    pub fn index_of(&self, label: &str) -> Option<usize> {
        self.labels.iter().position(|l| l.trim() == label.trim())
    }

    fn push_frame(&mut self, frame: &[Option<Point>]) {
        self.data.extend_from_slice(frame);
        self.frame_count += 1;
    }
}

/// Analog channels: `frames × samples_per_frame` samples of `channels` real values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Analog {
    /// One label per channel.
    pub labels: Vec<String>,
    /// Samples per second.
    pub rate: f32,
    /// Samples per channel per point frame.
    pub samples_per_frame: usize,
    data: Vec<f32>,
}

impl Analog {
    /// Zero-filled channels for `frame_count` point frames.
    #[must_use]
    pub fn new(
        labels: Vec<String>,
        rate: f32,
        samples_per_frame: usize,
        frame_count: usize,
    ) -> Analog {
        let data = vec![0.0; labels.len() * samples_per_frame * frame_count];
        Analog { labels, rate, samples_per_frame, data }
    }

    /// Number of channels.
    #[must_use]
    pub fn channel_count(&self) -> usize {
        self.labels.len()
    }

    /// Number of samples per channel.
    #[must_use]
    pub fn sample_count(&self) -> usize {
        self.data.len().checked_div(self.channel_count()).unwrap_or(0)
    }

    /// All channels at one sample.
    #[must_use]
    pub fn sample(&self, sample: usize) -> Option<&[f32]> {
        let n = self.channel_count();
        self.data.get(sample * n..(sample + 1) * n)
    }

    /// One value.
    #[must_use]
    pub fn get(&self, sample: usize, channel: usize) -> Option<f32> {
        self.sample(sample)?.get(channel).copied()
    }

    /// Sets one value; returns `false` (and changes nothing) when out of range.
    pub fn set(&mut self, sample: usize, channel: usize, value: f32) -> bool {
        let n = self.channel_count();
        match self.data.get_mut(sample * n + channel) {
            Some(v) if channel < n => {
                *v = value;
                true
            }
            _ => false,
        }
    }

    /// One channel over time.
    pub fn channel(&self, channel: usize) -> impl Iterator<Item = f32> + '_ {
        let n = self.channel_count();
        // With no samples (a file of 0 frames) `data` is empty while `channel < n`.
        let data: &[f32] = if channel < n { self.data.get(channel..).unwrap_or(&[]) } else { &[] };
        data.iter().step_by(n.max(1)).copied()
    }
}

/// Where an event was stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EventSource {
    /// The header's event block (4-character labels, at most 18).
    Header,
    /// The `EVENT` parameter group.
    Parameters,
}

/// A time event (foot strike, toe off, …).
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Label (`Foot Strike`, `RIC`, …).
    pub label: String,
    /// Context (`Left`, `Right`, …), empty for header events.
    pub context: String,
    /// Seconds from the start of the trial.
    pub time: f32,
    /// Free text, empty for header events.
    pub description: String,
    /// Header display flag as stored; `None` for parameter events.
    pub display: Option<u8>,
    /// Header block or `EVENT` group.
    pub source: EventSource,
}

/// A whole C3D file: header, parameters, points, analog and events, as written (file units
/// and axes). Invalid point samples are `None`, never zeros.
#[derive(Clone, Debug, PartialEq)]
pub struct C3d {
    /// Header as read (the writer rewrites the fields it derives).
    pub header: Header,
    /// Parameter section; the writer overrides the parameters it derives from the data.
    pub parameters: Parameters,
    /// Processor type of the file read.
    pub processor: Processor,
    /// Integer or float data in the file read.
    pub format: DataFormat,
    /// `POINT:SCALE` of the file read (integer step, or residual step for floats).
    pub point_scale: f32,
    /// Frames per second (`POINT:RATE`, header frame rate when absent), as stored.
    pub point_rate: f32,
    /// Number of the first frame.
    pub first_frame: u32,
    /// Marker samples.
    pub points: Points,
    /// Analog channels.
    pub analog: Analog,
    /// Events of the header block, then of the `EVENT` group.
    pub events: Vec<Event>,
    /// Problems that did not stop reading (corrupt parameter items, short data section, …).
    pub warnings: Vec<String>,
}

impl C3d {
    /// An empty file (no points, no analog, no frames) at `point_rate` frames per second.
    #[must_use]
    pub fn new(point_rate: f32) -> C3d {
        C3d {
            header: Header::parse(&[0; crate::header::BLOCK], Processor::Intel),
            parameters: Parameters::default(),
            processor: Processor::Intel,
            format: DataFormat::Float,
            point_scale: -0.1,
            point_rate,
            first_frame: 1,
            points: Points::default(),
            analog: Analog::default(),
            events: vec![],
            warnings: vec![],
        }
    }

    /// Reads a whole file.
    pub fn from_path(path: &Path) -> Result<C3d, Error> {
        let file = std::fs::File::open(path).map_err(|e| Error::from(e).in_file(path))?;
        C3d::from_reader(std::io::BufReader::new(file)).map_err(|e| e.in_file(path))
    }

    /// Reads a whole file from any seekable source. A data section shorter than announced
    /// keeps its complete frames and adds a warning.
    pub fn from_reader<R: Read + Seek>(inner: R) -> Result<C3d, Error> {
        let mut reader = Reader::new(inner)?;
        let layout = reader.layout().clone();
        let labels = labels_of(reader.parameters(), "POINT", layout.point_count);
        let mut points = Points {
            labels,
            frame_count: 0,
            data: Vec::with_capacity(layout.frame_count * layout.point_count),
        };
        let analog_labels = labels_of(reader.parameters(), "ANALOG", layout.analog_channels);
        let per_frame = layout.analog_channels * layout.analog_samples_per_frame;
        let mut analog = Analog {
            labels: analog_labels,
            rate: layout.analog_rate,
            samples_per_frame: layout.analog_samples_per_frame,
            data: Vec::with_capacity(layout.frame_count * per_frame),
        };
        let mut frame = Frame::default();
        let mut short = None;
        loop {
            match reader.read_frame(&mut frame) {
                Ok(true) => {
                    points.push_frame(&frame.points);
                    analog.data.extend_from_slice(&frame.analog);
                }
                Ok(false) => break,
                Err(Error::Truncated { frame, frames }) => {
                    short = Some(format!("the data section ends inside frame {frame} of {frames}"));
                    break;
                }
                Err(e) => return Err(e),
            }
        }
        let (header, parameters, layout, mut warnings) = reader.into_parts();
        warnings.extend(short);
        let events = events(&header, &parameters, &mut warnings);
        Ok(C3d {
            header,
            parameters,
            processor: layout.processor,
            format: layout.format,
            point_scale: layout.point_scale,
            point_rate: layout.point_rate,
            first_frame: layout.first_frame,
            points,
            analog,
            events,
            warnings,
        })
    }

    /// Point labels (one per point).
    #[must_use]
    pub fn point_labels(&self) -> &[String] {
        &self.points.labels
    }

    /// Frames per second as stored (`f32`, e.g. 65.05 Hz stays 65.05 in `f32`).
    #[must_use]
    pub fn point_rate(&self) -> f32 {
        self.point_rate
    }

    /// `FORCE_PLATFORM:USED`, 0 without it.
    #[must_use]
    pub fn force_plate_count(&self) -> usize {
        self.parameters
            .get("FORCE_PLATFORM", "USED")
            .and_then(|v| v.first_u16())
            .map_or(0, usize::from)
    }
}

/// `GROUP:LABELS` (with continuations) cut or padded with empty strings to `count`.
fn labels_of(params: &Parameters, group: &str, count: usize) -> Vec<String> {
    let mut labels = params.strings(group, "LABELS");
    labels.resize(count, String::new());
    labels
}

/// Header events, then `EVENT` group events (`EVENT:TIMES` holds minutes and seconds).
fn events(header: &Header, params: &Parameters, warnings: &mut Vec<String>) -> Vec<Event> {
    let mut out: Vec<Event> = header
        .events
        .iter()
        .map(|e| Event {
            label: e.label.clone(),
            context: String::new(),
            time: e.time,
            description: String::new(),
            display: Some(e.display),
            source: EventSource::Header,
        })
        .collect();
    let Some(used) = params.get("EVENT", "USED").and_then(|v| v.first_u16()) else { return out };
    let times = params.f32s("EVENT", "TIMES");
    let labels = params.strings("EVENT", "LABELS");
    let contexts = params.strings("EVENT", "CONTEXTS");
    let descriptions = params.strings("EVENT", "DESCRIPTIONS");
    let n = usize::from(used).min(times.len() / 2);
    if n < usize::from(used) {
        warnings
            .push(format!("EVENT:USED is {used} but EVENT:TIMES holds {n} events; {n} are read"));
    }
    let text = |v: &[String], i: usize| v.get(i).cloned().unwrap_or_default();
    out.extend((0..n).map(|i| Event {
        label: text(&labels, i),
        context: text(&contexts, i),
        time: (f64::from(times.get(2 * i).copied().unwrap_or(0.0)) * 60.0
            + f64::from(times.get(2 * i + 1).copied().unwrap_or(0.0))) as f32,
        description: text(&descriptions, i),
        display: None,
        source: EventSource::Parameters,
    }));
    out
}

//! `retarget c3d …`: inspect, dump and convert C3D files.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use c3d::{C3d, DataFormat, EventSource, Format};
use clap::{Args, Subcommand};
use serde_json::{json, Value};

#[derive(Subcommand, Debug)]
pub enum C3dCommand {
    /// Print header facts, points, analog channels, rate, events and parameter groups.
    Info {
        /// The C3D file.
        file: PathBuf,
    },
    /// Write marker positions, analog channels or events as CSV (default) or JSON.
    Dump {
        /// The C3D file.
        file: PathBuf,
        #[command(flatten)]
        what: DumpWhat,
        /// Output file; the format follows the extension (.csv or .json). Default: CSV on stdout.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Rewrite a file as Intel data (the input's integer or float format unless told).
    Convert {
        /// The C3D file to rewrite.
        file: PathBuf,
        /// Output .c3d file (written atomically).
        #[arg(short, long)]
        output: PathBuf,
        /// Float data: positions kept exactly.
        #[arg(long, conflicts_with = "int")]
        float: bool,
        /// Scaled 16-bit integer data: positions quantised to POINT:SCALE.
        #[arg(long)]
        int: bool,
    },
}

/// What `dump` writes (exactly one).
#[derive(Args, Debug)]
#[group(required = true, multiple = false)]
pub struct DumpWhat {
    /// Marker positions, one row per frame (empty cells for missing markers).
    #[arg(long)]
    points: bool,
    /// Analog channels, one row per analog sample.
    #[arg(long)]
    analog: bool,
    /// Events of the header block and of the EVENT group.
    #[arg(long)]
    events: bool,
}

pub fn run(cmd: C3dCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        C3dCommand::Info { file } => {
            let c3d = read(&file)?;
            to_stdout(info(&file, &c3d).as_bytes())?;
        }
        C3dCommand::Dump { file, what, output } => {
            let c3d = read(&file)?;
            dump(&c3d, &what, output.as_deref())?;
        }
        C3dCommand::Convert { file, output, float, int } => {
            let c3d = read(&file)?;
            let data = match (float, int) {
                (true, _) => DataFormat::Float,
                (_, true) => DataFormat::Integer,
                _ => c3d.format,
            };
            let mut bytes = Vec::new();
            c3d.write(&mut bytes, Format { processor: c3d::Processor::Intel, data })
                .with_context(|| format!("{}: cannot convert", file.display()))?;
            crate::atomic_write(&output, &bytes)?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Reads a file, printing its warnings to stderr.
fn read(file: &Path) -> anyhow::Result<C3d> {
    let c3d = C3d::from_path(file)?;
    for w in &c3d.warnings {
        eprintln!("warning: {}: {w}", file.display());
    }
    Ok(c3d)
}

fn format_name(data: DataFormat) -> &'static str {
    match data {
        DataFormat::Integer => "integer",
        DataFormat::Float => "float",
    }
}

fn info(file: &Path, c: &C3d) -> String {
    let mut s = String::new();
    let h = &c.header;
    let frames = c.points.frame_count();
    let last = (u64::from(c.first_frame) + frames as u64).saturating_sub(1);
    let _ = writeln!(s, "file: {}", file.display());
    let _ = writeln!(s, "processor: {} ({})", c.processor.name(), c.processor.to_byte());
    let _ = writeln!(s, "data: {} (POINT:SCALE {})", format_name(c.format), c.point_scale);
    let _ = writeln!(s, "frames: {frames} ({}..{last}) at {} Hz", c.first_frame, c.point_rate());
    let _ = writeln!(
        s,
        "header: parameter block {}, data block {}, points {}, analog values/frame {}, \
         frames {}..{}, scale {}, rate {} Hz, max gap {}",
        h.parameter_block,
        h.data_start_block,
        h.point_count,
        h.analog_per_frame,
        h.first_frame,
        h.last_frame,
        h.scale,
        h.frame_rate,
        h.max_interpolation_gap
    );
    let _ = writeln!(s, "points: {}", c.points.point_count());
    for (i, label) in c.point_labels().iter().enumerate() {
        let valid = (0..frames).filter(|&f| c.points.get(f, i).is_some()).count();
        let _ = writeln!(s, "  {i:4} {label:<24} valid in {valid}/{frames} frames");
    }
    let a = &c.analog;
    let _ = writeln!(
        s,
        "analog: {} channels at {} Hz ({} samples per frame)",
        a.channel_count(),
        a.rate,
        a.samples_per_frame
    );
    for (i, label) in a.labels.iter().enumerate() {
        let _ = writeln!(s, "  {i:4} {label}");
    }
    let _ = writeln!(s, "force plates: {}", c.force_plate_count());
    let _ = writeln!(s, "events: {}", c.events.len());
    for e in &c.events {
        let source = match e.source {
            EventSource::Header => "header",
            EventSource::Parameters => "EVENT",
        };
        let _ = writeln!(s, "  {source:<6} {:>10.4} s  {} {}", e.time, e.label, e.context);
    }
    let _ = writeln!(s, "parameter groups: {}", c.parameters.groups.len());
    for g in &c.parameters.groups {
        let names: Vec<&str> = g.parameters.iter().map(|p| p.name.as_str()).collect();
        let _ = writeln!(s, "  {}: {}", g.name, names.join(" "));
    }
    let _ = writeln!(s, "warnings: {}", c.warnings.len());
    for w in &c.warnings {
        let _ = writeln!(s, "  {w}");
    }
    s
}

#[derive(Clone, Copy, PartialEq)]
enum Out {
    Csv,
    Json,
}

fn dump(c: &C3d, what: &DumpWhat, output: Option<&Path>) -> anyhow::Result<()> {
    let out = match output.and_then(|p| p.extension()).and_then(|e| e.to_str()) {
        None => Out::Csv,
        Some(e) if e.eq_ignore_ascii_case("csv") => Out::Csv,
        Some(e) if e.eq_ignore_ascii_case("json") => Out::Json,
        Some(e) => bail!(
            "{}: unknown output format .{e} (use .csv or .json)",
            output.unwrap_or(Path::new("")).display()
        ),
    };
    let text = match (out, what.points, what.analog) {
        (Out::Csv, true, _) => points_csv(c),
        (Out::Csv, _, true) => analog_csv(c),
        (Out::Csv, _, _) => events_csv(c),
        (Out::Json, true, _) => json_text(&points_json(c)),
        (Out::Json, _, true) => json_text(&analog_json(c)),
        (Out::Json, _, _) => json_text(&events_json(c)),
    };
    match output {
        Some(path) => crate::atomic_write(path, text.as_bytes()),
        None => to_stdout(text.as_bytes()),
    }
}

/// Writes to stdout; a closed pipe (`| head`) is not an error.
fn to_stdout(bytes: &[u8]) -> anyhow::Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(bytes).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(e).context("cannot write to stdout")
        }
        _ => Ok(()),
    }
}

fn json_text(v: &Value) -> String {
    let mut s = serde_json::to_string_pretty(v).unwrap_or_default();
    s.push('\n');
    s
}

/// A CSV field, quoted when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A label for a column: the point's label, or `P<index>` when it has none.
fn column_label(labels: &[String], i: usize, prefix: &str) -> String {
    match labels.get(i).map(|l| l.trim()) {
        Some(l) if !l.is_empty() => l.to_string(),
        _ => format!("{prefix}{i}"),
    }
}

fn points_csv(c: &C3d) -> String {
    let mut s = String::from("frame,time");
    for i in 0..c.points.point_count() {
        let l = csv_field(&column_label(c.point_labels(), i, "P"));
        let _ = write!(s, ",{l}_x,{l}_y,{l}_z");
    }
    s.push('\n');
    for f in 0..c.points.frame_count() {
        let _ = write!(
            s,
            "{},{}",
            u64::from(c.first_frame) + f as u64,
            f as f64 / f64::from(c.point_rate())
        );
        for p in c.points.frame(f).unwrap_or(&[]) {
            match p {
                Some(p) => {
                    let _ = write!(s, ",{},{},{}", p.position[0], p.position[1], p.position[2]);
                }
                None => s.push_str(",,,"),
            }
        }
        s.push('\n');
    }
    s
}

fn analog_csv(c: &C3d) -> String {
    let a = &c.analog;
    let mut s = String::from("sample,time");
    for i in 0..a.channel_count() {
        let _ = write!(s, ",{}", csv_field(&column_label(&a.labels, i, "A")));
    }
    s.push('\n');
    for i in 0..a.sample_count() {
        let _ = write!(s, "{i},{}", i as f64 / f64::from(a.rate));
        for v in a.sample(i).unwrap_or(&[]) {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    s
}

fn source_name(source: EventSource) -> &'static str {
    match source {
        EventSource::Header => "header",
        EventSource::Parameters => "parameters",
    }
}

fn events_csv(c: &C3d) -> String {
    let mut s = String::from("source,label,context,time,description\n");
    for e in &c.events {
        let _ = writeln!(
            s,
            "{},{},{},{},{}",
            source_name(e.source),
            csv_field(&e.label),
            csv_field(&e.context),
            e.time,
            csv_field(&e.description)
        );
    }
    s
}

fn points_json(c: &C3d) -> Value {
    let frames: Vec<Value> = (0..c.points.frame_count())
        .map(|f| {
            let points = c.points.frame(f).unwrap_or(&[]);
            Value::Array(
                points.iter().map(|p| p.map_or(Value::Null, |p| json!(p.position))).collect(),
            )
        })
        .collect();
    json!({
        "rate": c.point_rate(),
        "first_frame": c.first_frame,
        "labels": c.point_labels(),
        "frames": frames,
    })
}

fn analog_json(c: &C3d) -> Value {
    let a = &c.analog;
    let samples: Vec<&[f32]> = (0..a.sample_count()).filter_map(|i| a.sample(i)).collect();
    json!({
        "rate": a.rate,
        "samples_per_frame": a.samples_per_frame,
        "labels": a.labels,
        "samples": samples,
    })
}

fn events_json(c: &C3d) -> Value {
    let events: Vec<Value> = c
        .events
        .iter()
        .map(|e| {
            json!({
                "source": source_name(e.source),
                "label": e.label,
                "context": e.context,
                "time": e.time,
                "description": e.description,
            })
        })
        .collect();
    Value::Array(events)
}

//! Writing: from scratch and rewriting the samples, read back by us, `c3dio` and Python `c3d`.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use c3d::{Analog, C3d, DataFormat, Event, EventSource, Format, Point, Points, Processor};

use crate::read_shared::{all_samples, read};

const ALL_FORMATS: [Format; 6] = [
    Format::INTEL_FLOAT,
    Format::INTEL_INT,
    Format { processor: Processor::Mips, data: DataFormat::Float },
    Format { processor: Processor::Mips, data: DataFormat::Integer },
    Format { processor: Processor::Dec, data: DataFormat::Float },
    Format { processor: Processor::Dec, data: DataFormat::Integer },
];

fn to_bytes(c: &C3d, format: Format) -> Vec<u8> {
    let mut out = Vec::new();
    c.write(&mut out, format).unwrap();
    out
}

fn reread(bytes: &[u8]) -> C3d {
    C3d::from_reader(Cursor::new(bytes)).unwrap()
}

/// Same points (within `tol`, validity exact), analog (within `analog_tol` relative to the
/// channel's largest value), labels, rate and events.
fn assert_same(a: &C3d, b: &C3d, tol: f32, analog_tol: f32, what: &str) {
    assert_eq!(a.point_labels(), b.point_labels(), "{what}: labels");
    assert_eq!(a.points.frame_count(), b.points.frame_count(), "{what}: frames");
    assert_eq!(a.point_rate(), b.point_rate(), "{what}: rate");
    assert_eq!(a.first_frame, b.first_frame, "{what}: first frame");
    for f in 0..a.points.frame_count() {
        for (i, (p, q)) in
            a.points.frame(f).unwrap().iter().zip(b.points.frame(f).unwrap()).enumerate()
        {
            match (p, q) {
                (None, None) => {}
                (Some(p), Some(q)) => {
                    let d =
                        (0..3).map(|k| (p.position[k] - q.position[k]).abs()).fold(0.0, f32::max);
                    assert!(d <= tol, "{what}: frame {f} point {i}: {p:?} vs {q:?}");
                    assert_eq!(p.cameras, q.cameras, "{what}: frame {f} point {i}");
                }
                _ => panic!("{what}: frame {f} point {i}: {p:?} vs {q:?}"),
            }
        }
    }
    assert_eq!(a.analog.labels, b.analog.labels, "{what}: analog labels");
    assert_eq!(a.analog.sample_count(), b.analog.sample_count(), "{what}: analog samples");
    for c in 0..a.analog.channel_count() {
        let max = a.analog.channel(c).fold(0f32, |m, v| m.max(v.abs()));
        for (s, (x, y)) in a.analog.channel(c).zip(b.analog.channel(c)).enumerate() {
            assert!((x - y).abs() <= analog_tol * max, "{what}: analog {c} sample {s}: {x} vs {y}");
        }
    }
    let key = |e: &Event| (e.label.clone(), e.context.clone(), e.time.to_bits(), e.source);
    assert_eq!(
        a.events.iter().map(key).collect::<Vec<_>>(),
        b.events.iter().map(key).collect::<Vec<_>>(),
        "{what}: events"
    );
}

/// A small file made from nothing: 3 markers (one missing in frame 2), 2 analog channels at
/// 4 samples per frame, header and group events.
pub fn scratch() -> C3d {
    let mut c = C3d::new(100.0);
    let frames = 5;
    c.points = Points::new(vec!["LASI".into(), "RASI".into(), "Human1:PELV".into()], frames);
    for f in 0..frames {
        for p in 0..3 {
            // Multiples of 1/8 mm: exact in f32 and on the 0.125 grid of the integer files.
            let v = |k: usize| (f * 100 + p * 10 + k) as f32 * 0.125 - 20.0;
            let point =
                Point { position: [v(0), v(1), v(2)], residual: 0.25 * p as f32, cameras: 0b101 };
            c.points.set(f, p, (f != 2 || p != 1).then_some(point));
        }
    }
    c.point_scale = 0.125;
    c.analog = Analog::new(vec!["FZ1".into(), "EMG".into()], 400.0, 4, frames);
    for s in 0..c.analog.sample_count() {
        c.analog.set(s, 0, s as f32 * 2.0 - 10.0);
        c.analog.set(s, 1, (s % 7) as f32);
    }
    let event = |label: &str, context: &str, time: f32, source| Event {
        label: label.into(),
        context: context.into(),
        time,
        description: String::new(),
        display: (source == EventSource::Header).then_some(0),
        source,
    };
    c.events = vec![
        event("RIC", "", 0.01, EventSource::Header),
        event("Foot Strike", "Left", 0.02, EventSource::Parameters),
        event("Foot Off", "Right", 0.035, EventSource::Parameters),
    ];
    c
}

#[test]
fn scratch_file_reads_back_identically_in_every_format() {
    let c = scratch();
    for format in ALL_FORMATS {
        let back = reread(&to_bytes(&c, format));
        assert!(back.warnings.is_empty(), "{format:?}: {:?}", back.warnings);
        assert_eq!(back.points, c.points, "{format:?}");
        // Integer analog needs a scale: the writer chooses largest magnitude / 32000.
        let analog_tol = if format.data == DataFormat::Integer { 1.0 / 32000.0 } else { 0.0 };
        assert_same(&c, &back, 0.0, analog_tol, &format!("{format:?}"));
        assert_eq!(back.processor, format.processor);
        assert_eq!(back.format, format.data);
    }
}

#[test]
fn rewriting_every_sample_keeps_its_data() {
    for path in all_samples() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let original = C3d::from_path(&path).unwrap();
        for format in ALL_FORMATS {
            let what = format!("{name} {format:?}");
            let once = reread(&to_bytes(&original, format));
            assert!(once.warnings.is_empty(), "{what}: {:?}", once.warnings);
            // Float output keeps positions and analog exactly (DEC: up to VAX's smaller range);
            // integer output quantises positions to half a step of the scale it chose.
            let (tol, analog_tol) = match format.data {
                DataFormat::Float => (0.0, 0.0),
                DataFormat::Integer => (0.5 * once.point_scale + 1e-3, 1.0 / 32000.0),
            };
            assert_same(&original, &once, tol, analog_tol, &what);
            // The parameters we do not derive are carried over.
            for g in &original.parameters.groups {
                assert!(once.parameters.group(&g.name).is_some(), "{what}: group {}", g.name);
            }
            // Writing what we read from our own file is a fixed point, byte for byte.
            let bytes = to_bytes(&once, format);
            assert_eq!(to_bytes(&reread(&bytes), format), bytes, "{what}: not a fixed point");
        }
    }
}

/// A scratch folder under the system temp dir, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("c3d-test-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// What we write for the cross-readers: the scratch file and two rewritten samples, each as
/// Intel float and Intel integer.
fn written_files(dir: &Path) -> Vec<(PathBuf, C3d)> {
    let mut sources = vec![("scratch".to_string(), scratch())];
    for name in ["c3dorg_s01_Eb015vr.c3d", "c3dorg_s02_sgi_int.c3d", "ezc3dtest_Qualisys.c3d"] {
        if let Some(c) = read(name) {
            sources.push((name.trim_end_matches(".c3d").to_string(), c));
        }
    }
    let mut out = Vec::new();
    for (name, c) in sources {
        for (tag, format) in [("float", Format::INTEL_FLOAT), ("int", Format::INTEL_INT)] {
            let path = dir.join(format!("{name}_{tag}.c3d"));
            let bytes = to_bytes(&c, format);
            std::fs::write(&path, &bytes).unwrap();
            out.push((path, reread(&bytes)));
        }
    }
    out
}

#[test]
fn c3dio_reads_what_we_write() {
    let dir = TempDir::new("c3dio");
    for (path, ours) in written_files(&dir.0) {
        let what = path.display().to_string();
        let theirs =
            c3dio::C3d::load_path(path.clone()).unwrap_or_else(|e| panic!("{what}: {e:?}"));
        let grid = &theirs.points.points;
        assert_eq!(grid.rows(), ours.points.frame_count(), "{what}: frames");
        assert_eq!(grid.cols(), ours.points.point_count(), "{what}: points");
        let labels: Vec<String> =
            theirs.points.labels.iter().map(|l| l.trim().to_string()).collect();
        assert_eq!(&labels[..ours.points.point_count()], ours.point_labels(), "{what}: labels");
        for f in 0..grid.rows() {
            for p in 0..grid.cols() {
                let t = grid[f][p];
                match ours.points.get(f, p) {
                    Some(o) => {
                        assert_eq!(t.point, o.position, "{what}: frame {f} point {p}");
                        let cameras =
                            (0..7).filter(|&k| t.cameras[k]).map(|k| 1u8 << k).sum::<u8>();
                        assert_eq!(cameras, o.cameras, "{what}: frame {f} point {p} cameras");
                    }
                    None => assert_eq!(t.point, [0.0; 3], "{what}: frame {f} point {p} missing"),
                }
            }
        }
        let analog = &theirs.analog.analog;
        assert_eq!(analog.cols(), ours.analog.channel_count(), "{what}: analog channels");
        if analog.cols() > 0 {
            assert_eq!(analog.rows(), ours.analog.sample_count(), "{what}: analog samples");
            for s in 0..analog.rows() {
                for c in 0..analog.cols() {
                    let (t, o) = (analog[s][c], f64::from(ours.analog.get(s, c).unwrap()));
                    assert!(
                        (t - o).abs() <= 1e-6 * o.abs().max(1.0),
                        "{what}: analog {s} {c}: {t} vs {o}"
                    );
                }
            }
        }
    }
}

/// Runs `scripts/check-c3d-python` (Python `c3d` 0.6.0 in a venv under `target/`).
pub fn python_c3d(files: &[PathBuf]) -> Option<serde_json::Value> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/check-c3d-python");
    let in_ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false");
    let has_python = std::process::Command::new("python3").arg("--version").output().is_ok();
    if !has_python && !in_ci {
        eprintln!("note: python3 is not installed; skipping the Python c3d cross-check");
        return None;
    }
    // One caller at a time: the first one may be creating the venv.
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let out = std::process::Command::new(&script).args(files).output().unwrap();
    assert!(out.status.success(), "{}: {}", script.display(), String::from_utf8_lossy(&out.stderr));
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

pub fn assert_python_frame(theirs: &serde_json::Value, ours: &C3d, frame: usize, what: &str) {
    let f32_at = |v: &serde_json::Value| v.as_f64().map(|x| x as f32);
    let points = theirs["points"].as_array().unwrap();
    assert_eq!(points.len(), ours.points.point_count(), "{what}");
    for (p, t) in points.iter().enumerate() {
        let t: Vec<Option<f32>> = t.as_array().unwrap().iter().map(f32_at).collect();
        match ours.points.get(frame, p) {
            Some(o) => {
                let position = [t[0], t[1], t[2]].map(Option::unwrap);
                assert_eq!(position, o.position, "{what}: frame {frame} point {p}");
                assert_eq!(t[3], Some(o.residual), "{what}: frame {frame} point {p} residual");
                assert_eq!(
                    t[4],
                    Some(f32::from(o.cameras)),
                    "{what}: frame {frame} point {p} cameras"
                );
            }
            None => {
                assert_eq!(t[3], Some(-1.0), "{what}: frame {frame} point {p} should be invalid")
            }
        }
    }
    let analog = theirs["analog"].as_array().unwrap();
    let spf = ours.analog.samples_per_frame;
    assert_eq!(analog.len(), if ours.analog.channel_count() > 0 { spf } else { 0 }, "{what}");
    for (s, row) in analog.iter().enumerate() {
        for (c, t) in row.as_array().unwrap().iter().enumerate() {
            let (t, o) =
                (t.as_f64().unwrap(), f64::from(ours.analog.get(frame * spf + s, c).unwrap()));
            assert!((t - o).abs() <= 1e-6 * o.abs().max(1.0), "{what}: analog {s} {c}: {t} vs {o}");
        }
    }
}

#[test]
fn python_c3d_reads_what_we_write() {
    let dir = TempDir::new("python");
    let files = written_files(&dir.0);
    let paths: Vec<PathBuf> = files.iter().map(|(p, _)| p.clone()).collect();
    let Some(json) = python_c3d(&paths) else { return };
    let results = json.as_array().unwrap();
    assert_eq!(results.len(), files.len());
    for ((path, ours), theirs) in files.iter().zip(results) {
        let what = path.display().to_string();
        let n = ours.points.frame_count();
        assert_eq!(theirs["frames"].as_u64(), Some(n as u64), "{what}: frames");
        assert_eq!(theirs["first_frame"].as_u64(), Some(u64::from(ours.first_frame)), "{what}");
        assert_eq!(theirs["points"].as_u64(), Some(ours.points.point_count() as u64), "{what}");
        assert_eq!(
            theirs["point_rate"].as_f64(),
            Some(f64::from(ours.point_rate())),
            "{what}: rate"
        );
        let labels: Vec<&str> =
            theirs["labels"].as_array().unwrap().iter().map(|l| l.as_str().unwrap()).collect();
        assert_eq!(labels, ours.point_labels(), "{what}: labels");
        let channels = ours.analog.channel_count() as u64;
        assert_eq!(theirs["analog_channels"].as_u64(), Some(channels), "{what}: analog channels");
        assert_python_frame(&theirs["first"], ours, 0, &format!("{what} first frame"));
        assert_python_frame(&theirs["last"], ours, n - 1, &format!("{what} last frame"));
    }
}

#[test]
fn more_than_255_points_and_channels_use_continuation_parameters() {
    let labels: Vec<String> = (0..300).map(|i| format!("M{i:03}")).collect();
    let channels: Vec<String> = (0..260).map(|i| format!("A{i}")).collect();
    let mut c = C3d::new(50.0);
    c.points = Points::new(labels.clone(), 2);
    c.points.set(1, 299, Some(Point { position: [1.0, 2.0, 3.0], residual: 0.0, cameras: 1 }));
    c.analog = Analog::new(channels.clone(), 100.0, 2, 2);
    c.analog.set(3, 259, 4.5);
    for format in [Format::INTEL_FLOAT, Format::INTEL_INT] {
        let back = reread(&to_bytes(&c, format));
        assert!(back.parameters.get("POINT", "LABELS2").is_some());
        assert!(back.parameters.get("ANALOG", "SCALE2").is_some());
        assert_eq!(back.point_labels(), &labels[..]);
        assert_eq!(back.analog.labels, channels);
        assert_eq!(back.points.get(1, 299).map(|p| p.position), Some([1.0, 2.0, 3.0]));
        assert_eq!(back.analog.get(3, 259), Some(4.5));
    }
}

#[test]
fn first_frame_outside_the_header_range_goes_to_trial_fields() {
    for first in [0, 70_000] {
        let mut c = scratch();
        c.first_frame = first;
        let back = reread(&to_bytes(&c, Format::INTEL_FLOAT));
        assert_eq!(back.first_frame, first);
        assert_eq!(back.points, c.points);
    }
}

//! The shared C3D samples (see `shared/data/c3d/NOTES.md`).

use std::path::PathBuf;

use c3d::{C3d, DataFormat, EventSource, Processor, Reader};

use crate::shared;

pub fn sample(name: &str) -> Option<PathBuf> {
    shared::shared_file(&format!("data/c3d/{name}"))
}

pub fn read(name: &str) -> Option<C3d> {
    let path = sample(name)?;
    Some(C3d::from_path(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// Every `.c3d` file of the shared folder.
pub fn all_samples() -> Vec<PathBuf> {
    let Some(dir) = shared::shared_file("data/c3d") else { return vec![] };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "c3d"))
        .collect();
    files.sort();
    assert!(files.len() >= 24, "expected the 24 samples of NOTES.md");
    files
}

/// Asserts that two readings of the same recording agree: same validity, positions within
/// `point_tol`, analog within half a quantisation step of the integer variant plus `f32` noise.
fn assert_same_recording(a: &C3d, b: &C3d, point_tol: f32, cameras: bool, what: &str) {
    assert_eq!(a.points.frame_count(), b.points.frame_count(), "{what}: frames");
    assert_eq!(a.point_labels(), b.point_labels(), "{what}: labels");
    for f in 0..a.points.frame_count() {
        for (i, (p, q)) in
            a.points.frame(f).unwrap().iter().zip(b.points.frame(f).unwrap()).enumerate()
        {
            match (p, q) {
                (None, None) => {}
                (Some(p), Some(q)) => {
                    for k in 0..3 {
                        let d = (p.position[k] - q.position[k]).abs();
                        assert!(
                            d <= point_tol,
                            "{what}: frame {f} point {i} axis {k}: {p:?} vs {q:?}"
                        );
                    }
                    assert!(
                        !cameras || p.cameras == q.cameras,
                        "{what}: frame {f} point {i} cameras"
                    );
                    assert!(
                        (p.residual - q.residual).abs() <= point_tol,
                        "{what}: frame {f} point {i} residual"
                    );
                }
                _ => panic!("{what}: frame {f} point {i}: valid in one file only: {p:?} vs {q:?}"),
            }
        }
    }
    assert_eq!(a.analog.channel_count(), b.analog.channel_count(), "{what}: analog channels");
    assert_eq!(a.analog.sample_count(), b.analog.sample_count(), "{what}: analog samples");
    let steps: Vec<f32> = a.parameters.f32s("ANALOG", "SCALE");
    let gen = a.parameters.get("ANALOG", "GEN_SCALE").and_then(|v| v.first_f32()).unwrap_or(1.0);
    for s in 0..a.analog.sample_count() {
        let (xs, ys) = (a.analog.sample(s).unwrap(), b.analog.sample(s).unwrap());
        for (c, ((x, y), step)) in xs.iter().zip(ys).zip(&steps).enumerate() {
            let tol = 0.5 * (step * gen).abs() + 1e-5 * x.abs().max(1.0);
            assert!((x - y).abs() <= tol, "{what}: analog sample {s} channel {c}: {x} vs {y}");
        }
    }
}

#[test]
fn sample01_six_variants_decode_to_the_same_values() {
    let names = ["pi", "pr", "si", "sr", "vi", "vr"].map(|v| format!("c3dorg_s01_Eb015{v}.c3d"));
    let Some(reference) = read(&names[0]) else { return };
    let step = reference.point_scale;
    assert!(step > 0.0 && reference.format == DataFormat::Integer);
    let expected_processor = [
        Processor::Intel,
        Processor::Intel,
        Processor::Mips,
        Processor::Mips,
        Processor::Dec,
        Processor::Dec,
    ];
    for (name, processor) in names.iter().zip(expected_processor) {
        let c = read(name).unwrap();
        assert_eq!(c.processor, processor, "{name}");
        assert_eq!(c.format == DataFormat::Float, name.ends_with("r.c3d"), "{name}");
        assert_eq!((c.points.point_count(), c.points.frame_count()), (26, 450), "{name}");
        assert_eq!(c.point_rate(), 50.0, "{name}");
        let first = c.points.get(0, 0).unwrap().position;
        for (got, want) in first.iter().zip([248.58, 226.83, 37.42]) {
            assert!((got - want).abs() < 0.005, "{name}: first marker {first:?}");
        }
        assert_same_recording(&reference, &c, 0.5 * step + 1e-3, true, name);
        assert!(c.warnings.is_empty(), "{name}: {:?}", c.warnings);
    }
}

#[test]
fn sample02_six_variants_decode_to_the_same_values() {
    let names = ["pc_int", "pc_real", "sgi_int", "sgi_real", "dec_int", "dec_real"]
        .map(|v| format!("c3dorg_s02_{v}.c3d"));
    let Some(reference) = read(&names[0]) else { return };
    let step = reference.point_scale;
    // The stored samples differ by up to one step: the integer files were truncated, not
    // rounded, from the same floats (frame 2 point 7 z: 2043 steps vs 2044.0 × scale), and the
    // DEC integer file has other camera masks (the Python `c3d` package reads the same).
    for name in &names {
        let c = read(name).unwrap();
        assert_eq!((c.points.point_count(), c.points.frame_count()), (36, 89), "{name}");
        assert_eq!(
            (c.analog.channel_count(), c.analog.samples_per_frame, c.force_plate_count()),
            (16, 4, 2),
            "{name}"
        );
        assert_same_recording(&reference, &c, step + 1e-3, false, name);
    }
}

/// File, points, frames, analog channels, header events, `EVENT` group events, force plates.
const TABLE: &[(&str, usize, usize, usize, usize, usize, usize)] = &[
    ("c3dorg_s00_MAC_Sample_Jump2.c3d", 51, 264, 16, 0, 4, 2),
    ("c3dorg_s00_Vicon_pyCGM2_Walking01.c3d", 171, 493, 6, 0, 18, 1),
    ("c3dorg_s01_Eb015pi.c3d", 26, 450, 16, 3, 0, 2),
    ("c3dorg_s02_dec_int.c3d", 36, 89, 16, 8, 0, 2),
    ("c3dorg_s02_pc_real.c3d", 36, 89, 16, 9, 0, 2),
    ("c3dorg_s03_gait-pig-nz.c3d", 85, 301, 18, 0, 7, 3),
    ("c3dorg_s03_gait-pig.c3d", 77, 142, 30, 0, 9, 2),
    ("c3dorg_s07_16bitanalog.c3d", 27, 237, 40, 0, 0, 2),
    ("c3dorg_s13_Dance.c3d", 40, 499, 8, 0, 0, 0),
    ("c3dorg_s16_basketball.c3d", 22, 34, 0, 0, 0, 0),
    ("c3dorg_s35_Mega_EMG_analog_only.c3d", 0, 29, 4, 0, 0, 0),
    ("c3dorg_s37_ART-Human_2persons_integer.c3d", 126, 972, 0, 0, 0, 0),
    ("c3dorg_s37_ART-Human_real.c3d", 63, 966, 0, 0, 0, 0),
    ("ezc3dtest_Qualisys.c3d", 55, 340, 69, 0, 7, 2),
];

#[test]
fn counts_match_the_notes() {
    for &(name, points, frames, channels, header_events, group_events, plates) in TABLE {
        let Some(c) = read(name) else { return };
        let count = |s| c.events.iter().filter(|e| e.source == s).count();
        assert_eq!(
            (c.points.point_count(), c.points.frame_count(), c.analog.channel_count()),
            (points, frames, channels),
            "{name}"
        );
        assert_eq!(
            (count(EventSource::Header), count(EventSource::Parameters)),
            (header_events, group_events),
            "{name}"
        );
        assert_eq!(c.force_plate_count(), plates, "{name}");
        assert_eq!(c.point_labels().len(), points, "{name}");
    }
}

#[test]
fn group_events_have_labels_contexts_and_times() {
    let Some(c) = read("c3dorg_s03_gait-pig.c3d") else { return };
    let events: Vec<_> = c.events.iter().filter(|e| e.source == EventSource::Parameters).collect();
    assert!(events.iter().all(|e| e.label == "Foot Strike" || e.label == "Foot Off"), "{events:?}");
    assert!(events.iter().all(|e| e.context == "Left" || e.context == "Right"), "{events:?}");
    assert!(events.iter().all(|e| e.time > 0.0 && e.time < 10.0), "{events:?}");
}

#[test]
fn non_integer_rate_is_the_stored_f32() {
    let Some(path) = sample("c3dorg_s13_Dance.c3d") else { return };
    let bytes = std::fs::read(&path).unwrap();
    // Header words 11–12 hold the rate (Intel file): decode them independently of the crate.
    let header_rate = f32::from_le_bytes(bytes[20..24].try_into().unwrap());
    let c = C3d::from_path(&path).unwrap();
    assert_eq!(c.point_rate(), header_rate);
    assert_eq!(c.parameters.get("POINT", "RATE").and_then(|v| v.first_f32()), Some(header_rate));
    assert!(c.point_rate() > 65.0 && c.point_rate() < 65.1 && c.point_rate().fract() != 0.0);
}

#[test]
fn invalid_points_are_none_not_zeros() {
    let Some(c) = read("c3dorg_s02_pc_int.c3d") else { return };
    let missing = (0..c.points.frame_count()).filter(|&f| c.points.get(f, 0).is_none()).count();
    assert!(missing > 0, "sample 02 has markers missing in some frames");
    let valid_zero = (0..c.points.frame_count())
        .flat_map(|f| c.points.frame(f).unwrap().iter().flatten().copied().collect::<Vec<_>>())
        .filter(|p| p.position == [0.0; 3] && p.residual < 0.0)
        .count();
    assert_eq!(valid_zero, 0);
}

#[test]
fn analog_offsets_and_scales_are_applied() {
    let Some(c) = read("c3dorg_s07_16bitanalog.c3d") else { return };
    let offsets = c.parameters.i16s("ANALOG", "OFFSET");
    assert!(offsets.iter().any(|&o| o != 0), "the sample sets ANALOG:OFFSET");
    // Recompute channel 0 of sample 0 from the raw float in the file.
    let path = sample("c3dorg_s07_16bitanalog.c3d").unwrap();
    let reader = Reader::new(std::fs::File::open(&path).unwrap()).unwrap();
    let layout = reader.layout().clone();
    let bytes = std::fs::read(&path).unwrap();
    let at = layout.data_start as usize + 4 * 4 * layout.point_count;
    let raw = f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let scales = c.parameters.f32s("ANALOG", "SCALE");
    let gen = c.parameters.get("ANALOG", "GEN_SCALE").unwrap().first_f32().unwrap();
    let want =
        ((f64::from(raw) - f64::from(offsets[0])) * f64::from(scales[0]) * f64::from(gen)) as f32;
    assert_eq!(c.analog.get(0, 0), Some(want));
}

#[test]
fn bad_parameter_section_gives_data_with_a_warning() {
    let Some(c) = read("c3dorg_s18_bad_parameter_section.c3d") else { return };
    assert!(c.warnings.iter().any(|w| w.contains("invalid offset")), "{:?}", c.warnings);
    assert_eq!(
        (c.points.point_count(), c.points.frame_count(), c.analog.channel_count()),
        (45, 332, 32)
    );
    assert_eq!(c.events.iter().filter(|e| e.source == EventSource::Header).count(), 7);
}

#[test]
fn streaming_reader_yields_the_whole_file_frame_by_frame() {
    for name in
        ["c3dorg_s01_Eb015vr.c3d", "ezc3dtest_Qualisys.c3d", "c3dorg_s35_Mega_EMG_analog_only.c3d"]
    {
        let Some(path) = sample(name) else { return };
        let whole = C3d::from_path(&path).unwrap();
        let reader =
            Reader::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap())).unwrap();
        let spf = whole.analog.samples_per_frame;
        let mut n = 0;
        for (i, frame) in reader.enumerate() {
            let frame = frame.unwrap();
            assert_eq!(frame.index, i);
            assert_eq!(frame.number, whole.first_frame + i as u32);
            assert_eq!(frame.points, whole.points.frame(i).unwrap(), "{name} frame {i}");
            let analog: Vec<f32> = (i * spf..(i + 1) * spf)
                .flat_map(|s| whole.analog.sample(s).unwrap().to_vec())
                .collect();
            assert_eq!(frame.analog, analog, "{name} frame {i}");
            n += 1;
        }
        assert_eq!(n, whole.points.frame_count());
    }
}

#[test]
fn every_sample_reads() {
    for path in all_samples() {
        let c = C3d::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(c.points.frame_count() > 0, "{}", path.display());
    }
}

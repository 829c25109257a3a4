//! The shared samples read by us, by the Python `c3d` package and by `c3dio`.

use c3d::C3d;

use crate::read_shared::all_samples;
use crate::write::{assert_python_frame, python_c3d};

/// Samples the Python `c3d` package 0.6.0 cannot read (we can: see `read_shared`).
const PYTHON_FAILS: &[&str] = &[
    // The corrupt parameter item: "read length must be non-negative".
    "c3dorg_s18_bad_parameter_section.c3d",
    // No POINT data: "buffer is smaller than requested size".
    "c3dorg_s35_Mega_EMG_analog_only.c3d",
    // TRIAL:ACTUAL_START_FIELD is not a 2-element array there: a TypeError.
    "c3dorg_s37_ART-Human_2persons_integer.c3d",
    "c3dorg_s37_ART-Human_real.c3d",
];

/// Python `c3d` stops reading parameters at POINT:DESCRIPTIONS, a 0 × 40 char array, and so
/// misses the ANALOG group, whose GEN_SCALE is −1: its analog values have the opposite sign.
/// Points are compared, analog is checked to be exactly negated.
const PYTHON_MISSES_ANALOG_GROUP: &str = "c3dorg_s13_Dance.c3d";

#[test]
fn python_c3d_agrees_on_the_shared_samples() {
    let files = all_samples();
    if files.is_empty() {
        return;
    }
    let Some(json) = python_c3d(&files) else { return };
    for (path, theirs) in files.iter().zip(json.as_array().unwrap()) {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if let Some(error) = theirs["error"].as_str() {
            assert!(PYTHON_FAILS.contains(&name.as_str()), "{name}: python fails: {error}");
            assert!(C3d::from_path(path).is_ok());
            continue;
        }
        assert!(!PYTHON_FAILS.contains(&name.as_str()), "{name}: python reads it now");
        let mut ours = C3d::from_path(path).unwrap();
        if name == PYTHON_MISSES_ANALOG_GROUP {
            let gen = ours.parameters.get("ANALOG", "GEN_SCALE").and_then(|v| v.first_f32());
            assert_eq!(gen, Some(-1.0));
            for s in 0..ours.analog.sample_count() {
                for c in 0..ours.analog.channel_count() {
                    let v = ours.analog.get(s, c).unwrap();
                    ours.analog.set(s, c, -v);
                }
            }
        }
        let n = ours.points.frame_count();
        assert_eq!(theirs["frames"].as_u64(), Some(n as u64), "{name}: frames");
        assert_eq!(theirs["points"].as_u64(), Some(ours.points.point_count() as u64), "{name}");
        let channels = ours.analog.channel_count() as u64;
        assert_eq!(theirs["analog_channels"].as_u64(), Some(channels), "{name}: analog channels");
        let labels: Vec<&str> =
            theirs["labels"].as_array().unwrap().iter().map(|l| l.as_str().unwrap()).collect();
        let k = ours.points.point_count().min(labels.len());
        assert_eq!(&labels[..k], &ours.point_labels()[..k], "{name}: labels");
        assert_python_frame(&theirs["first"], &ours, 0, &format!("{name} first frame"));
        assert_python_frame(&theirs["last"], &ours, n - 1, &format!("{name} last frame"));
    }
}

/// Samples `c3dio` 0.8 refuses (we read them: see `read_shared`).
const C3DIO_FAILS: &[(&str, &str)] = &[
    ("c3dorg_s13_Dance.c3d", "ANALOG:OFFSET stored as floats"),
    ("c3dorg_s16_basketball.c3d", "no POINT:UNITS"),
    ("c3dorg_s18_bad_parameter_section.c3d", "the corrupt parameter item"),
];

#[test]
fn c3dio_agrees_on_the_shared_samples() {
    for path in all_samples() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let ours = C3d::from_path(&path).unwrap();
        let expected_failure = C3DIO_FAILS.iter().any(|(n, _)| *n == name);
        let theirs = match c3dio::C3d::load_path(path.clone()) {
            Ok(c) => c,
            Err(e) => {
                assert!(expected_failure, "{name}: c3dio fails: {e:?}");
                continue;
            }
        };
        assert!(!expected_failure, "{name}: c3dio reads it now");
        let grid = &theirs.points.points;
        assert_eq!(grid.cols(), ours.points.point_count(), "{name}: points");
        if grid.cols() > 0 {
            assert_eq!(grid.rows(), ours.points.frame_count(), "{name}: frames");
        }
        for f in 0..grid.rows() {
            for p in 0..grid.cols() {
                if let Some(o) = ours.points.get(f, p) {
                    assert_eq!(grid[f][p].point, o.position, "{name}: frame {f} point {p}");
                }
            }
        }
    }
}

//! Marker-driven human motion: labelled optical markers (e.g. from a C3D file) become
//! *virtual bodies*, one per set of markers, that the retargeter tracks like FK bodies.
//!
//! - position: centroid of the body's markers present in the frame; when none is present,
//!   linear interpolation of that centroid over the gap (held at the clip's ends);
//! - orientation: from three markers `a b c` (gap-filled the same way, one by one):
//!   `x = (b − a)/‖·‖`, `z = x × (c − a)/‖·‖`, `y = z × x`; identity without a frame.
//!
//! Inputs are plain data (no IO): labels, `frames × points` of optional positions in file
//! units and lab axes, a unit scale and an axis rotation into our world (metres, Z up).

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use crate::HumanMotion;

/// One virtual body: `name` is what IK configs refer to.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerBody {
    pub name: String,
    pub markers: Vec<String>,
    /// Three markers `a b c` defining an orientation (see the module docs).
    pub frame: Option<[String; 3]>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MarkerError {
    #[error("body `{body}`: marker `{marker}` is not among the file's labels")]
    UnknownMarker { body: String, marker: String },
    #[error("body `{body}`: none of its markers is seen in any frame")]
    NeverSeen { body: String },
    #[error("body `{body}`: marker `{marker}` is never seen")]
    FrameMarkerNeverSeen { body: String, marker: String },
    #[error("body `{0}` has no markers")]
    NoMarkers(String),
    #[error("the marker data has no frames")]
    NoFrames,
    #[error("frame {frame} has {got} points, expected {expected}")]
    Shape { frame: usize, got: usize, expected: usize },
    /// A marker config's `metres_per_unit` that is not a positive finite number.
    #[error("metres_per_unit = {0}: must be a positive finite number")]
    BadUnit(f64),
    /// A point rate (frames per second) that is not a positive finite number.
    #[error("point rate {0}: must be a positive finite number of frames per second")]
    BadRate(f64),
    /// Height landmarks (`top` or `bottom` markers) none of which is seen in any frame.
    #[error("none of the height markers {} is seen in any frame", .0.join(", "))]
    HeightNeverSeen(Vec<String>),
    #[error("body `{body}`, frame {frame}: frame markers are collinear or coincide")]
    DegenerateFrame { body: String, frame: usize },
    /// A marker absurdly far from the origin (more than [`crate::MAX_DISTANCE`] in metres).
    #[error("frame {frame}: marker `{marker}` is {distance:.3e} m from the origin (more than {} km): a corrupt value or a wrong unit", crate::MAX_DISTANCE / 1e3)]
    AbsurdMarker { frame: usize, marker: String, distance: f64 },
    /// The virtual bodies' motion fails [`HumanMotion::validate`].
    #[error(transparent)]
    Motion(#[from] crate::Error),
}

/// The rotation taking a lab frame to ours (Z up): `"z-up"` (identity) or `"y-up"`
/// (+90° about X: `(x, y, z) → (x, −z, y)`).
#[must_use]
pub fn axes_rotation(name: &str) -> Option<UnitQuaternion<f64>> {
    match name.to_ascii_lowercase().as_str() {
        "z-up" | "zup" | "z" => Some(UnitQuaternion::identity()),
        "y-up" | "yup" | "y" => {
            Some(UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2))
        }
        _ => None,
    }
}

/// Marker data converted to our world: per frame, per label, metres and Z up. Non-finite
/// coordinates count as occluded; a finite one farther than [`crate::MAX_DISTANCE`] is an
/// error naming the frame and marker.
fn to_world(
    frames: &[Vec<Option<[f64; 3]>>],
    labels: &[String],
    metres_per_unit: f64,
    axes: &UnitQuaternion<f64>,
) -> Result<Vec<Vec<Option<Vector3<f64>>>>, MarkerError> {
    if !(metres_per_unit.is_finite() && metres_per_unit > 0.0) {
        return Err(MarkerError::BadUnit(metres_per_unit));
    }
    frames
        .iter()
        .enumerate()
        .map(|(f, row)| {
            if row.len() != labels.len() {
                return Err(MarkerError::Shape {
                    frame: f,
                    got: row.len(),
                    expected: labels.len(),
                });
            }
            row.iter()
                .zip(labels)
                .map(|(p, label)| {
                    let Some(p) = p.filter(|p| p.iter().all(|v| v.is_finite())) else {
                        return Ok(None);
                    };
                    let p = axes * (Vector3::from(p) * metres_per_unit);
                    let distance = crate::motion::robust_norm(&p);
                    if distance <= crate::MAX_DISTANCE {
                        Ok(Some(p))
                    } else {
                        Err(MarkerError::AbsurdMarker { frame: f, marker: label.clone(), distance })
                    }
                })
                .collect()
        })
        .collect()
}

/// Fills the gaps of a per-frame series linearly; holds the first/last value at the ends.
/// `None` if no frame has a value.
fn fill_gaps(series: &[Option<Vector3<f64>>]) -> Option<Vec<Vector3<f64>>> {
    let known: Vec<(usize, Vector3<f64>)> =
        series.iter().enumerate().filter_map(|(f, v)| Some((f, (*v)?))).collect();
    let (&(first, at_first), &(last, at_last)) = (known.first()?, known.last()?);
    let mut out = Vec::with_capacity(series.len());
    let mut next = 0; // index into `known` of the first known frame >= f
    for (f, value) in series.iter().enumerate() {
        while known.get(next).is_some_and(|&(k, _)| k < f) && next + 1 < known.len() {
            next += 1;
        }
        let v = match (value, known.get(next.wrapping_sub(1)), known.get(next)) {
            (Some(v), _, _) => *v,
            (None, _, _) if f < first => at_first,
            (None, _, _) if f > last => at_last,
            (None, Some(&(a, va)), Some(&(b, vb))) => {
                let t = (f - a) as f64 / (b - a) as f64;
                va * (1.0 - t) + vb * t
            }
            (None, _, _) => at_last,
        };
        out.push(v);
    }
    Some(out)
}

fn find(labels: &[String], body: &str, marker: &str) -> Result<usize, MarkerError> {
    labels.iter().position(|l| l.trim() == marker).ok_or_else(|| MarkerError::UnknownMarker {
        body: body.to_owned(),
        marker: marker.to_owned(),
    })
}

/// Builds the virtual bodies' motion. `frames[f][p]` is marker `labels[p]` at frame `f`
/// (file units, lab axes; `None` when occluded). Orientations are made continuous in time.
/// Absurd marker positions and body motions are errors ([`HumanMotion::validate`]).
pub fn marker_motion(
    labels: &[String],
    frames: &[Vec<Option<[f64; 3]>>],
    fps: f64,
    metres_per_unit: f64,
    axes: &UnitQuaternion<f64>,
    bodies: &[MarkerBody],
) -> Result<HumanMotion, MarkerError> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(MarkerError::BadRate(fps));
    }
    if frames.is_empty() {
        return Err(MarkerError::NoFrames);
    }
    let world = to_world(frames, labels, metres_per_unit, axes)?;
    let nf = frames.len();
    let nb = bodies.len();
    let mut positions = vec![Vector3::zeros(); nf * nb];
    let mut orientations = vec![UnitQuaternion::identity(); nf * nb];
    for (b, body) in bodies.iter().enumerate() {
        if body.markers.is_empty() {
            return Err(MarkerError::NoMarkers(body.name.clone()));
        }
        let idx: Vec<usize> =
            body.markers.iter().map(|m| find(labels, &body.name, m)).collect::<Result<_, _>>()?;
        let centroid: Vec<Option<Vector3<f64>>> = world
            .iter()
            .map(|row| {
                let present: Vec<Vector3<f64>> =
                    idx.iter().filter_map(|&i| row.get(i).copied().flatten()).collect();
                (!present.is_empty())
                    .then(|| present.iter().sum::<Vector3<f64>>() / present.len() as f64)
            })
            .collect();
        let filled = fill_gaps(&centroid)
            .ok_or_else(|| MarkerError::NeverSeen { body: body.name.clone() })?;
        for (slot, p) in positions.iter_mut().skip(b).step_by(nb).zip(filled) {
            *slot = p;
        }
        let Some(frame) = &body.frame else { continue };
        let mut tracks: Vec<Vec<Vector3<f64>>> = Vec::with_capacity(3);
        for m in frame {
            let i = find(labels, &body.name, m)?;
            let series: Vec<Option<Vector3<f64>>> =
                world.iter().map(|row| row.get(i).copied().flatten()).collect();
            tracks.push(fill_gaps(&series).ok_or_else(|| MarkerError::FrameMarkerNeverSeen {
                body: body.name.clone(),
                marker: m.clone(),
            })?);
        }
        let [ta, tb, tc] = tracks.as_slice() else { continue };
        let mut previous: Option<UnitQuaternion<f64>> = None;
        let slots = orientations.iter_mut().skip(b).step_by(nb);
        for (f, (((a, bb), c), slot)) in ta.iter().zip(tb).zip(tc).zip(slots).enumerate() {
            let q = triad(a, bb, c).ok_or_else(|| MarkerError::DegenerateFrame {
                body: body.name.clone(),
                frame: f,
            })?;
            let q = match previous {
                Some(p) if p.coords.dot(&q.coords) < 0.0 => {
                    UnitQuaternion::new_unchecked(-q.into_inner())
                }
                _ => q,
            };
            *slot = q;
            previous = Some(q);
        }
    }
    let motion = HumanMotion {
        fps,
        body_names: bodies.iter().map(|b| b.name.clone()).collect(),
        num_frames: nf,
        positions,
        orientations,
    };
    motion.validate()?;
    Ok(motion)
}

/// The orientation of the triad `a b c` (module docs); `None` when degenerate.
#[must_use]
pub fn triad(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> Option<UnitQuaternion<f64>> {
    let x = (b - a).try_normalize(1e-9)?;
    let z = x.cross(&(c - a)).try_normalize(1e-9)?;
    let y = z.cross(&x);
    let m = Matrix3::from_columns(&[x, y, z]);
    Some(UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m)))
}

/// Height of landmark markers above the floor: the median over frames of the highest `top`
/// marker, minus the lowest `bottom` marker over the clip (metres, after the axis rotation).
/// The caller turns it into a stature (e.g. ASIS height ≈ 0.555 × stature).
/// [`MarkerError::HeightNeverSeen`] when either set is never seen.
pub fn marker_height(
    labels: &[String],
    frames: &[Vec<Option<[f64; 3]>>],
    metres_per_unit: f64,
    axes: &UnitQuaternion<f64>,
    top: &[String],
    bottom: &[String],
) -> Result<f64, MarkerError> {
    let world = to_world(frames, labels, metres_per_unit, axes)?;
    let never_seen = |set: &[String]| MarkerError::HeightNeverSeen(set.to_vec());
    let (top_names, bottom_names) = (top, bottom);
    let top: Vec<usize> =
        top.iter().map(|m| find(labels, "height", m)).collect::<Result<_, _>>()?;
    let bottom: Vec<usize> =
        bottom.iter().map(|m| find(labels, "height", m)).collect::<Result<_, _>>()?;
    let mut tops: Vec<f64> = world
        .iter()
        .filter_map(|row| {
            top.iter().filter_map(|&i| row.get(i).copied().flatten().map(|p| p.z)).reduce(f64::max)
        })
        .collect();
    let floor = world
        .iter()
        .filter_map(|row| {
            bottom
                .iter()
                .filter_map(|&i| row.get(i).copied().flatten().map(|p| p.z))
                .reduce(f64::min)
        })
        .reduce(f64::min);
    let floor = floor.ok_or_else(|| never_seen(bottom_names))?;
    tops.sort_by(f64::total_cmp);
    tops.get(tops.len() / 2).map(|top| top - floor).ok_or_else(|| never_seen(top_names))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(names: &[&str]) -> Vec<String> {
        names.iter().map(|s| (*s).to_owned()).collect()
    }

    #[test]
    fn centroid_gaps_and_frame() {
        let l = labels(&["A", "B", "C"]);
        // Frame 0: all; frame 1: B missing (centroid of A and C); frames 2-3: none of the
        // body's markers (A, B) → interpolated between frame 1 and frame 4.
        let frames = vec![
            vec![Some([0.0, 0.0, 0.0]), Some([1000.0, 0.0, 0.0]), Some([0.0, 1000.0, 0.0])],
            vec![Some([0.0, 0.0, 0.0]), None, Some([0.0, 1000.0, 0.0])],
            vec![None, None, Some([0.0, 1000.0, 0.0])],
            vec![None, None, Some([0.0, 1000.0, 0.0])],
            vec![Some([200.0, 0.0, 0.0]), Some([400.0, 0.0, 0.0]), Some([0.0, 1000.0, 0.0])],
        ];
        let bodies = vec![
            MarkerBody { name: "AB".into(), markers: labels(&["A", "B"]), frame: None },
            MarkerBody { name: "ABC".into(), markers: labels(&["A", "B", "C"]), frame: None },
            MarkerBody {
                name: "F".into(),
                markers: labels(&["A"]),
                frame: Some(["A".into(), "B".into(), "C".into()]),
            },
        ];
        let id = UnitQuaternion::identity();
        let m = marker_motion(&l, &frames, 100.0, 0.001, &id, &bodies).unwrap();
        assert_eq!(m.num_frames, 5);
        let x = |f: usize, b: usize| m.position(f, b).x;
        assert!((x(0, 0) - 0.5).abs() < 1e-12);
        assert!((x(1, 0) - 0.0).abs() < 1e-12);
        assert!((x(2, 0) - 0.1).abs() < 1e-12);
        assert!((x(3, 0) - 0.2).abs() < 1e-12);
        assert!((x(4, 0) - 0.3).abs() < 1e-12);
        assert!((m.position(1, 1) - Vector3::new(0.0, 0.5, 0.0)).norm() < 1e-12);
        // Frame of A→B (x), C: at frame 0 the identity.
        assert!(m.orientation(0, 2).angle_to(&id) < 1e-9);
        // Frame 2: A and B gap-filled one by one; still along +x, so still the identity.
        assert!(m.orientation(2, 2).angle_to(&id) < 1e-9);
        // Y-up input: the lab's y becomes our z.
        let up = axes_rotation("y-up").unwrap();
        let m = marker_motion(&l, &frames, 100.0, 0.001, &up, &bodies).unwrap();
        assert!((m.position(1, 1) - Vector3::new(0.0, 0.0, 0.5)).norm() < 1e-12);
        // Errors: unknown marker, a body never seen.
        let bad = vec![MarkerBody { name: "X".into(), markers: labels(&["Z"]), frame: None }];
        assert!(matches!(
            marker_motion(&l, &frames, 100.0, 0.001, &id, &bad),
            Err(MarkerError::UnknownMarker { .. })
        ));
        let never = vec![vec![None, Some([0.0; 3]), Some([0.0; 3])]; 3];
        let only_a = vec![MarkerBody { name: "A".into(), markers: labels(&["A"]), frame: None }];
        assert!(matches!(
            marker_motion(&l, &never, 100.0, 0.001, &id, &only_a),
            Err(MarkerError::NeverSeen { .. })
        ));
    }

    #[test]
    fn absurd_markers_and_jumps_are_errors_naming_the_frame() {
        let l = labels(&["A", "B"]);
        let id = UnitQuaternion::identity();
        let bodies = vec![MarkerBody { name: "AB".into(), markers: l.clone(), frame: None }];
        let mut frames = vec![vec![Some([0.0, 0.0, 1000.0]), Some([100.0, 0.0, 1000.0])]; 4];
        assert!(marker_motion(&l, &frames, 100.0, 0.001, &id, &bodies).is_ok());
        // 1e300 mm: a corrupt number, named with its frame and marker.
        frames[2][1] = Some([1e300, 0.0, 0.0]);
        let err = marker_motion(&l, &frames, 100.0, 0.001, &id, &bodies).unwrap_err();
        assert!(
            matches!(&err, MarkerError::AbsurdMarker { frame: 2, marker, .. } if marker == "B"),
            "{err:?}"
        );
        assert!(err.to_string().starts_with("frame 2: marker `B` is 1.000e297 m"), "{err}");
        // 1 km in one frame (within the distance bound): the body's motion is refused.
        frames[2][1] = Some([2e6, 0.0, 1000.0]);
        let err = marker_motion(&l, &frames, 100.0, 0.001, &id, &bodies).unwrap_err();
        assert!(
            matches!(&err, MarkerError::Motion(crate::Error::AbsurdStep { frame: 2, body, .. }) if body == "AB"),
            "{err:?}"
        );
        // Non-finite values are occlusions, as before.
        frames[2][1] = Some([f64::NAN, 0.0, 0.0]);
        assert!(marker_motion(&l, &frames, 100.0, 0.001, &id, &bodies).is_ok());
    }

    #[test]
    fn triad_axes() {
        let q =
            triad(&Vector3::zeros(), &Vector3::new(0.0, 2.0, 0.0), &Vector3::new(-1.0, 1.0, 0.0))
                .unwrap();
        // x along +y, z = y × (−x, y) ∝ +z, y = z × x = −x.
        assert!((q * Vector3::x() - Vector3::y()).norm() < 1e-12);
        assert!((q * Vector3::z() - Vector3::z()).norm() < 1e-12);
        assert!(triad(&Vector3::zeros(), &Vector3::x(), &(Vector3::x() * 2.0)).is_none());
    }
}

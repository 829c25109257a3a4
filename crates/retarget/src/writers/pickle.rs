//! GMR's pickle (`scripts/bvh_to_robot.py` in YanjieZe/GMR): a dict
//! `{"fps": float, "root_pos": (T,3), "root_rot": (T,4) x y z w, "dof_pos": (T,n),
//! "local_body_pos": (T,B,3), "link_body_list": [B names]}` whose arrays are numpy float64.
//! GMR itself stores `local_body_pos = None` and `link_body_list = None`; we fill them as its
//! FK-enriched variants do: every body's position in the root frame
//! (`R_rootᵀ (xpos − root_pos)`, the pose FK gives with the root at the origin, unrotated).
//!
//! The pickle is written by hand with protocol 3 opcodes (protocol 2 has no bytes opcode, so
//! raw array data would become latin-1 text). An array is built the way numpy's own
//! `__reduce__` state works, through public names only: `numpy.ndarray((0,))` (REDUCE), then
//! `BUILD` with the state `(1, shape, numpy.dtype('<f8'), False, raw bytes)`, which calls
//! `ndarray.__setstate__`. `numpy.ndarray` and `numpy.dtype` resolve the same on numpy 1.x
//! and 2.x (unlike `numpy.core.multiarray._reconstruct`, which numpy 2 moved to `numpy._core`).

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use super::derived::body_poses;
use super::root::{root_nq, root_pose, xyzw_from_wxyz};
use crate::motion::RobotMotion;
use crate::Error;

const PROTO: u8 = 0x80;
const EMPTY_DICT: u8 = b'}';
const EMPTY_LIST: u8 = b']';
const MARK: u8 = b'(';
const SETITEMS: u8 = b'u';
const APPENDS: u8 = b'e';
const TUPLE: u8 = b't';
const TUPLE1: u8 = 0x85;
const BININT: u8 = b'J';
const LONG1: u8 = 0x8a;
const BINFLOAT: u8 = b'G';
const BINUNICODE: u8 = b'X';
const BINBYTES: u8 = b'B';
const GLOBAL: u8 = b'c';
const REDUCE: u8 = b'R';
const BUILD: u8 = b'b';
const NEWFALSE: u8 = 0x89;
const NONE: u8 = b'N';
const STOP: u8 = b'.';

/// The bytes of a GMR pickle of `motion`.
pub(crate) fn motion_pickle(motion: &RobotMotion, model: &mjcf::Model) -> Result<Vec<u8>, Error> {
    let frames = motion.num_frames();
    let poses = body_poses(motion, model);
    let skip = root_nq(model);
    let (mut root_pos, mut root_rot, mut local) = (Vec::new(), Vec::new(), Vec::new());
    for t in 0..frames {
        let (p, q) = root_pose(motion, model, &poses, t);
        root_pos.extend_from_slice(&p);
        root_rot.extend_from_slice(&xyzw_from_wxyz(q));
        // Local positions use the normalised root pose FK computed (xpos/xquat of body 1).
        let (origin, rot) = (poses.pos(t, 0), poses.quat(t, 0));
        for b in 0..poses.bodies {
            let v = rot.inverse_transform_vector(&(poses.pos(t, b) - origin));
            local.extend_from_slice(&[v.x, v.y, v.z]);
        }
    }
    let dof_pos: Vec<f64> = (0..frames)
        .flat_map(|t| motion.frame(t).get(skip..).unwrap_or_default().to_vec())
        .collect();

    let mut p = Pickler::default();
    p.out.extend_from_slice(&[PROTO, 3, EMPTY_DICT, MARK]);
    p.string("fps");
    p.float(motion.fps);
    p.string("root_pos");
    p.array(&[frames, 3], &root_pos)?;
    p.string("root_rot");
    p.array(&[frames, 4], &root_rot)?;
    p.string("dof_pos");
    p.array(&[frames, motion.nq - skip], &dof_pos)?;
    p.string("local_body_pos");
    if poses.bodies == 0 {
        p.out.push(NONE);
    } else {
        p.array(&[frames, poses.bodies, 3], &local)?;
    }
    p.string("link_body_list");
    p.string_list(&motion.body_names);
    p.out.extend_from_slice(&[SETITEMS, STOP]);
    Ok(p.out)
}

#[derive(Default)]
struct Pickler {
    out: Vec<u8>,
}

impl Pickler {
    fn string(&mut self, s: &str) {
        self.out.push(BINUNICODE);
        self.out.extend_from_slice(&(s.len() as u32).to_le_bytes());
        self.out.extend_from_slice(s.as_bytes());
    }

    fn float(&mut self, v: f64) {
        self.out.push(BINFLOAT);
        self.out.extend_from_slice(&v.to_be_bytes());
    }

    fn int(&mut self, v: usize) {
        match i32::try_from(v) {
            Ok(small) => {
                self.out.push(BININT);
                self.out.extend_from_slice(&small.to_le_bytes());
            }
            Err(_) => {
                // Little-endian two's complement; 9 bytes hold any u64 as a positive number.
                self.out.extend_from_slice(&[LONG1, 9]);
                self.out.extend_from_slice(&(v as u64).to_le_bytes());
                self.out.push(0);
            }
        }
    }

    fn global(&mut self, module: &str, name: &str) {
        self.out.push(GLOBAL);
        self.out.extend_from_slice(format!("{module}\n{name}\n").as_bytes());
    }

    fn string_list(&mut self, items: &[String]) {
        self.out.extend_from_slice(&[EMPTY_LIST, MARK]);
        for s in items {
            self.string(s);
        }
        self.out.push(APPENDS);
    }

    /// A C-order float64 numpy array: `numpy.ndarray((0,))` then `__setstate__`.
    fn array(&mut self, shape: &[usize], data: &[f64]) -> Result<(), Error> {
        let raw_len = u32::try_from(data.len() * 8)
            .map_err(|_| Error::Mismatch("an array exceeds the pickle's 4 GiB limit".to_owned()))?;
        self.global("numpy", "ndarray");
        self.int(0);
        self.out.extend_from_slice(&[TUPLE1, TUPLE1, REDUCE, MARK]);
        self.int(1);
        self.out.push(MARK);
        for &d in shape {
            self.int(d);
        }
        self.out.push(TUPLE);
        self.global("numpy", "dtype");
        self.string("<f8");
        self.out.extend_from_slice(&[TUPLE1, REDUCE, NEWFALSE, BINBYTES]);
        self.out.extend_from_slice(&raw_len.to_le_bytes());
        data.iter().for_each(|v| self.out.extend_from_slice(&v.to_le_bytes()));
        self.out.extend_from_slice(&[TUPLE, BUILD]);
        Ok(())
    }
}

//! numpy's `.npy` arrays and `.npz` archives (a zip of `<key>.npy` members): the one reader
//! and writer of the workspace.
//!
//! Reading ([`Npz`]) is one member at a time and only the members asked for: a body model's
//! `posedirs` (122 MB in SMPL-X) is never decompressed, and `shapedirs` (100 MB) is streamed
//! row by row ([`Npz::rows`]). Every dtype real files use is read: floats (`f2`, `f4`, `f8`),
//! integers (1 to 8 bytes, signed or not), bools, unicode (`U`) and byte (`S`) strings, either
//! byte order, C or Fortran order (returned in C order). Pickled object arrays are an error,
//! never unpickled.
//!
//! Writing ([`write()`], [`Array::to_npy`]) is numpy's own layout: `numpy.savez`'s stored
//! members, `numpy.save`'s header padded so the data starts 64-byte aligned, float64 (`<f8`),
//! bool (`|b1`) and unicode (`<U`n) arrays.
//!
//! Why not `npyz` or `ndarray-npy`: both read a whole member into one typed array, so the
//! rows reader would still be ours, and a caller would still need a dispatch over the
//! dtypes real files use to get `f64`s; `npyz`'s npz support would also pull in a second
//! `zip` version. The format itself is small (numpy's NEP 1: magic, version, a Python-dict
//! header, raw C- or Fortran-order data).
//!
//! Allocation: element counts come from headers, so nothing is allocated from them; buffers
//! grow with the data actually decompressed (a crafted header is an error, not an
//! allocation). Errors name the file and the member ([`Error`]). This crate never prints and
//! never panics on input.
//!
//! ```no_run
//! let mut npz = npz::Npz::open(std::path::Path::new("motion.npz"))?;
//! let (shape, qpos) = npz.floats("qpos")?; // C order, any numeric dtype as f64
//! let names = npz.strings("joint_names")?;
//! # Ok::<(), npz::Error>(())
//! ```

// Library code never panics on input (issue 15): the compiler checks it. Tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod array;
mod dtype;
mod error;
mod npy;
mod read;
mod write;

pub use array::{Array, ArrayData};
pub use dtype::Dtype;
pub use error::{Error, Problem};
pub use npy::Header;
pub use read::Npz;
pub use write::write;

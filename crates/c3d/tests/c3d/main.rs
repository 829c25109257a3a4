//! Reading the shared C3D samples, writing, and cross-reading what we write with `c3dio` and
//! the Python `c3d` package.

#[path = "../../../../tests/support/shared.rs"]
mod shared;

mod cross_shared;
mod fuzz;
mod read_shared;
mod write;

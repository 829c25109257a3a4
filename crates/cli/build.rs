//! With the `mujoco` feature, bake the directory of `libmujoco.so` (MUJOCO_DYNAMIC_LINK_DIR,
//! set by `.cargo/config.toml`) into the `retarget` binary and its tests as an rpath, so they run without
//! LD_LIBRARY_PATH. mujoco-rs itself only adds the link search path.

fn main() {
    println!("cargo:rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    println!("cargo:rerun-if-env-changed=CARGO_FEATURE_MUJOCO");
    if std::env::var_os("CARGO_FEATURE_MUJOCO").is_none() {
        return;
    }
    if let Some(dir) = std::env::var_os("MUJOCO_DYNAMIC_LINK_DIR") {
        let dir = std::path::PathBuf::from(dir);
        let dir = std::fs::canonicalize(&dir).unwrap_or(dir);
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
    }
}

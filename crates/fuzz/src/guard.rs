//! An allocator that refuses, while an input is being parsed, any single allocation larger
//! than [`ALLOCATION_LIMIT`]. Inputs are at most a few hundred KB, so such an allocation can
//! only come from a count read from the file and trusted (the `<U0` npz bug asked for
//! 2.4 PB): the guard saves the input and refuses, which aborts the process
//! (`handle_alloc_error`), so the run fails loudly instead of swapping or passing by luck.
//!
//! The binary and the tests opt in with
//! `#[global_allocator] static ALLOC: fuzz::GuardedAlloc = fuzz::GuardedAlloc;`.

// An allocator is `unsafe` by definition (`GlobalAlloc`), and the failure path may not
// allocate, so it writes through `libc` directly. Each block states why it is sound.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::CString;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
use std::sync::OnceLock;

/// Largest single allocation allowed while an input runs: 256 MiB, over 1000× the largest
/// input the harness makes.
pub const ALLOCATION_LIMIT: usize = 256 << 20;

static ARMED: AtomicBool = AtomicBool::new(false);
static INPUT: AtomicPtr<u8> = AtomicPtr::new(std::ptr::null_mut());
static INPUT_LEN: AtomicUsize = AtomicUsize::new(0);
static CRASH_FILE: OnceLock<CString> = OnceLock::new();

/// [`System`] with the limit above while armed.
pub struct GuardedAlloc;

// SAFETY: every method forwards to `System` with the same arguments; the only addition is
// returning null (a documented allocation failure) for oversized requests while armed.
unsafe impl GlobalAlloc for GuardedAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > ALLOCATION_LIMIT && ARMED.load(Ordering::Relaxed) {
            report(layout.size());
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's contract for `alloc` is passed on unchanged.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > ALLOCATION_LIMIT && ARMED.load(Ordering::Relaxed) {
            report(layout.size());
            return std::ptr::null_mut();
        }
        // SAFETY: as `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` through this allocator with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > ALLOCATION_LIMIT && ARMED.load(Ordering::Relaxed) {
            report(new_size);
            return std::ptr::null_mut();
        }
        // SAFETY: as `dealloc`, and the caller's contract for `realloc` holds.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Where an oversized allocation or an abort saves the input (`<dir>/abort-<target>.bin`).
pub fn set_crash_dir(target: &str, dir: Option<&Path>) {
    if let Some(dir) = dir {
        let _ = std::fs::create_dir_all(dir);
        let path = dir.join(format!("abort-{target}.bin"));
        if let Ok(c) = CString::new(path.to_string_lossy().into_owned()) {
            let _ = CRASH_FILE.set(c);
        }
    }
}

/// Watch allocations while `input` (which must stay alive until [`disarm`]) is parsed.
pub fn arm(input: &[u8]) {
    INPUT.store(input.as_ptr().cast_mut(), Ordering::SeqCst);
    INPUT_LEN.store(input.len(), Ordering::SeqCst);
    ARMED.store(true, Ordering::SeqCst);
}

pub fn disarm() {
    ARMED.store(false, Ordering::SeqCst);
    INPUT.store(std::ptr::null_mut(), Ordering::SeqCst);
    INPUT_LEN.store(0, Ordering::SeqCst);
}

/// Saves the input being parsed when the process aborts (a refused allocation, a panic
/// while unwinding, a stack overflow): Rust ends all of these with `abort()`, i.e. SIGABRT.
pub fn save_input_on_abort() {
    extern "C" fn on_abort(_: libc::c_int) {
        write_stderr(b"ABORT while parsing an input; it is saved as abort-<target>.bin\n");
        save_input();
        // SAFETY: restoring the default disposition and re-raising is async-signal-safe.
        unsafe {
            libc::signal(libc::SIGABRT, libc::SIG_DFL);
            libc::raise(libc::SIGABRT);
        }
    }
    // SAFETY: `on_abort` only calls async-signal-safe functions (write, open, close, signal,
    // raise) and reads atomics.
    unsafe {
        libc::signal(libc::SIGABRT, on_abort as extern "C" fn(libc::c_int) as libc::sighandler_t);
    }
}

fn write_stderr(bytes: &[u8]) {
    // SAFETY: writes `bytes.len()` initialised bytes to stderr.
    unsafe { libc::write(2, bytes.as_ptr().cast(), bytes.len()) };
}

/// Writes the armed input to the crash file, without allocating.
fn save_input() {
    let (ptr, len) = (INPUT.load(Ordering::SeqCst), INPUT_LEN.load(Ordering::SeqCst));
    if let (Some(path), false) = (CRASH_FILE.get(), ptr.is_null()) {
        // SAFETY: `path` is a NUL-terminated C string; `ptr..ptr+len` is the armed input,
        // alive until `disarm` (the parse that fails runs before it).
        unsafe {
            let fd =
                libc::open(path.as_ptr(), libc::O_WRONLY | libc::O_CREAT | libc::O_TRUNC, 0o644);
            if fd >= 0 {
                libc::write(fd, ptr.cast(), len);
                libc::close(fd);
            }
        }
    }
}

/// Saves the current input and says why, without allocating.
fn report(size: usize) {
    ARMED.store(false, Ordering::SeqCst);
    let mut digits = [0u8; 20];
    let mut n = size;
    let mut at = digits.len();
    loop {
        at -= 1;
        if let Some(d) = digits.get_mut(at) {
            *d = b'0' + (n % 10) as u8;
        }
        n /= 10;
        if n == 0 || at == 0 {
            break;
        }
    }
    let parts: [&[u8]; 3] = [
        b"ABORT: an input asked for one allocation of ",
        digits.get(at..).unwrap_or_default(),
        b" bytes (over the fuzz limit); the input is saved as abort-<target>.bin\n",
    ];
    for part in parts {
        write_stderr(part);
    }
    save_input();
}

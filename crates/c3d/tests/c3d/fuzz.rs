//! Mutation fuzzing of the reader on the shared samples: byte flips, truncation and random
//! 16-bit values in header and parameter fields. Fixed seed, so every run tests the same cases.
//! The property: reading returns `Ok` or `Err`, never panics, and allocates no more than the
//! file justifies (a corrupt count cannot make frames the file does not hold).

use std::io::Cursor;
use std::sync::atomic::{AtomicUsize, Ordering};

use c3d::{C3d, Reader};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use crate::read_shared::all_samples;

#[derive(Clone, Debug)]
enum Mutation {
    /// XOR bytes at positions (fractions of the file length).
    Flip(Vec<(f64, u8)>),
    /// Keep only the first fraction of the file.
    Truncate(f64),
    /// Random 16-bit values in header words (0–255).
    HeaderWord(Vec<(usize, u16)>),
    /// Random 16-bit values at byte offsets in the parameter section (fraction of its size).
    ParameterWord(Vec<(f64, u16)>),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        prop::collection::vec((0.0..1.0f64, 1..=255u8), 1..16).prop_map(Mutation::Flip),
        (0.0..1.0f64).prop_map(Mutation::Truncate),
        prop::collection::vec((0..256usize, any::<u16>()), 1..6).prop_map(Mutation::HeaderWord),
        prop::collection::vec((0.0..1.0f64, any::<u16>()), 1..6).prop_map(Mutation::ParameterWord),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let len = bytes.len();
    let at = |f: f64| ((f * len as f64) as usize).min(len - 1);
    match m {
        Mutation::Flip(flips) => flips.iter().for_each(|&(f, x)| bytes[at(f)] ^= x),
        Mutation::Truncate(f) => bytes.truncate(at(*f)),
        Mutation::HeaderWord(words) => {
            for &(w, v) in words {
                bytes[2 * w..2 * w + 2].copy_from_slice(&v.to_le_bytes());
            }
        }
        Mutation::ParameterWord(words) => {
            // Parameter section: from the block in header byte 0 to the data section.
            let start = (usize::from(bytes[0].max(1)) - 1) * 512;
            let size = usize::from(bytes.get(start + 2).copied().unwrap_or(1).max(1)) * 512;
            for &(f, v) in words {
                let i = (start + (f * size as f64) as usize).min(len - 2);
                bytes[i..i + 2].copy_from_slice(&v.to_le_bytes());
            }
        }
    }
}

/// Reads whole and streaming; returns whether the whole read succeeded.
fn read_both(bytes: &[u8]) -> bool {
    let whole = C3d::from_reader(Cursor::new(bytes));
    if let Ok(c) = &whole {
        // Nothing read may claim more frames than the file can hold.
        let frame_bytes = 2 * 4 * c.points.point_count();
        assert!(frame_bytes == 0 || c.points.frame_count() * frame_bytes <= bytes.len());
    }
    if let Ok(reader) = Reader::new(Cursor::new(bytes)) {
        for frame in reader {
            if frame.is_err() {
                break;
            }
        }
    }
    whole.is_ok()
}

#[test]
fn mutated_samples_never_panic() {
    let files: Vec<Vec<u8>> = all_samples().iter().map(|p| std::fs::read(p).unwrap()).collect();
    if files.is_empty() {
        return;
    }
    // Thousands of cases in release; fewer in debug builds, which are slower but check
    // arithmetic overflow.
    let cases = if cfg!(debug_assertions) { 1500 } else { 4000 };
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let (runs, ok) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let strategy = (0..files.len(), mutation());
    runner
        .run(&strategy, |(file, m)| {
            let mut bytes = files[file].clone();
            apply(&mut bytes, &m);
            runs.fetch_add(1, Ordering::Relaxed);
            if read_both(&bytes) {
                ok.fetch_add(1, Ordering::Relaxed);
            }
            Ok(())
        })
        .unwrap();
    let (runs, ok) = (runs.into_inner(), ok.into_inner());
    eprintln!("fuzz: {runs} mutated files read, {ok} Ok, {} Err, 0 panics", runs - ok);
    assert_eq!(runs, cases as usize);
}

#[test]
fn huge_counts_in_a_tiny_file_are_refused_without_allocating() {
    // Header claiming 65535 points × 65535 frames, integer data, over 3 blocks only.
    let mut bytes = vec![0u8; 3 * 512];
    bytes[0] = 2;
    bytes[1] = 0x50;
    let word =
        |b: &mut Vec<u8>, n: usize, v: u16| b[2 * (n - 1)..2 * n].copy_from_slice(&v.to_le_bytes());
    word(&mut bytes, 2, 65535);
    word(&mut bytes, 3, 65535);
    word(&mut bytes, 4, 1);
    word(&mut bytes, 5, 65535);
    bytes[12..16].copy_from_slice(&1.0f32.to_le_bytes());
    word(&mut bytes, 9, 3);
    word(&mut bytes, 10, 1);
    bytes[512..516].copy_from_slice(&[1, 0x50, 1, 84]);
    let c = C3d::from_reader(Cursor::new(&bytes)).unwrap();
    assert_eq!(c.points.frame_count(), 0);
    assert!(
        c.warnings.iter().any(|w| w.contains("holds 0 of the 65535 frames")),
        "{:?}",
        c.warnings
    );
}

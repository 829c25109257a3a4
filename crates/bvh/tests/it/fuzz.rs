//! Mutation fuzz with a fixed seed: real files (cut to a few KB) and our fixtures, mutated by
//! byte flips, deletions, insertions and truncation. `parse` must return, never panic; what
//! it accepts must round-trip exactly, and what it rejects must carry a position in the file.

use std::sync::atomic::{AtomicUsize, Ordering};

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use crate::{assert_round_trip, fixture_dir, shared_bvh_files};

const CASES: u32 = 20_000;

/// Tokens worth inserting: structure, numbers at the edges, separators.
const DICTIONARY: &[&str] = &[
    "{",
    "}",
    "\n",
    "\r\n",
    "\t",
    " ",
    "-",
    ".",
    "e",
    "E+",
    "1e999",
    "nan",
    "inf",
    "0",
    "9999999999",
    "JOINT X\n{\n",
    "End Site",
    "OFFSET 1 2 3",
    "CHANNELS",
    "CHANNELS 3 Xrotation Yrotation Zrotation",
    "Xposition",
    "ROOT",
    "MOTION",
    "Frames:",
    "Frame Time:",
    "\u{feff}",
    "é",
    ":",
];

/// Numbers that stress the float parser and the writer when swapped in for a file's own.
const NUMBERS: &[&str] = &[
    "-0",
    "0.1",
    "5e-324",
    "4.9e-324",
    "2.2250738585072014e-308",
    "1.7976931348623157e308",
    "9007199254740993",
    "123456789012345678901234567890",
    "0.30000000000000004",
    "1e22",
    "1e23",
    "-1.5E+2",
    ".5",
    "7.",
    "+3",
    "1e-400",
    "0.000000000000000000000000001",
];

#[derive(Debug, Clone)]
enum Mutation {
    /// Replace one number of the file (keeps most files valid: exercises the round trip).
    Number(Index, &'static str),
    Flip(Index, u8),
    Delete(Index, usize),
    Insert(Index, Vec<u8>),
    Truncate(Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let token = prop_oneof![
        prop::sample::select(DICTIONARY).prop_map(|t| t.as_bytes().to_vec()),
        prop::collection::vec(any::<u8>(), 1..4),
    ];
    prop_oneof![
        3 => (any::<Index>(), prop::sample::select(NUMBERS)).prop_map(|(i, n)| Mutation::Number(i, n)),
        3 => (any::<Index>(), 0u8..8).prop_map(|(i, bit)| Mutation::Flip(i, 1 << bit)),
        3 => (any::<Index>(), 1usize..12).prop_map(|(i, n)| Mutation::Delete(i, n)),
        3 => (any::<Index>(), token).prop_map(|(i, t)| Mutation::Insert(i, t)),
        1 => any::<Index>().prop_map(Mutation::Truncate),
    ]
}

fn apply(mut bytes: Vec<u8>, mutations: &[Mutation]) -> Vec<u8> {
    for m in mutations {
        let len = bytes.len();
        match m {
            _ if len == 0 => {}
            Mutation::Number(i, number) => {
                let numbers = number_spans(&bytes);
                if !numbers.is_empty() {
                    let (start, end) = numbers[i.index(numbers.len())];
                    bytes.splice(start..end, number.bytes());
                }
            }
            Mutation::Flip(i, bit) => bytes[i.index(len)] ^= bit,
            Mutation::Delete(i, n) => {
                let at = i.index(len);
                bytes.drain(at..(at + n).min(len));
            }
            Mutation::Insert(i, t) => {
                let at = i.index(len + 1);
                bytes.splice(at..at, t.iter().copied());
            }
            Mutation::Truncate(i) => bytes.truncate(i.index(len)),
        }
    }
    bytes
}

/// Byte ranges of the whitespace-separated tokens that are numbers.
fn number_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, &b) in bytes.iter().chain(b" ").enumerate() {
        match (b.is_ascii_whitespace() || b == 0x0b, start) {
            (false, None) => start = Some(i),
            (true, Some(s)) => {
                let token = std::str::from_utf8(&bytes[s..i]).unwrap_or("x");
                if token.parse::<f64>().is_ok_and(f64::is_finite) {
                    spans.push((s, i));
                }
                start = None;
            }
            _ => {}
        }
    }
    spans
}

/// The head of a real file, and its hierarchy plus the first two rows with `Frames: 2`.
fn seeds_from_file(text: &[u8]) -> Vec<Vec<u8>> {
    let mut seeds = vec![text[..text.len().min(3000)].to_vec()];
    let text = String::from_utf8_lossy(text);
    if let (Some(frames), Some(time)) = (text.find("Frames:"), text.find("Frame Time:")) {
        let rows_start = time + text[time..].find('\n').map_or(0, |n| n + 1);
        let rows: String = text[rows_start..].split_inclusive('\n').take(2).collect();
        let head = format!("{}Frames: 2\n{}", &text[..frames], &text[time..rows_start]);
        let cut = (head + &rows).into_bytes();
        seeds.push(cut[..cut.len().min(16_000)].to_vec());
    }
    seeds
}

fn corpus() -> Vec<Vec<u8>> {
    let mut corpus = Vec::new();
    for entry in std::fs::read_dir(fixture_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "bvh") {
            corpus.push(std::fs::read(path).unwrap());
        }
    }
    for path in shared_bvh_files().unwrap_or_default() {
        corpus.extend(seeds_from_file(&std::fs::read(path).unwrap()));
    }
    corpus
}

#[test]
fn mutated_files_never_panic_the_parser() {
    let corpus = corpus();
    let config = Config { cases: CASES, failure_persistence: None, ..Config::default() };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let (ran, accepted) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let strategy = (0..corpus.len(), prop::collection::vec(mutation(), 1..6));
    let result = runner.run(&strategy, |(seed, mutations)| {
        let input = apply(corpus[seed].clone(), &mutations);
        ran.fetch_add(1, Ordering::Relaxed);
        match bvh::parse(&input) {
            Ok(parsed) => {
                accepted.fetch_add(1, Ordering::Relaxed);
                assert_round_trip(&parsed, "a mutated file");
                bvh::write_json(&parsed, std::io::sink()).unwrap();
                let _ = bvh::Summary::new(&parsed, "fuzz").to_string();
            }
            Err(e) => {
                let pos = e.position().expect("parse errors carry a position");
                let lines = input.iter().filter(|&&b| b == b'\n').count() + 1;
                prop_assert!(pos.line >= 1 && pos.line <= lines && pos.column >= 1, "{e}");
                prop_assert!(!e.to_string().is_empty());
            }
        }
        Ok(())
    });
    let (ran, accepted) = (ran.into_inner(), accepted.into_inner());
    eprintln!("fuzz: {ran} mutated inputs from {} seeds, {accepted} accepted", corpus.len());
    result.unwrap();
    assert!(ran >= CASES as usize);
}

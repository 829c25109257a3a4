//! Byte mutation in the manner of AFL's "havoc" stage: a few random edits stacked. Written
//! here (about 100 lines) because the crates that offer it (libafl, …) are whole fuzzing
//! frameworks built around coverage instrumentation we cannot have on stable.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Numbers that stress parsers when they replace a number of the input.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "1e-320",
    "1e999",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "9223372036854775807",
    "2147483647",
    "-2147483648",
    "65535",
    "65536",
    "100000000000000",
    "0.000001",
    "1.7976931348623157e308",
    "",
];

/// Integers that stress binary fields.
const INTEGERS: &[u32] = &[
    0,
    1,
    2,
    0x7f,
    0x80,
    0xff,
    0x100,
    0x7fff,
    0x8000,
    0xffff,
    0x1_0000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
];

/// Applies 1 to 8 random edits to `data`; `other` is a second input for splices.
pub fn havoc(rng: &mut ChaCha8Rng, data: &mut Vec<u8>, other: &[u8], dictionary: &[&str]) {
    let edits = 1 << rng.gen_range(0..4);
    for _ in 0..edits {
        edit(rng, data, other, dictionary);
    }
}

fn edit(rng: &mut ChaCha8Rng, data: &mut Vec<u8>, other: &[u8], dictionary: &[&str]) {
    let len = data.len();
    let at = |rng: &mut ChaCha8Rng| rng.gen_range(0..=len);
    match rng.gen_range(0..12) {
        0 if len > 0 => {
            let i = rng.gen_range(0..len);
            if let Some(b) = data.get_mut(i) {
                *b ^= 1 << rng.gen_range(0..8);
            }
        }
        1 if len > 0 => {
            let i = rng.gen_range(0..len);
            if let Some(b) = data.get_mut(i) {
                *b = rng.gen();
            }
        }
        2 if len > 0 => {
            // A 1-, 2- or 4-byte interesting integer, either byte order.
            let value = INTEGERS[rng.gen_range(0..INTEGERS.len())];
            let width = [1, 2, 4][rng.gen_range(0..3)];
            let bytes = if rng.gen_bool(0.5) { value.to_le_bytes() } else { value.to_be_bytes() };
            let i = rng.gen_range(0..len);
            for (k, &b) in bytes.iter().take(width).enumerate() {
                if let Some(slot) = data.get_mut(i + k) {
                    *slot = b;
                }
            }
        }
        3 => {
            let n = rng.gen_range(1..16);
            let i = at(rng);
            let bytes: Vec<u8> = (0..n).map(|_| rng.gen()).collect();
            data.splice(i..i, bytes);
        }
        4 if len > 0 => {
            let i = rng.gen_range(0..len);
            let n = rng.gen_range(1..=(len - i).min(64));
            data.drain(i..i + n);
        }
        5 if len > 0 => {
            // Duplicate a chunk (repeated elements, rows, blocks).
            let i = rng.gen_range(0..len);
            let n = rng.gen_range(1..=(len - i).min(256));
            let chunk: Vec<u8> = data.get(i..i + n).map(<[u8]>::to_vec).unwrap_or_default();
            let j = at(rng);
            data.splice(j..j, chunk);
        }
        6 | 7 if !dictionary.is_empty() => {
            let token = dictionary[rng.gen_range(0..dictionary.len())].as_bytes();
            let i = at(rng);
            if rng.gen_bool(0.5) {
                data.splice(i..i, token.iter().copied());
            } else {
                let end = (i + token.len()).min(len);
                data.splice(i..end, token.iter().copied());
            }
        }
        8 => replace_number(rng, data),
        9 if len > 1 => {
            data.truncate(rng.gen_range(0..len));
        }
        10 if !other.is_empty() => {
            // Splice: our head, the other input's tail.
            let i = at(rng);
            let j = rng.gen_range(0..other.len());
            data.truncate(i);
            data.extend_from_slice(other.get(j..).unwrap_or_default());
        }
        _ => replace_number(rng, data),
    }
}

/// Replaces one ASCII number (digits, sign, point, exponent) with an interesting one.
fn replace_number(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) {
    let starts: Vec<usize> = data
        .iter()
        .enumerate()
        .filter(|&(i, b)| {
            b.is_ascii_digit() && (i == 0 || data.get(i - 1).is_some_and(|p| !p.is_ascii_digit()))
        })
        .map(|(i, _)| i)
        .collect();
    if starts.is_empty() {
        return;
    }
    let start = starts[rng.gen_range(0..starts.len())];
    let numeric = |b: &u8| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'-' | b'+');
    let len = data.get(start..).map_or(0, |rest| rest.iter().take_while(|b| numeric(b)).count());
    let number = NUMBERS[rng.gen_range(0..NUMBERS.len())];
    data.splice(start..start + len, number.bytes());
}

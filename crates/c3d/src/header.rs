//! The 512-byte header section.
//!
//! Word numbers below are the C3D manual's (16-bit words, counted from 1).

use crate::processor::Processor;

/// Size of every C3D section block.
pub const BLOCK: usize = 512;
/// Key byte of the header (byte 2) and of the parameter section.
pub const KEY: u8 = 0x50;
/// Marks the event block of the header (word 150) and the label/range block (word 148).
const EVENT_KEY: u16 = 12345;
/// The header holds at most this many events.
pub const MAX_HEADER_EVENTS: usize = 18;

/// One event of the header's event block.
#[derive(Clone, Debug, PartialEq)]
pub struct HeaderEvent {
    /// Up to four characters, trailing blanks removed.
    pub label: String,
    /// Seconds from the start of the trial.
    pub time: f32,
    /// Display flag byte as stored (the manual: 0 on, 1 off).
    pub display: u8,
}

/// Header facts as stored; the parameter section holds the values that win (see `Layout`).
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Block number (from 1) where the parameter section starts (word 1, low byte).
    pub parameter_block: u8,
    /// Points per frame (word 2).
    pub point_count: u16,
    /// Analog measurements per frame: channels × samples per frame (word 3).
    pub analog_per_frame: u16,
    /// First frame number, from 1 (word 4).
    pub first_frame: u16,
    /// Last frame number (word 5); counts are unsigned 16-bit.
    pub last_frame: u16,
    /// Maximum interpolation gap in frames (word 6).
    pub max_interpolation_gap: u16,
    /// Point scale (words 7–8): negative means float data.
    pub scale: f32,
    /// Block number (from 1) where the data section starts (word 9).
    pub data_start_block: u16,
    /// Analog samples per channel per frame (word 10).
    pub analog_samples_per_frame: u16,
    /// Frame rate in Hz (words 11–12).
    pub frame_rate: f32,
    /// Whether word 150 says events have 4-character labels.
    pub long_event_labels: bool,
    /// Events of the header block (up to 18).
    pub events: Vec<HeaderEvent>,
}

impl Header {
    /// Decodes a header block read with the given processor's byte order.
    // Fixed offsets into a fixed 512-byte block (words 1..=152, event bytes up to 467):
    // every index is a constant bounded below BLOCK, whatever the file says.
    #[allow(clippy::indexing_slicing)]
    pub fn parse(b: &[u8; BLOCK], p: Processor) -> Header {
        let word = |n: usize| p.u16([b[2 * (n - 1)], b[2 * (n - 1) + 1]]);
        let float = |n: usize| {
            let i = 2 * (n - 1);
            p.f32([b[i], b[i + 1], b[i + 2], b[i + 3]])
        };
        let long_event_labels = word(150) == EVENT_KEY;
        let count = usize::from(word(151)).min(MAX_HEADER_EVENTS);
        let events = (0..count)
            .map(|i| HeaderEvent {
                time: float(153 + 2 * i),
                display: b[376 + i],
                label: latin1(&b[396 + 4 * i..400 + 4 * i]).trim_end().to_string(),
            })
            .collect();
        Header {
            parameter_block: b[0],
            point_count: word(2),
            analog_per_frame: word(3),
            first_frame: word(4),
            last_frame: word(5),
            max_interpolation_gap: word(6),
            scale: float(7),
            data_start_block: word(9),
            analog_samples_per_frame: word(10),
            frame_rate: float(11),
            long_event_labels,
            events,
        }
    }

    /// Encodes the header with the given processor's byte order.
    // Fixed offsets into a fixed 512-byte block, as in `parse`; at most 18 events.
    #[allow(clippy::indexing_slicing)]
    pub fn to_bytes(&self, p: Processor) -> [u8; BLOCK] {
        let mut b = [0u8; BLOCK];
        let put16 = |b: &mut [u8; BLOCK], n: usize, v: u16| {
            let i = 2 * (n - 1);
            b[i..i + 2].copy_from_slice(&encode_u16(p, v));
        };
        let put32 = |b: &mut [u8; BLOCK], n: usize, v: f32| {
            let i = 2 * (n - 1);
            b[i..i + 4].copy_from_slice(&encode_f32(p, v));
        };
        b[0] = self.parameter_block;
        b[1] = KEY;
        put16(&mut b, 2, self.point_count);
        put16(&mut b, 3, self.analog_per_frame);
        put16(&mut b, 4, self.first_frame);
        put16(&mut b, 5, self.last_frame);
        put16(&mut b, 6, self.max_interpolation_gap);
        put32(&mut b, 7, self.scale);
        put16(&mut b, 9, self.data_start_block);
        put16(&mut b, 10, self.analog_samples_per_frame);
        put32(&mut b, 11, self.frame_rate);
        let events = &self.events[..self.events.len().min(MAX_HEADER_EVENTS)];
        if self.long_event_labels || !events.is_empty() {
            put16(&mut b, 150, EVENT_KEY);
        }
        put16(&mut b, 151, events.len() as u16);
        for (i, e) in events.iter().enumerate() {
            put32(&mut b, 153 + 2 * i, e.time);
            b[376 + i] = e.display;
            let mut label = [b' '; 4];
            for (dst, src) in label.iter_mut().zip(to_latin1(&e.label)) {
                *dst = src;
            }
            b[396 + 4 * i..400 + 4 * i].copy_from_slice(&label);
        }
        b
    }
}

/// Bytes as Latin-1 text: every byte is a character, so nothing is lost.
pub(crate) fn latin1(bytes: &[u8]) -> String {
    bytes.iter().map(|&c| char::from(c)).collect()
}

/// Text as Latin-1 bytes; characters outside Latin-1 become `?`.
pub(crate) fn to_latin1(s: &str) -> Vec<u8> {
    s.chars().map(|c| u8::try_from(u32::from(c)).unwrap_or(b'?')).collect()
}

pub(crate) fn encode_u16(p: Processor, v: u16) -> [u8; 2] {
    match p {
        Processor::Mips => v.to_be_bytes(),
        _ => v.to_le_bytes(),
    }
}

pub(crate) fn encode_f32(p: Processor, v: f32) -> [u8; 4] {
    match p {
        Processor::Mips => v.to_be_bytes(),
        Processor::Intel => v.to_le_bytes(),
        Processor::Dec => f32_to_vax(v),
    }
}

/// IEEE single to VAX F (inverse of [`crate::processor::vax_f_to_f32`]); values outside the
/// VAX range saturate, subnormals and NaN become zero.
pub(crate) fn f32_to_vax(v: f32) -> [u8; 4] {
    if !v.is_finite() || v == 0.0 {
        return [0; 4];
    }
    let bits = v.to_bits();
    let sign = bits >> 31;
    let ieee_exp = (bits >> 23) & 0xff;
    if ieee_exp == 0 {
        return [0; 4];
    }
    let (exp, fraction) =
        if ieee_exp + 2 > 255 { (255, (1 << 23) - 1) } else { (ieee_exp + 2, bits & 0x7f_ffff) };
    let hi = ((sign << 15) | (exp << 7) | (fraction >> 16)) as u16;
    let lo = (fraction & 0xffff) as u16;
    let [a, b] = hi.to_le_bytes();
    let [c, d] = lo.to_le_bytes();
    [a, b, c, d]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_round_trip_all_processors() {
        let h = Header {
            parameter_block: 2,
            point_count: 26,
            analog_per_frame: 64,
            first_frame: 1,
            last_frame: 40000,
            max_interpolation_gap: 10,
            scale: -0.083333,
            data_start_block: 11,
            analog_samples_per_frame: 4,
            frame_rate: 65.05,
            long_event_labels: true,
            events: vec![HeaderEvent { label: "RIC".into(), time: 1.25, display: 1 }],
        };
        for p in [Processor::Intel, Processor::Dec, Processor::Mips] {
            assert_eq!(Header::parse(&h.to_bytes(p), p), h, "{p:?}");
        }
    }

    #[test]
    fn vax_round_trip() {
        for v in [1.0f32, -3.5, 65.05, 1e-30, 1e30, -0.083333] {
            assert_eq!(crate::processor::vax_f_to_f32(f32_to_vax(v)), v);
        }
    }
}

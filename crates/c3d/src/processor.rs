//! Byte order and float formats of the three processor types.

/// Processor type, byte 4 of the parameter section (`83 + n`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Processor {
    /// 84: little-endian integers, IEEE 754 floats.
    Intel,
    /// 85: little-endian integers, VAX F floats.
    Dec,
    /// 86: big-endian integers and IEEE 754 floats (SGI/MIPS).
    Mips,
}

impl Processor {
    /// The processor for a parameter-section byte, if it is one of 84, 85, 86.
    #[must_use]
    pub fn from_byte(byte: u8) -> Option<Self> {
        match byte {
            84 => Some(Processor::Intel),
            85 => Some(Processor::Dec),
            86 => Some(Processor::Mips),
            _ => None,
        }
    }

    /// The parameter-section byte of this processor.
    #[must_use]
    pub fn to_byte(self) -> u8 {
        match self {
            Processor::Intel => 84,
            Processor::Dec => 85,
            Processor::Mips => 86,
        }
    }

    /// Lowercase name, as `info` prints it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Processor::Intel => "intel",
            Processor::Dec => "dec",
            Processor::Mips => "mips",
        }
    }

    pub(crate) fn u16(self, b: [u8; 2]) -> u16 {
        match self {
            Processor::Mips => u16::from_be_bytes(b),
            _ => u16::from_le_bytes(b),
        }
    }

    pub(crate) fn i16(self, b: [u8; 2]) -> i16 {
        self.u16(b) as i16
    }

    pub(crate) fn f32(self, b: [u8; 4]) -> f32 {
        match self {
            Processor::Intel => f32::from_le_bytes(b),
            Processor::Mips => f32::from_be_bytes(b),
            Processor::Dec => vax_f_to_f32(b),
        }
    }
}

/// A VAX F_floating value (as stored by DEC processors) converted to IEEE 754 single.
///
/// Layout (VAX Architecture Reference Manual, 1.4.1): two little-endian 16-bit words, the first
/// holding sign (bit 15), an excess-128 exponent (bits 14–7) and the high 7 fraction bits; the
/// value is `0.1f × 2^(e − 128)` = `1.f × 2^(e − 129)`. IEEE has a bias of 127, so the IEEE
/// exponent is `e − 2`: exact for `e ≥ 3`; `e` of 1 and 2 become IEEE subnormals (rounded once,
/// through `f64`). Exponent 0 is zero, or with the sign set a "reserved operand", returned as NaN.
#[must_use]
/// The first `N` bytes of `c` (zeros when shorter: callers pass exact chunks).
#[inline]
pub(crate) fn take<const N: usize>(c: &[u8]) -> [u8; N] {
    c.first_chunk::<N>().copied().unwrap_or([0; N])
}

pub fn vax_f_to_f32(b: [u8; 4]) -> f32 {
    let hi = u32::from(u16::from_le_bytes([b[0], b[1]]));
    let lo = u32::from(u16::from_le_bytes([b[2], b[3]]));
    let sign = hi >> 15;
    let exp = (hi >> 7) & 0xff;
    let fraction = ((hi & 0x7f) << 16) | lo;
    match exp {
        0 if sign == 0 => 0.0,
        0 => f32::NAN,
        1 | 2 => {
            let magnitude =
                (1.0 + f64::from(fraction) / f64::from(1u32 << 23)) * 2f64.powi(exp as i32 - 129);
            let v = magnitude as f32;
            if sign == 1 {
                -v
            } else {
                v
            }
        }
        _ => f32::from_bits((sign << 31) | ((exp - 2) << 23) | fraction),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vax(sign: u32, exp: u32, fraction: u32) -> [u8; 4] {
        let hi = ((sign << 15) | (exp << 7) | (fraction >> 16)) as u16;
        let lo = (fraction & 0xffff) as u16;
        let [a, b] = hi.to_le_bytes();
        let [c, d] = lo.to_le_bytes();
        [a, b, c, d]
    }

    #[test]
    fn vax_one_and_friends() {
        // 1.0 = 0.1b × 2^1 → exponent 129, fraction 0.
        assert_eq!(vax_f_to_f32(vax(0, 129, 0)), 1.0);
        assert_eq!(vax_f_to_f32(vax(1, 129, 0)), -1.0);
        assert_eq!(vax_f_to_f32(vax(0, 130, 1 << 22)), 3.0);
        assert_eq!(vax_f_to_f32(vax(0, 0, 0)), 0.0);
        assert!(vax_f_to_f32(vax(1, 0, 5)).is_nan());
        // Largest VAX value is finite in IEEE.
        let max = vax_f_to_f32(vax(0, 255, (1 << 23) - 1));
        assert_eq!(max, f32::from_bits((253 << 23) | ((1 << 23) - 1)));
        // Smallest normal VAX value is 0.5 × 2^-127 = 2^-128, an IEEE subnormal.
        assert_eq!(vax_f_to_f32(vax(0, 1, 0)), 2f32.powi(-128));
    }

    #[test]
    fn byte_orders() {
        assert_eq!(Processor::Intel.i16([0x01, 0x80]), -32767);
        assert_eq!(Processor::Mips.i16([0x80, 0x01]), -32767);
        assert_eq!(Processor::Mips.f32(1.5f32.to_be_bytes()), 1.5);
        assert_eq!(Processor::Intel.f32(1.5f32.to_le_bytes()), 1.5);
    }
}

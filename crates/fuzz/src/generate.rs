//! What the generators share: numbers as a generator writes them ([`Num`]) and the shipped
//! G1 that the config, npz and motion targets run on.

use std::fmt::Write as _;
use std::sync::OnceLock;

use arbitrary::{Arbitrary, Result, Unstructured};

/// The shipped G1, the robot of the config and npz targets.
pub(crate) fn g1() -> &'static mjcf::Model {
    static G1: OnceLock<mjcf::Model> = OnceLock::new();
    G1.get_or_init(|| {
        let xml = include_str!("../../../robots/unitree_g1/unitree_g1.xml");
        mjcf::Model::from_xml_str(xml, None).unwrap_or_else(|e| panic!("shipped G1: {e}"))
    })
}

/// Numbers as a generator writes them: mostly ordinary, sometimes extreme or malformed
/// (1 in 40), so that most generated files get past the tokenizer.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Num {
    Small(i8),
    Tenths(i16),
    Any(f64),
    Special(u8),
}

impl<'a> Arbitrary<'a> for Num {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Num> {
        Ok(match u.int_in_range(0..=39)? {
            0 => Num::Special(u.arbitrary()?),
            1 => Num::Any(u.arbitrary()?),
            2..=9 => Num::Small(u.arbitrary()?),
            _ => Num::Tenths(u.arbitrary()?),
        })
    }
}

impl Num {
    /// Writes the number; unless `wild`, extreme and malformed ones are written as `0` or a
    /// finite value (a generated file is either clean, to reach the later stages, or wild).
    pub(crate) fn write(self, out: &mut String, wild: bool) {
        const SPECIAL: &[&str] =
            &["nan", "inf", "-inf", "1e300", "-1e300", "1e-320", "0", "-0", "1e999", "", "+", "."];
        let _ = match self {
            Num::Small(v) => write!(out, "{v}"),
            Num::Tenths(v) => write!(out, "{}", f64::from(v) / 10.0),
            Num::Any(v) if wild || v.is_finite() => write!(out, "{v}"),
            Num::Special(k) if wild => write!(out, "{}", SPECIAL[usize::from(k) % SPECIAL.len()]),
            Num::Any(_) | Num::Special(_) => write!(out, "0"),
        };
    }
}

pub(crate) fn num_value(n: Num) -> f64 {
    match n {
        Num::Small(v) => f64::from(v),
        Num::Tenths(v) => f64::from(v) / 10.0,
        Num::Any(v) => v,
        Num::Special(k) => [f64::NAN, f64::INFINITY, 1e300, 0.0, -0.1][usize::from(k) % 5],
    }
}

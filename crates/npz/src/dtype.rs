//! The element types of `.npy` members, as numpy names them.

/// The element types a reader meets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    Float {
        width: usize,
        big: bool,
    },
    Int {
        width: usize,
        signed: bool,
        big: bool,
    },
    Bool,
    /// numpy `U<n>`: `n` UTF-32 code units.
    Unicode {
        chars: usize,
        big: bool,
    },
    /// numpy `S<n>`: `n` bytes.
    Bytes(usize),
    /// A pickled Python object array.
    Object,
}

impl std::fmt::Display for Dtype {
    /// numpy's `descr` (`<f8`, `>i4`, `|b1`, `<U12`, `|S6`, `|O`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let order = |big: bool| if big { '>' } else { '<' };
        match *self {
            Dtype::Float { width, big } => write!(f, "{}f{width}", order(big)),
            Dtype::Int { width: 1, signed, .. } => {
                write!(f, "|{}1", if signed { 'i' } else { 'u' })
            }
            Dtype::Int { width, signed, big } => {
                write!(f, "{}{}{width}", order(big), if signed { 'i' } else { 'u' })
            }
            Dtype::Bool => f.write_str("|b1"),
            Dtype::Unicode { chars, big } => write!(f, "{}U{chars}", order(big)),
            Dtype::Bytes(n) => write!(f, "|S{n}"),
            Dtype::Object => f.write_str("|O"),
        }
    }
}

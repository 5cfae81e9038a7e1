//! PLY scalar types: their names, sizes and binary decoding.

/// One of the eight PLY 1.0 scalar types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    Int8,
    Uint8,
    Int16,
    Uint16,
    Int32,
    Uint32,
    Float32,
    Float64,
}

impl Scalar {
    /// Parses a type name, accepting both the original (`uchar`) and sized (`uint8`) spellings.
    pub(crate) fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::Int8,
            "uchar" | "uint8" => Scalar::Uint8,
            "short" | "int16" => Scalar::Int16,
            "ushort" | "uint16" => Scalar::Uint16,
            "int" | "int32" => Scalar::Int32,
            "uint" | "uint32" => Scalar::Uint32,
            "float" | "float32" => Scalar::Float32,
            "double" | "float64" => Scalar::Float64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary file.
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::Int8 | Scalar::Uint8 => 1,
            Scalar::Int16 | Scalar::Uint16 => 2,
            Scalar::Int32 | Scalar::Uint32 | Scalar::Float32 => 4,
            Scalar::Float64 => 8,
        }
    }

    /// Decodes one value from the start of `bytes`, or `None` if `bytes` is too short.
    /// Every type converts to `f64` exactly.
    #[inline]
    pub(crate) fn decode(self, bytes: &[u8], big_endian: bool) -> Option<f64> {
        macro_rules! get {
            ($t:ty) => {{
                let raw = bytes.get(..size_of::<$t>())?.try_into().ok()?;
                if big_endian {
                    <$t>::from_be_bytes(raw)
                } else {
                    <$t>::from_le_bytes(raw)
                }
            }};
        }
        Some(match self {
            Scalar::Int8 => f64::from(get!(i8)),
            Scalar::Uint8 => f64::from(get!(u8)),
            Scalar::Int16 => f64::from(get!(i16)),
            Scalar::Uint16 => f64::from(get!(u16)),
            Scalar::Int32 => f64::from(get!(i32)),
            Scalar::Uint32 => f64::from(get!(u32)),
            Scalar::Float32 => f64::from(get!(f32)),
            Scalar::Float64 => get!(f64),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_both_endiannesses() {
        assert_eq!(Scalar::Int16.decode(&[0xff, 0xfe], false), Some(-257.0));
        assert_eq!(Scalar::Int16.decode(&[0xfe, 0xff], true), Some(-257.0));
        assert_eq!(Scalar::Uint32.decode(&[0, 0, 0, 0x80], false), Some(2147483648.0));
        let bytes = 1.5f32.to_be_bytes();
        assert_eq!(Scalar::Float32.decode(&bytes, true), Some(1.5));
        assert_eq!(Scalar::Float64.decode(&[0; 7], false), None);
    }

    #[test]
    fn knows_every_type_name() {
        for (a, b) in [
            ("char", "int8"),
            ("uchar", "uint8"),
            ("short", "int16"),
            ("ushort", "uint16"),
            ("int", "int32"),
            ("uint", "uint32"),
            ("float", "float32"),
            ("double", "float64"),
        ] {
            assert_eq!(Scalar::from_name(a), Scalar::from_name(b));
            assert!(Scalar::from_name(a).is_some());
        }
        assert_eq!(Scalar::from_name("int64"), None);
    }
}

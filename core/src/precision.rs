//! The number representation coverage is decided in (`--precision`).
//!
//! | precision | family | what changes |
//! |---|---|---|
//! | `f32` | every algorithm | the default: single precision, one fixed operation order |
//! | `f64` | 3D family (`3dr-*`, `raycast`) | setup and per-sample evaluation in double precision, vertices relative to the eye |
//! | `fixed` | 2D family (`2dr-brute`, `2dr-bin`, `2dr-scanline`) | vertices snapped to 1/256 pixel (16.8 fixed point) and exact integer edge functions, as hardware does (Direct3D 11 §3.4, Vulkan) |
//!
//! Non-planar viewports evaluate their curved edges in f64 at every precision.

use std::fmt;

use crate::ground::{Family, FieldError};

/// How coverage decisions are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    #[default]
    F32,
    F64,
    Fixed,
}

impl Precision {
    pub const ALL: [Precision; 3] = [Precision::F32, Precision::F64, Precision::Fixed];

    pub fn as_str(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
            Precision::Fixed => "fixed",
        }
    }

    /// Parses `f32`, `f64` or `fixed`; the error names the field `precision`.
    pub fn parse(s: &str) -> Result<Precision, FieldError> {
        Precision::ALL
            .into_iter()
            .find(|p| p.as_str() == s.trim())
            .ok_or_else(|| {
                FieldError::new(
                    "precision",
                    format!("unknown precision '{s}'; precisions are: f32, f64 (3D family), fixed (2D family)"),
                )
            })
    }

    /// Can algorithms of `family` compute at this precision?
    pub fn serves(self, family: Family) -> bool {
        match self {
            Precision::F32 => true,
            Precision::F64 => family == Family::ThreeD,
            Precision::Fixed => family == Family::TwoD,
        }
    }
}

impl fmt::Display for Precision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl serde::Serialize for Precision {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

impl<'de> serde::Deserialize<'de> for Precision {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        Precision::parse(&s).map_err(|e| serde::de::Error::custom(e.message))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ground::AlgorithmId;

    #[test]
    fn words_round_trip_and_errors_name_the_field() {
        for p in Precision::ALL {
            assert_eq!(Precision::parse(p.as_str()), Ok(p));
        }
        assert_eq!(Precision::parse("f16").unwrap_err().field, "precision");
    }

    #[test]
    fn pairings() {
        assert!(Precision::F64.serves(AlgorithmId::Raycast.family()));
        assert!(!Precision::F64.serves(AlgorithmId::TwoDBrute.family()));
        assert!(Precision::Fixed.serves(AlgorithmId::TwoDBin.family()));
        assert!(!Precision::Fixed.serves(AlgorithmId::TwoDHomogeneous.family()));
    }
}

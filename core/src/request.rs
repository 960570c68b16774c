//! Parsing of the words a user gives (CLI flags, HTTP fields) into typed values,
//! shared by every front end so both speak the same language. Errors name the field.

use std::str::FromStr;

use crate::algorithm::AlgorithmId;
use crate::render::MAX_DIMENSION;

/// A user value that cannot be used, with the field it came from.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct FieldError {
    pub field: &'static str,
    pub message: String,
}

impl FieldError {
    pub fn new(field: &'static str, message: impl Into<String>) -> FieldError {
        FieldError {
            field,
            message: message.into(),
        }
    }
}

/// Parses `WxH` (e.g. `640x480`), each side in `1..=16384`.
pub fn parse_size(s: &str) -> Result<(u32, u32), FieldError> {
    let bad = || {
        FieldError::new(
            "size",
            format!("'{s}' is not WIDTHxHEIGHT with both in 1..={MAX_DIMENSION}, e.g. 640x480"),
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > MAX_DIMENSION || h > MAX_DIMENSION {
        return Err(bad());
    }
    Ok((w, h))
}

/// Parses an algorithm id; the error lists the valid ones.
pub fn parse_algorithm(s: &str) -> Result<AlgorithmId, FieldError> {
    AlgorithmId::from_str(s).map_err(|e| FieldError::new("algorithm", e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        for bad in ["", "640", "0x10", "10x0", "axb", "99999x1", "-1x5"] {
            assert_eq!(parse_size(bad).map_err(|e| e.field), Err("size"), "{bad}");
        }
    }

    #[test]
    fn algorithms() {
        for a in AlgorithmId::ALL {
            assert_eq!(parse_algorithm(a.as_str()), Ok(a));
        }
        let e = parse_algorithm("zbuffer").unwrap_err();
        assert!(e.message.contains("3dr-brute"), "{e}");
    }
}

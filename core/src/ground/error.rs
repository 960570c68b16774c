//! The one error type of the renderer's inputs: a value that cannot be used,
//! with the field it came from. Every front end maps it to its own surface
//! (`--field: message` on the command line, `{error, field}` over HTTP, a
//! message under the field in the viewer).

/// Largest width or height a render accepts.
pub const MAX_DIMENSION: u32 = 16384;

/// A user value that cannot be used, with the field it came from.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct FieldError {
    /// The request field at fault (`size`, `algorithm`, `viewport`, `aa`,
    /// `precision`, `oracles`, `camera`, `scene`, `texture_filter`, …), or
    /// `cancelled` for a render abandoned by its caller.
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

//! Floor 0: the words every other floor speaks — the one error type, pixel
//! rectangles, algorithm ids and boxes. Nothing here imports the rest of the
//! crate (`scripts/floors.py` checks it, and that no module anywhere imports
//! one declared after it in `lib.rs`).

mod algorithm_id;
mod bounds;
mod error;
mod rect;

pub use algorithm_id::{AlgorithmId, Family, UnknownAlgorithm};
pub use bounds::Bounds;
pub use error::{FieldError, MAX_DIMENSION};
pub use rect::{PixelRect, SampleSpan};

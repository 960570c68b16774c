//! Help texts made from the lists the code accepts, so `--help` names every
//! value there is.

use continuum::{AaMode, AlgorithmId};

/// `--algorithm`: every algorithm id.
pub fn algorithms() -> String {
    format!(
        "Algorithm id: {}",
        AlgorithmId::ALL.map(|a| a.as_str()).join(", ")
    )
}

/// `--algorithms` of `compare`: every algorithm id and peer.
pub fn algorithms_and_peers() -> String {
    format!(
        "Algorithm ids and peers, comma-separated: {}; peers {} (peer-embree and peer-embree-stream need the `embree` feature) [default: every algorithm this machine can run, and the peers built in]",
        AlgorithmId::ALL.map(|a| a.as_str()).join(", "),
        crate::compare::peer::PeerId::ALL
            .map(|p| p.as_str())
            .join(", ")
    )
}

/// `--aa`: every anti-aliasing mode.
pub fn aa_modes() -> String {
    let all: Vec<String> = AaMode::all().iter().map(ToString::to_string).collect();
    format!("Anti-aliasing mode: {}", all.join(", "))
}

//! Anti-aliasing: the modes, their sample patterns and the resolve.
//!
//! Every mode is a [`SamplePattern`]: `C` coverage positions inside the pixel, of
//! which the first `S` also store a depth and a triangle id. Each position is a
//! sample like the pixel centre is without anti-aliasing — it goes through the
//! same edge functions, tie rules and depth test in every algorithm — so the
//! agreement of algorithms holds per sample.
//!
//! | mode | coverage `C` | stored `S` | shading |
//! |---|---|---|---|
//! | `none` | 1 (the centre) | 1 | per pixel |
//! | `ssaa:N` | N | N | per sample |
//! | `msaa:N` | N | N | once per pixel per triangle |
//! | `csaa:CxS` | C | S | once per pixel per triangle |
//!
//! The paper (§4, Fig. 8) adds MSAA and CSAA to 3D rasterization; the resolve
//! (module `resolve`) is a box filter over the coverage samples in linear light.

mod pattern;

use std::fmt;

pub use pattern::SamplePattern;

use crate::ground::FieldError;

/// How many samples a pixel gets and how they are shaded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AaMode {
    /// One sample at the pixel centre.
    #[default]
    None,
    /// Supersampling: `N` samples, each shaded.
    Ssaa(u32),
    /// Multisampling: `N` samples with coverage and depth, shaded once per pixel
    /// per covering triangle.
    Msaa(u32),
    /// Coverage sampling: `coverage` positions decide coverage, `stored` of them
    /// keep depth and triangle id (NVIDIA's CSAA, paper §4).
    Csaa { coverage: u32, stored: u32 },
}

/// Sample counts `ssaa:N` accepts.
pub const SSAA_COUNTS: [u32; 4] = [4, 16, 64, 256];
/// Sample counts `msaa:N` accepts.
pub const MSAA_COUNTS: [u32; 4] = [2, 4, 8, 16];
/// Coverage counts `csaa:CxS` accepts.
pub const CSAA_COVERAGE: [u32; 3] = [4, 8, 16];
/// Stored counts `csaa:CxS` accepts (below `C`).
pub const CSAA_STORED: [u32; 4] = [1, 2, 4, 8];

/// The reference every mode's accuracy is measured against: 16×16 stratified
/// samples, each shaded.
impl AaMode {
    pub const REFERENCE: AaMode = AaMode::Ssaa(256);
}

impl AaMode {
    /// Parses the CLI's words: `none`, `ssaa:N`, `msaa:N`, `csaa:CxS`.
    pub fn parse(s: &str) -> Result<AaMode, FieldError> {
        let bad = |why: String| {
            FieldError::new("aa", format!("{why}; valid modes: {}", Self::valid_modes()))
        };
        let s = s.trim();
        if s.eq_ignore_ascii_case("none") {
            return Ok(AaMode::None);
        }
        let Some((kind, count)) = s.split_once(':') else {
            return Err(bad(format!("unknown mode {s:?}")));
        };
        let number = |t: &str| {
            t.trim()
                .parse::<u32>()
                .map_err(|_| bad(format!("{s:?}: {t:?} is not a sample count")))
        };
        let one_of = |n: u32, valid: &[u32], what: &str| {
            if valid.contains(&n) {
                Ok(n)
            } else {
                Err(bad(format!("{s:?}: {what} must be one of {valid:?}")))
            }
        };
        match kind.trim().to_ascii_lowercase().as_str() {
            "ssaa" => Ok(AaMode::Ssaa(one_of(number(count)?, &SSAA_COUNTS, "N")?)),
            "msaa" => Ok(AaMode::Msaa(one_of(number(count)?, &MSAA_COUNTS, "N")?)),
            "csaa" => {
                let Some((c, st)) = count.split_once(['x', 'X']) else {
                    return Err(bad(format!("{s:?}: csaa takes CxS, e.g. csaa:16x4")));
                };
                let coverage = one_of(number(c)?, &CSAA_COVERAGE, "C")?;
                let stored = one_of(number(st)?, &CSAA_STORED, "S")?;
                if stored >= coverage {
                    return Err(bad(format!(
                        "{s:?}: S must be below C (with S = C it is msaa:{coverage})"
                    )));
                }
                Ok(AaMode::Csaa { coverage, stored })
            }
            other => Err(bad(format!("unknown mode {other:?}"))),
        }
    }

    /// Every mode `parse` accepts, for error messages and listings.
    pub fn valid_modes() -> String {
        let list = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join("|");
        format!(
            "none, ssaa:{}, msaa:{}, csaa:CxS with C in {} and S in {} below C (e.g. csaa:16x4)",
            list(&SSAA_COUNTS),
            list(&MSAA_COUNTS),
            list(&CSAA_COVERAGE),
            list(&CSAA_STORED)
        )
    }

    /// Every mode, in a fixed order (for listings and tests).
    pub fn all() -> Vec<AaMode> {
        let mut all = vec![AaMode::None];
        all.extend(SSAA_COUNTS.map(AaMode::Ssaa));
        all.extend(MSAA_COUNTS.map(AaMode::Msaa));
        for coverage in CSAA_COVERAGE {
            for stored in CSAA_STORED.into_iter().filter(|&s| s < coverage) {
                all.push(AaMode::Csaa { coverage, stored });
            }
        }
        all
    }

    /// Coverage samples per pixel (`C`).
    pub fn coverage_samples(self) -> u32 {
        match self {
            AaMode::None => 1,
            AaMode::Ssaa(n) | AaMode::Msaa(n) => n,
            AaMode::Csaa { coverage, .. } => coverage,
        }
    }

    /// Samples per pixel with their own depth and triangle id (`S`).
    pub fn stored_samples(self) -> u32 {
        match self {
            AaMode::Csaa { stored, .. } => stored,
            other => other.coverage_samples(),
        }
    }

    /// Is every stored sample shaded (rather than once per pixel per triangle)?
    pub fn shades_per_sample(self) -> bool {
        matches!(self, AaMode::None | AaMode::Ssaa(_))
    }

    /// The sample positions of this mode.
    pub fn pattern(self) -> SamplePattern {
        SamplePattern::of(self)
    }
}

impl fmt::Display for AaMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AaMode::None => f.write_str("none"),
            AaMode::Ssaa(n) => write!(f, "ssaa:{n}"),
            AaMode::Msaa(n) => write!(f, "msaa:{n}"),
            AaMode::Csaa { coverage, stored } => write!(f, "csaa:{coverage}x{stored}"),
        }
    }
}

impl serde::Serialize for AaMode {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mode_round_trips_through_its_words() {
        for mode in AaMode::all() {
            assert_eq!(AaMode::parse(&mode.to_string()), Ok(mode), "{mode}");
        }
        assert_eq!(AaMode::parse(" MSAA:4 "), Ok(AaMode::Msaa(4)));
    }

    #[test]
    fn wrong_modes_name_the_field_and_list_the_valid_ones() {
        for bad in [
            "",
            "msaa",
            "msaa:3",
            "ssaa:2",
            "csaa:16",
            "csaa:16x16",
            "csaa:4x8",
            "fxaa:4",
            "msaa:x",
        ] {
            let e = AaMode::parse(bad).expect_err(bad);
            assert_eq!(e.field, "aa");
            assert!(
                e.message.contains("valid modes: none, ssaa:4|16|64|256"),
                "{bad}: {}",
                e.message
            );
        }
    }
}

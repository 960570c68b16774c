//! Procedural generators: large, reproducible scenes without shipping files.
//!
//! | generator | parameters |
//! |---|---|
//! | `teapots` | `count` copies of the Newell teapot on a grid, each patch tessellated `resolution`² quads, welded |
//! | `grid` | a plane `size = [x, z]` split into `divisions = [nx, nz]` quads, shared vertices |
//! | `sphere` | an icosphere of `radius`, `subdivisions` levels, welded and closed |
//! | `soup` | `count` random triangles from `seed`, sizes in `[min_size, max_size]`, inside a cube of half-size `extent` |
//! | `fan` | `count` triangles around one shared centre vertex, ring at `radius`, first at `start_deg` (plane z = 0) |
//! | `slivers` | `count` triangles of height `length` and aspect ratio `aspect` sharing long edges and one apex (plane z = 0) |

mod fan;
mod grid;
mod slivers;
mod soup;
mod sphere;
mod teapot;
mod weld;

use serde::Deserialize;

pub use fan::FanParams;
pub use grid::GridParams;
pub use slivers::SliverParams;
pub use soup::SoupParams;
pub use sphere::SphereParams;
pub use teapot::{TEAPOT_PATCHES, TeapotParams};

use super::Mesh;

/// Most triangles a generator may make (about 3 GB of renderer data).
pub const MAX_GENERATED_TRIANGLES: u64 = 50_000_000;

/// A generator and its parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Generator {
    Teapots(TeapotParams),
    Grid(GridParams),
    Sphere(SphereParams),
    Soup(SoupParams),
    Fan(FanParams),
    Slivers(SliverParams),
}

/// A generator parameter out of range, naming it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("parameter {field}: {message}")]
pub struct ParamError {
    pub field: &'static str,
    pub message: String,
}

pub(crate) fn param_error(field: &'static str, message: impl Into<String>) -> ParamError {
    ParamError {
        field,
        message: message.into(),
    }
}

/// Checks that a generator would make at most [`MAX_GENERATED_TRIANGLES`].
pub(crate) fn check_count(field: &'static str, triangles: u64) -> Result<(), ParamError> {
    if triangles > MAX_GENERATED_TRIANGLES {
        return Err(param_error(
            field,
            format!("would make {triangles} triangles; the limit is {MAX_GENERATED_TRIANGLES}"),
        ));
    }
    Ok(())
}

impl Generator {
    pub const NAMES: [&'static str; 6] = ["teapots", "grid", "sphere", "soup", "fan", "slivers"];

    /// Builds a generator from its name and a table of parameters (unknown
    /// parameters are an error naming them).
    pub fn from_table(name: &str, params: toml::Table) -> Result<Generator, String> {
        fn parse<'de, T: Deserialize<'de>>(params: toml::Table) -> Result<T, String> {
            params
                .try_into()
                .map_err(|e: toml::de::Error| e.message().to_string())
        }
        Ok(match name {
            "teapots" => Generator::Teapots(parse(params)?),
            "grid" => Generator::Grid(parse(params)?),
            "sphere" => Generator::Sphere(parse(params)?),
            "soup" => Generator::Soup(parse(params)?),
            "fan" => Generator::Fan(parse(params)?),
            "slivers" => Generator::Slivers(parse(params)?),
            other => {
                return Err(format!(
                    "unknown generator '{other}'; generators are: {}",
                    Generator::NAMES.join(", ")
                ));
            }
        })
    }

    pub fn name(&self) -> &'static str {
        match self {
            Generator::Teapots(_) => "teapots",
            Generator::Grid(_) => "grid",
            Generator::Sphere(_) => "sphere",
            Generator::Soup(_) => "soup",
            Generator::Fan(_) => "fan",
            Generator::Slivers(_) => "slivers",
        }
    }

    /// Makes the mesh (material id 0 on every triangle).
    pub fn generate(&self) -> Result<Mesh, ParamError> {
        let mut mesh = match self {
            Generator::Teapots(p) => p.generate()?,
            Generator::Grid(p) => p.generate()?,
            Generator::Sphere(p) => p.generate()?,
            Generator::Soup(p) => p.generate()?,
            Generator::Fan(p) => p.generate()?,
            Generator::Slivers(p) => p.generate()?,
        };
        mesh.material_ids = vec![0; mesh.triangles.len()];
        Ok(mesh)
    }
}

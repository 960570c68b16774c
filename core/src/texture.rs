//! Textures: images decoded from sRGB into linear light, their mip chains
//! (2×2 box filter per level), and filtered lookups — `nearest`, `bilinear`,
//! `trilinear`, and `anisotropic:N` — driven by the screen-space derivatives
//! of the texture coordinates that a 2×2 pixel quad gives (the `ddx_coarse`
//! approach of paper §4; the MIT lecture's mip-mapping and anisotropic filtering).
//! Coordinates outside [0, 1] wrap as the texture's sampler says ([`Wrap`]:
//! repeat, clamp to edge, mirrored repeat).

use glam::{Vec2, Vec4};

use crate::color::decode_srgb;
use crate::ground::FieldError;
use crate::scene::{ImageSource, Wrap};

/// How texture lookups are filtered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TextureFilter {
    /// The texel under the sample, from the full-resolution level.
    Nearest,
    /// Four texels of the full-resolution level, weighted.
    Bilinear,
    /// Bilinear in the two levels around the footprint's size, blended.
    #[default]
    Trilinear,
    /// Up to `N` trilinear probes along the footprint's long axis (N ≤ 16).
    Anisotropic(u32),
}

/// The filter words, for messages.
pub const TEXTURE_FILTERS: &str = "nearest, bilinear, trilinear, anisotropic:N (N in 1..=16)";

impl TextureFilter {
    /// Parses the CLI's word; the error names the field `texture_filter`.
    pub fn parse(s: &str) -> Result<TextureFilter, FieldError> {
        let bad = || {
            FieldError::new(
                "texture_filter",
                format!("'{s}' is not a filter; one of {TEXTURE_FILTERS}"),
            )
        };
        Ok(match s.trim() {
            "nearest" => TextureFilter::Nearest,
            "bilinear" => TextureFilter::Bilinear,
            "trilinear" => TextureFilter::Trilinear,
            other => {
                let n: u32 = other
                    .strip_prefix("anisotropic:")
                    .and_then(|n| n.parse().ok())
                    .ok_or_else(bad)?;
                if !(1..=16).contains(&n) {
                    return Err(bad());
                }
                TextureFilter::Anisotropic(n)
            }
        })
    }
}

impl std::fmt::Display for TextureFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TextureFilter::Nearest => f.write_str("nearest"),
            TextureFilter::Bilinear => f.write_str("bilinear"),
            TextureFilter::Trilinear => f.write_str("trilinear"),
            TextureFilter::Anisotropic(n) => write!(f, "anisotropic:{n}"),
        }
    }
}

/// One level of a mip chain: linear RGBA texels, row-major.
#[derive(Clone, Debug, PartialEq)]
struct Level {
    width: u32,
    height: u32,
    texels: Vec<Vec4>,
}

impl Level {
    /// The texel at integer coordinates, wrapped along u and v.
    #[inline]
    fn texel(&self, x: i64, y: i64, [wu, wv]: [Wrap; 2]) -> Vec4 {
        let x = wu.texel(x, self.width);
        let y = wv.texel(y, self.height);
        self.texels[y * self.width as usize + x]
    }

    /// The texel whose area holds `uv`.
    #[inline]
    fn nearest(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec4 {
        let x = (uv.x * self.width as f32).floor() as i64;
        let y = (uv.y * self.height as f32).floor() as i64;
        self.texel(x, y, wrap)
    }

    /// The four texels around `uv` (texel centres at half-integers), weighted.
    #[inline]
    fn bilinear(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec4 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let texel = |dx, dy| self.texel(x0 + dx, y0 + dy, wrap);
        let top = texel(0, 0).lerp(texel(1, 0), fx);
        let bottom = texel(0, 1).lerp(texel(1, 1), fx);
        top.lerp(bottom, fy)
    }

    /// The next level: each texel the mean of (up to) 2×2 of this one's.
    fn halved(&self) -> Level {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let mut texels = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let xs = [2 * x, (2 * x + 1).min(self.width - 1)];
                let ys = [2 * y, (2 * y + 1).min(self.height - 1)];
                let mut sum = Vec4::ZERO;
                for &sy in &ys {
                    for &sx in &xs {
                        sum += self.texels[(sy * self.width + sx) as usize];
                    }
                }
                texels.push(sum / 4.0);
            }
        }
        Level {
            width: w,
            height: h,
            texels,
        }
    }
}

/// A texture and its mip chain, level 0 first, down to 1×1.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    levels: Vec<Level>,
}

impl MipChain {
    /// From sRGB-encoded RGBA8 texels (alpha stays linear).
    pub fn from_srgb_rgba8(width: u32, height: u32, rgba: &[u8]) -> MipChain {
        assert_eq!(
            rgba.len(),
            (width * height * 4) as usize,
            "width × height RGBA texels"
        );
        let texels = rgba
            .chunks_exact(4)
            .map(|c| {
                Vec4::new(
                    decode_srgb(c[0]),
                    decode_srgb(c[1]),
                    decode_srgb(c[2]),
                    f32::from(c[3]) / 255.0,
                )
            })
            .collect();
        let mut levels = vec![Level {
            width,
            height,
            texels,
        }];
        while let Some(last) = levels.last()
            && (last.width > 1 || last.height > 1)
        {
            let next = last.halved();
            levels.push(next);
        }
        MipChain { levels }
    }

    /// Decodes a scene image (PNG or JPEG) from where it lives.
    pub fn load(source: &ImageSource) -> Result<MipChain, String> {
        match source {
            ImageSource::File(path) => {
                let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
                MipChain::decode(&bytes).map_err(|e| format!("{}: {e}", path.display()))
            }
            ImageSource::Embedded { bytes, .. } => MipChain::decode(bytes),
            ImageSource::DataUri(uri) => {
                use base64::Engine as _;
                let data = uri
                    .split_once(";base64,")
                    .map(|(_, data)| data)
                    .ok_or_else(|| "a data: URI that is not base64".to_owned())?;
                let bytes = base64::engine::general_purpose::STANDARD
                    .decode(data.trim())
                    .map_err(|e| format!("data: URI: {e}"))?;
                MipChain::decode(&bytes)
            }
        }
    }

    /// Decodes a PNG or JPEG image.
    pub fn decode(bytes: &[u8]) -> Result<MipChain, String> {
        let image = image::load_from_memory(bytes)
            .map_err(|e| e.to_string())?
            .to_rgba8();
        if image.width() == 0 || image.height() == 0 {
            return Err("the image is empty".into());
        }
        Ok(MipChain::from_srgb_rgba8(
            image.width(),
            image.height(),
            image.as_raw(),
        ))
    }

    pub fn size(&self) -> (u32, u32) {
        (self.levels[0].width, self.levels[0].height)
    }

    /// Texels over every level.
    pub fn texel_count(&self) -> usize {
        self.levels.iter().map(|l| l.texels.len()).sum()
    }

    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// The filtered colour at `uv`, where `ddx`, `ddy` are how `uv` changes
    /// from one pixel to the next along x and y, wrapped by `wrap`; returns
    /// it and the number of bilinear (or nearest) probes it took.
    pub fn sample(
        &self,
        uv: Vec2,
        (ddx, ddy): (Vec2, Vec2),
        filter: TextureFilter,
        wrap: [Wrap; 2],
    ) -> (Vec4, u32) {
        let base = &self.levels[0];
        let size = Vec2::new(base.width as f32, base.height as f32);
        // The footprint's axes in texels.
        let (ax, ay) = (ddx * size, ddy * size);
        let (lx, ly) = (ax.length(), ay.length());
        match filter {
            TextureFilter::Nearest => (base.nearest(uv, wrap), 1),
            TextureFilter::Bilinear => (base.bilinear(uv, wrap), 1),
            TextureFilter::Trilinear => self.trilinear(uv, lx.max(ly), wrap),
            TextureFilter::Anisotropic(max) => {
                // Probes along the major axis, each as wide as the minor one
                // (or as the major one over `max`, when that is wider).
                let (major_len, minor_len, major) = if lx >= ly {
                    (lx, ly, ddx)
                } else {
                    (ly, lx, ddy)
                };
                let probes = if minor_len > 0.0 {
                    (major_len / minor_len).ceil().clamp(1.0, max as f32) as u32
                } else {
                    max
                };
                let width = minor_len.max(major_len / probes as f32);
                let mut sum = Vec4::ZERO;
                let mut taken = 0;
                for i in 0..probes {
                    let offset = (i as f32 + 0.5) / probes as f32 - 0.5;
                    let (c, n) = self.trilinear(uv + major * offset, width, wrap);
                    sum += c;
                    taken += n;
                }
                (sum / probes as f32, taken)
            }
        }
    }

    /// Trilinear filtering of a footprint `width` texels across.
    fn trilinear(&self, uv: Vec2, width: f32, wrap: [Wrap; 2]) -> (Vec4, u32) {
        let lod = width.max(1.0).log2().min((self.levels.len() - 1) as f32);
        let lo = lod.floor() as usize;
        let hi = (lo + 1).min(self.levels.len() - 1);
        let t = lod - lo as f32;
        if t == 0.0 || lo == hi {
            return (self.levels[lo].bilinear(uv, wrap), 1);
        }
        (
            self.levels[lo]
                .bilinear(uv, wrap)
                .lerp(self.levels[hi].bilinear(uv, wrap), t),
            2,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `size`² checkerboard of black and white texels.
    fn checker(size: u32) -> MipChain {
        let rgba: Vec<u8> = (0..size * size)
            .flat_map(|i| {
                let v = if (i % size + i / size).is_multiple_of(2) {
                    255
                } else {
                    0
                };
                [v, v, v, 255]
            })
            .collect();
        MipChain::from_srgb_rgba8(size, size, &rgba)
    }

    #[test]
    fn filters_parse_and_print_alike() {
        for f in [
            TextureFilter::Nearest,
            TextureFilter::Bilinear,
            TextureFilter::Trilinear,
            TextureFilter::Anisotropic(16),
        ] {
            assert_eq!(TextureFilter::parse(&f.to_string()), Ok(f));
        }
        for bad in ["anisotropic:0", "anisotropic:17", "anisotropic", "linear"] {
            assert_eq!(
                TextureFilter::parse(bad).expect_err(bad).field,
                "texture_filter"
            );
        }
    }

    #[test]
    fn the_chain_halves_to_one_texel_keeping_the_mean() {
        let c = checker(8);
        assert_eq!(c.level_count(), 4);
        let last = &c.levels[3];
        assert_eq!((last.width, last.height), (1, 1));
        assert!((last.texels[0].x - 0.5).abs() < 1e-6, "{}", last.texels[0]);
        // Odd sizes round down and still reach 1×1.
        let odd = MipChain::from_srgb_rgba8(5, 3, &[128; 5 * 3 * 4]);
        assert_eq!(
            odd.levels
                .iter()
                .map(|l| (l.width, l.height))
                .collect::<Vec<_>>(),
            vec![(5, 3), (2, 1), (1, 1)]
        );
    }

    #[test]
    fn lookups_wrap_and_filter() {
        let c = checker(4);
        let white = Vec4::ONE;
        let d = (Vec2::ZERO, Vec2::ZERO);
        let repeat = [Wrap::Repeat; 2];
        let nearest = |uv, wrap| c.sample(uv, d, TextureFilter::Nearest, wrap).0;
        // The first texel is white, its right neighbour black; uv wraps.
        assert_eq!(nearest(Vec2::new(0.1, 0.1), repeat), white);
        assert_eq!(nearest(Vec2::new(1.1, -0.9), repeat), white);
        // u = 1.1: repeat is texel 0 (white), clamp the last texel of row 0
        // (black), mirror texel 3 of the mirrored copy (black); v = -0.9
        // mirrored is row 3.
        assert_eq!(
            nearest(Vec2::new(1.1, 0.1), [Wrap::ClampToEdge; 2]),
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        );
        assert_eq!(
            nearest(Vec2::new(1.1, 0.1), [Wrap::MirroredRepeat; 2]),
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        );
        assert_eq!(
            nearest(Vec2::new(0.1, -0.9), [Wrap::Repeat, Wrap::MirroredRepeat]),
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        );
        assert_eq!(
            nearest(Vec2::new(-0.1, 0.1), [Wrap::MirroredRepeat; 2]),
            white
        );
        // Halfway between texel centres: the mean.
        let mid = c
            .sample(Vec2::new(0.25, 0.125), d, TextureFilter::Bilinear, repeat)
            .0;
        assert!((mid.x - 0.5).abs() < 1e-6, "{mid}");
        // A footprint of the whole texture: the 1×1 level's grey.
        let wide = c
            .sample(
                Vec2::new(0.3, 0.7),
                (Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)),
                TextureFilter::Trilinear,
                repeat,
            )
            .0;
        assert!((wide.x - 0.5).abs() < 1e-6, "{wide}");
    }

    #[test]
    fn anisotropic_probes_follow_the_long_axis() {
        let c = checker(64);
        // Footprint 8 texels along u, 1 along v: 8 probes at level 0.
        let ddx = Vec2::new(8.0 / 64.0, 0.0);
        let ddy = Vec2::new(0.0, 1.0 / 64.0);
        let repeat = [Wrap::Repeat; 2];
        let (color, probes) = c.sample(
            Vec2::new(0.5, 0.5),
            (ddx, ddy),
            TextureFilter::Anisotropic(16),
            repeat,
        );
        assert_eq!(probes, 8);
        assert!((color.x - 0.5).abs() < 0.1, "{color}");
        // Capped at N: four probes, each two texels wide (level 1).
        let (_, capped) = c.sample(
            Vec2::new(0.5, 0.5),
            (ddx, ddy),
            TextureFilter::Anisotropic(4),
            repeat,
        );
        assert_eq!(capped, 4);
    }
}

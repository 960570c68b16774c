//! Images of a framebuffer for people: the colour image, the per-pixel
//! edge-evaluation heat map, depth, and triangle ids, as RGBA8 or PNG bytes.
//!
//! Heat-map scale: a pixel with `n` edge evaluations gets the *inferno* colour at
//! `t = ln(1 + n) / ln(1 + max)`, where `max` is the largest count in the image
//! (`Stats::max_edge_evals_per_pixel`); `n = 0` is black, `max` is pale yellow.

use image::{ImageEncoder, RgbaImage};

use crate::framebuffer::{BACKGROUND, Framebuffer};

/// The logarithmic heat-map position of `n` evaluations on a scale topping at `max`.
pub fn heat_position(n: u32, max: u32) -> f64 {
    if max == 0 {
        return 0.0;
    }
    (1.0 + f64::from(n)).ln() / (1.0 + f64::from(max)).ln()
}

/// The heat-map colour of position `t ∈ [0, 1]` (inferno).
pub fn heat_color(t: f64) -> [u8; 4] {
    let c = colorous::INFERNO.eval_continuous(t.clamp(0.0, 1.0));
    [c.r, c.g, c.b, 255]
}

pub fn color_image(fb: &Framebuffer) -> RgbaImage {
    from_pixels(fb, fb.color.iter().copied())
}

/// The heat map of `fb.edge_evals`; black where a frame rendered without
/// counter planes (`RenderRequest::counter_planes` off) has none.
pub fn edge_eval_image(fb: &Framebuffer) -> RgbaImage {
    if fb.edge_evals.is_empty() {
        return from_pixels(fb, std::iter::repeat_n([0, 0, 0, 255], fb.color.len()));
    }
    let max = fb.edge_evals.iter().copied().max().unwrap_or(0);
    // Counts run from 0 to `max` (tens on most frames), so each colour is
    // computed once, not once per pixel (an inferno spline in f64 each);
    // per pixel only where the counts outnumber the pixels.
    if max as usize > fb.edge_evals.len() {
        let colors = fb.edge_evals.iter();
        return from_pixels(fb, colors.map(|&n| heat_color(heat_position(n, max))));
    }
    let colors: Vec<[u8; 4]> = (0..=max)
        .map(|n| heat_color(heat_position(n, max)))
        .collect();
    from_pixels(fb, fb.edge_evals.iter().map(|&n| colors[n as usize]))
}

/// Depth as grey: nearest visible surface white, farthest dark grey, background black.
pub fn depth_image(fb: &Framebuffer) -> RgbaImage {
    let finite = fb.depth.iter().copied().filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| {
        (lo.min(d), hi.max(d))
    });
    let span = (hi - lo).max(f32::MIN_POSITIVE);
    from_pixels(
        fb,
        fb.depth.iter().map(|&d| {
            if d.is_finite() {
                let g = (255.0 - 200.0 * (d - lo) / span) as u8;
                [g, g, g, 255]
            } else {
                [0, 0, 0, 255]
            }
        }),
    )
}

/// Triangle ids as arbitrary but stable colours (a hash of the id); background black.
pub fn triangle_id_image(fb: &Framebuffer) -> RgbaImage {
    from_pixels(
        fb,
        fb.triangle_id.iter().map(|&id| {
            if id == BACKGROUND {
                [0, 0, 0, 255]
            } else {
                let h = id.wrapping_mul(0x9E37_79B1).rotate_left(13) ^ 0x5bd1_e995;
                let [r, g, b, _] = h.to_le_bytes();
                [r | 0x30, g | 0x30, b | 0x30, 255]
            }
        }),
    )
}

fn from_pixels(fb: &Framebuffer, pixels: impl Iterator<Item = [u8; 4]>) -> RgbaImage {
    let raw: Vec<u8> = pixels.flatten().collect();
    RgbaImage::from_raw(fb.width, fb.height, raw).expect("buffer has width × height pixels")
}

/// PNG-encodes an image.
pub fn png_bytes(img: &RgbaImage) -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgba8,
        )
        .expect("encoding to memory cannot fail");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The heat map gives each pixel the colour of its own count, whether
    /// the colours are computed once per count (counts below the pixel
    /// count) or per pixel (a larger count somewhere).
    #[test]
    fn heat_map_colours_each_pixel_by_its_count() {
        let mut fb = Framebuffer::new(4, 3);
        for counts in [
            vec![0, 1, 2, 3, 5, 8, 0, 1, 2, 3, 5, 11],
            vec![0, 1, 7, 1_000, 0, 2, 3, 4, 5, 6, 7, 8],
        ] {
            fb.edge_evals = counts;
            let max = *fb.edge_evals.iter().max().unwrap();
            let image = edge_eval_image(&fb);
            for (k, &n) in fb.edge_evals.iter().enumerate() {
                let pixel = image.get_pixel(k as u32 % 4, k as u32 / 4).0;
                assert_eq!(
                    pixel,
                    heat_color(heat_position(n, max)),
                    "pixel {k}, count {n}"
                );
            }
        }
    }
}

//! The views of a framebuffer as egui images (colour, edge-evaluation heat map,
//! depth, triangle ids — the same pictures `continuum render --maps` writes),
//! the values of one pixel, and the difference of two renders.

use continuum::{BACKGROUND, Framebuffer, maps};
use eframe::egui::{Color32, ColorImage};
use image::RgbaImage;

/// Which buffer the image view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ViewKind {
    Color,
    EdgeEvals,
    Depth,
    TriangleIds,
}

impl ViewKind {
    pub const ALL: [ViewKind; 4] = [
        ViewKind::Color,
        ViewKind::EdgeEvals,
        ViewKind::Depth,
        ViewKind::TriangleIds,
    ];

    /// The word the command line uses (`--view`).
    pub fn word(self) -> &'static str {
        match self {
            ViewKind::Color => "colour",
            ViewKind::EdgeEvals => "edge-evals",
            ViewKind::Depth => "depth",
            ViewKind::TriangleIds => "ids",
        }
    }

    /// Parses [`Self::word`]; the error lists the words.
    pub fn parse(word: &str) -> Result<ViewKind, String> {
        ViewKind::ALL
            .into_iter()
            .find(|k| k.word() == word)
            .ok_or_else(|| {
                let words: Vec<&str> = ViewKind::ALL.iter().map(|k| k.word()).collect();
                format!("'{word}' is not a view; one of {}", words.join(", "))
            })
    }

    pub fn label(self) -> &'static str {
        match self {
            ViewKind::Color => "Colour",
            ViewKind::EdgeEvals => "Edge evaluations",
            ViewKind::Depth => "Depth",
            ViewKind::TriangleIds => "Triangle ids",
        }
    }

    /// This view of `fb`, by the core's own map functions.
    pub fn image(self, fb: &Framebuffer) -> ColorImage {
        to_color_image(&self.rgba(fb))
    }

    /// This view of `fb` as RGBA8, for overlays to draw on.
    pub fn rgba(self, fb: &Framebuffer) -> RgbaImage {
        match self {
            ViewKind::Color => maps::color_image(fb),
            ViewKind::EdgeEvals => maps::edge_eval_image(fb),
            ViewKind::Depth => maps::depth_image(fb),
            ViewKind::TriangleIds => maps::triangle_id_image(fb),
        }
    }
}

/// Everything the framebuffer knows about one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelProbe {
    pub x: u32,
    pub y: u32,
    /// The visible triangle (`None`: background).
    pub triangle_id: Option<u32>,
    /// Distance along the view direction of the visible sample (`None`: background).
    pub depth: Option<f32>,
    pub edge_evals: u32,
    pub coverage_writes: u32,
    pub color: [u8; 4],
}

/// The values of pixel (`x`, `y`), or `None` outside the image.
pub fn probe(fb: &Framebuffer, x: u32, y: u32) -> Option<PixelProbe> {
    if x >= fb.width || y >= fb.height {
        return None;
    }
    let i = (y * fb.width + x) as usize;
    let id = fb.triangle_id[i];
    Some(PixelProbe {
        x,
        y,
        triangle_id: (id != BACKGROUND).then_some(id),
        depth: fb.depth[i].is_finite().then_some(fb.depth[i]),
        edge_evals: fb.edge_evals[i],
        coverage_writes: fb.coverage_writes[i],
        color: fb.color[i],
    })
}

/// Where two renders of the same size differ.
#[derive(Clone, Debug)]
pub struct Difference {
    /// Magenta: a different visible triangle; yellow: same triangle, other colour
    /// (brighter for a larger difference); otherwise A's colour, dimmed.
    pub image: ColorImage,
    pub ids_differ: u64,
    /// Pixels with any colour channel different (ids included).
    pub colours_differ: u64,
}

/// The difference of `a` and `b`, or `None` when their sizes differ.
pub fn difference(a: &Framebuffer, b: &Framebuffer) -> Option<Difference> {
    if (a.width, a.height) != (b.width, b.height) {
        return None;
    }
    let mut ids_differ = 0;
    let mut colours_differ = 0;
    let pixels = a
        .triangle_id
        .iter()
        .zip(&b.triangle_id)
        .zip(a.color.iter().zip(&b.color))
        .map(|((ia, ib), (ca, cb))| {
            let delta = ca
                .iter()
                .zip(cb)
                .map(|(p, q)| p.abs_diff(*q))
                .max()
                .unwrap_or(0);
            colours_differ += u64::from(delta > 0);
            if ia != ib {
                ids_differ += 1;
                Color32::from_rgb(255, 0, 255)
            } else if delta > 0 {
                let v = 128u8.saturating_add(delta.saturating_mul(4));
                Color32::from_rgb(v, v, 0)
            } else {
                let [r, g, b, _] = *ca;
                Color32::from_rgb(r / 3, g / 3, b / 3)
            }
        })
        .collect();
    Some(Difference {
        image: ColorImage::new([a.width as usize, a.height as usize], pixels),
        ids_differ,
        colours_differ,
    })
}

/// An RGBA8 image as egui's.
pub fn to_color_image(rgba: &RgbaImage) -> ColorImage {
    let (w, h) = rgba.dimensions();
    ColorImage::from_rgba_unmultiplied([w as usize, h as usize], rgba.as_raw())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn framebuffer() -> Framebuffer {
        let mut fb = Framebuffer::new(4, 2);
        fb.triangle_id[5] = 7;
        fb.depth[5] = 2.5;
        fb.edge_evals[5] = 12;
        fb.coverage_writes[5] = 1;
        fb.color[5] = [10, 20, 30, 255];
        fb
    }

    #[test]
    fn probe_reads_one_pixel_and_refuses_outside() {
        let fb = framebuffer();
        let p = probe(&fb, 1, 1).expect("inside");
        assert_eq!(
            (p.triangle_id, p.depth, p.edge_evals, p.coverage_writes),
            (Some(7), Some(2.5), 12, 1)
        );
        let background = probe(&fb, 0, 0).expect("inside");
        assert_eq!((background.triangle_id, background.depth), (None, None));
        assert!(probe(&fb, 4, 0).is_none() && probe(&fb, 0, 2).is_none());
    }

    #[test]
    fn difference_counts_id_and_colour_changes() {
        let a = framebuffer();
        let mut b = framebuffer();
        assert_eq!(
            difference(&a, &b).map(|d| (d.ids_differ, d.colours_differ)),
            Some((0, 0))
        );
        b.triangle_id[5] = 8;
        b.color[0] = [1, 0, 0, 255];
        let d = difference(&a, &b).expect("same size");
        assert_eq!((d.ids_differ, d.colours_differ), (1, 1));
        assert_eq!(d.image.pixels[5], Color32::from_rgb(255, 0, 255));
        assert_ne!(d.image.pixels[0], d.image.pixels[1]);
        assert!(difference(&a, &Framebuffer::new(2, 2)).is_none());
    }

    #[test]
    fn view_words_round_trip() {
        for kind in ViewKind::ALL {
            assert_eq!(ViewKind::parse(kind.word()), Ok(kind));
        }
        assert!(
            ViewKind::parse("heat")
                .expect_err("unknown")
                .contains("edge-evals")
        );
    }

    #[test]
    fn every_view_has_the_framebuffer_size() {
        let fb = framebuffer();
        for kind in ViewKind::ALL {
            assert_eq!(kind.image(&fb).size, [4, 2], "{}", kind.label());
        }
    }
}

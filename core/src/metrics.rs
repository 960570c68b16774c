//! Image comparison against a reference render: PSNR and FLIP.
//!
//! - PSNR over the sRGB channels (peak 255), of the whole image and of the
//!   pixels anti-aliasing is about: those where the render without
//!   anti-aliasing differs from the reference (geometry edges and sub-pixel
//!   detail; interior pixels agree in every mode and would only dilute it).
//! - FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating
//!   Images", HPG 2020) through NVIDIA's reference implementation (`nv-flip`),
//!   LDR, at its default 67 pixels per degree; we report the mean error.

use serde::Serialize;

/// How far an image is from a reference.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ImageError {
    /// PSNR in dB over every pixel; `None` when the images are equal (infinite).
    pub psnr: Option<f64>,
    /// PSNR in dB over the pixels of `edges`; `None` when they are equal or
    /// there are none.
    pub psnr_edges: Option<f64>,
    /// Mean FLIP error in [0, 1].
    pub flip_mean: f64,
}

/// Pixels where two images differ in any channel: where anti-aliasing changes
/// anything, when `a` is rendered without it and `b` is the reference.
pub fn differing_pixels(a: &[[u8; 4]], b: &[[u8; 4]]) -> Vec<bool> {
    a.iter().zip(b).map(|(p, q)| p[..3] != q[..3]).collect()
}

/// PSNR in dB over the RGB channels of the pixels where `mask` is set (every
/// pixel when `mask` is `None`); `None` when they are equal or none is selected.
pub fn psnr(reference: &[[u8; 4]], test: &[[u8; 4]], mask: Option<&[bool]>) -> Option<f64> {
    let mut squared = 0.0f64;
    let mut count = 0u64;
    for (i, (r, t)) in reference.iter().zip(test).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        for c in 0..3 {
            let d = f64::from(r[c]) - f64::from(t[c]);
            squared += d * d;
        }
        count += 3;
    }
    if count == 0 || squared == 0.0 {
        return None;
    }
    let mse = squared / count as f64;
    Some(10.0 * (255.0 * 255.0 / mse).log10())
}

/// Mean FLIP error of `test` against `reference` (both `width × height` sRGB).
pub fn flip_mean(reference: &[[u8; 4]], test: &[[u8; 4]], width: u32, height: u32) -> f64 {
    let rgb =
        |img: &[[u8; 4]]| -> Vec<u8> { img.iter().flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference)),
        nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    f64::from(nv_flip::FlipPool::from_image(&error).mean())
}

/// PSNR (whole image and over `edges`) and mean FLIP of `test` against `reference`.
pub fn compare(
    reference: &[[u8; 4]],
    test: &[[u8; 4]],
    edges: &[bool],
    width: u32,
    height: u32,
) -> ImageError {
    ImageError {
        psnr: psnr(reference, test, None),
        psnr_edges: psnr(reference, test, Some(edges)),
        flip_mean: flip_mean(reference, test, width, height),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_of_a_known_error() {
        let a = vec![[100, 100, 100, 255]; 4];
        let mut b = a.clone();
        // One channel of one pixel off by 10: MSE = 100 / 12.
        b[0][0] = 110;
        let expected = 10.0 * (255.0f64 * 255.0 / (100.0 / 12.0)).log10();
        let got = psnr(&a, &b, None).unwrap_or(0.0);
        assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
        assert_eq!(psnr(&a, &a, None), None);
        let mask = differing_pixels(&a, &b);
        assert_eq!(mask, [true, false, false, false]);
        let edge = psnr(&a, &b, Some(&mask)).unwrap_or(0.0);
        assert!((edge - 10.0 * (255.0f64 * 255.0 / (100.0 / 3.0)).log10()).abs() < 1e-9);
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
        let (w, h) = (32, 32);
        let a: Vec<[u8; 4]> = (0..w * h).map(|i| [(i % 256) as u8, 90, 40, 255]).collect();
        assert!(flip_mean(&a, &a, w, h) < 1e-6);
        let mut b = a.clone();
        let mut c = a.clone();
        for p in b.iter_mut().step_by(7) {
            p[1] = 140;
        }
        for p in c.iter_mut().step_by(7) {
            p[1] = 250;
        }
        let (fb, fc) = (flip_mean(&a, &b, w, h), flip_mean(&a, &c, w, h));
        assert!(fb > 0.0 && fc > fb, "{fb} {fc}");
    }
}

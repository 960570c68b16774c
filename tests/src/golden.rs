//! Golden images: a render compared with its PNG under `tests/golden/`
//! exactly, pixel for pixel. On a difference the test writes
//! `NAME-actual.png` (what rendered) and `NAME-diff.png` (differing pixels
//! red over the golden image, dimmed) beside the golden one and fails naming
//! all three. `UPDATE_GOLDEN=1 cargo test -p continuum-tests golden` writes
//! the golden images instead (review them before committing).

use std::path::{Path, PathBuf};

use image::{Rgba, RgbaImage};

/// The folder of golden images.
pub fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("golden")
}

/// Asserts that `image` is the golden image `golden/NAME.png` (`name` may
/// hold a subfolder, e.g. `aa/box_msaa4`).
pub fn assert_golden(name: &str, image: &RgbaImage) {
    let path = golden_dir().join(format!("{name}.png"));
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).expect("golden folder");
        }
        image.save(&path).expect("write golden image");
        return;
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (UPDATE_GOLDEN=1 writes it)", path.display()))
        .to_rgba8();
    let differing = if golden.dimensions() == image.dimensions() {
        golden
            .pixels()
            .zip(image.pixels())
            .filter(|(a, b)| a != b)
            .count()
    } else {
        (image.width() * image.height()) as usize
    };
    if differing == 0 {
        return;
    }
    let sibling = |suffix: &str| path.with_file_name(format!("{}-{suffix}.png", stem(&path)));
    let (actual, diff) = (sibling("actual"), sibling("diff"));
    image.save(&actual).expect("write the actual image");
    if golden.dimensions() == image.dimensions() {
        difference(&golden, image)
            .save(&diff)
            .expect("write the diff image");
    }
    panic!(
        "{name}: {differing} of {} pixels differ from {} (dimensions {:?} vs {:?}); see {} and {}",
        image.width() * image.height(),
        path.display(),
        golden.dimensions(),
        image.dimensions(),
        actual.display(),
        diff.display()
    );
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}

/// Differing pixels red, the others the golden image's, dimmed to a quarter.
fn difference(golden: &RgbaImage, actual: &RgbaImage) -> RgbaImage {
    RgbaImage::from_fn(golden.width(), golden.height(), |x, y| {
        let (g, a) = (golden.get_pixel(x, y), actual.get_pixel(x, y));
        if g == a {
            Rgba([g[0] / 4, g[1] / 4, g[2] / 4, 255])
        } else {
            Rgba([255, 0, 0, 255])
        }
    })
}

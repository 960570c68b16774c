//! The image on screen: a render drawn pixel-exact where it fits, the mouse
//! gestures on it (orbit, pan, zoom, hover), the pixel loupe and the heat-map
//! legend.

use continuum::maps::{heat_color, heat_position};
use eframe::egui::{
    self, Color32, ColorImage, Pos2, Rect, Sense, Stroke, StrokeKind, TextureHandle, Vec2,
    emath::GuiRounding as _, pos2, vec2,
};

/// What the mouse did to an image this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gesture {
    /// Orbit by (yaw, pitch) radians: primary-button drag.
    pub orbit: Vec2,
    /// Pan by image heights: secondary or middle drag, or shift + primary.
    pub pan: Vec2,
    /// Distance factor (< 1 closer): the scroll wheel over the image.
    pub zoom: f32,
    /// Double click: back to the scene's camera.
    pub reset: bool,
    /// The image pixel under the cursor.
    pub hovered: Option<(u32, u32)>,
}

impl Default for Gesture {
    fn default() -> Gesture {
        Gesture {
            orbit: Vec2::ZERO,
            pan: Vec2::ZERO,
            zoom: 1.0,
            reset: false,
            hovered: None,
        }
    }
}

impl Gesture {
    /// Both gestures (the compare view's images each report one).
    pub fn merge(self, o: Gesture) -> Gesture {
        Gesture {
            orbit: self.orbit + o.orbit,
            pan: self.pan + o.pan,
            zoom: self.zoom * o.zoom,
            reset: self.reset || o.reset,
            hovered: self.hovered.or(o.hovered),
        }
    }

    /// Whether the camera moves.
    pub fn moves(&self) -> bool {
        self.orbit != Vec2::ZERO || self.pan != Vec2::ZERO || self.zoom != 1.0
    }
}

/// Radians of orbit per point of drag.
const ORBIT_PER_POINT: f32 = 0.008;

/// Points per image pixel for an image of `size` pixels in `available` points:
/// whole multiples when it fits at 1:1 or more, so pixels stay sharp.
pub fn fit_scale(size: [u32; 2], available: Vec2, pixels_per_point: f32) -> f32 {
    let fit = (available.x / size[0] as f32).min(available.y / size[1] as f32);
    let fit_pixels = fit * pixels_per_point;
    if fit_pixels >= 1.0 {
        fit_pixels.floor() / pixels_per_point
    } else {
        fit.max(f32::MIN_POSITIVE)
    }
}

/// Draws `texture` (an image of `size` pixels) scaled into the space available,
/// and reports what the mouse did on it.
pub fn show(
    ui: &mut egui::Ui,
    texture: &TextureHandle,
    size: [u32; 2],
    available: Vec2,
) -> Gesture {
    let scale = fit_scale(size, available, ui.ctx().pixels_per_point());
    let shown = vec2(size[0] as f32, size[1] as f32) * scale;
    let (rect, response) = ui.allocate_exact_size(shown, Sense::click_and_drag());
    // Snap to the physical pixel grid so 1:1 really is 1:1.
    let rect = Rect::from_min_size(
        rect.min.round_to_pixels(ui.ctx().pixels_per_point()),
        rect.size(),
    );
    ui.painter().image(
        texture.id(),
        rect,
        Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)),
        Color32::WHITE,
    );

    let mut gesture = Gesture::default();
    let drag = response.drag_delta();
    let panning = response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
        || (response.dragged_by(egui::PointerButton::Primary) && ui.input(|i| i.modifiers.shift));
    if panning {
        gesture.pan = drag / shown.y;
    } else if response.dragged_by(egui::PointerButton::Primary) {
        gesture.orbit = vec2(-drag.x, drag.y) * ORBIT_PER_POINT;
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        gesture.zoom = (-scroll * 0.002).exp();
    }
    gesture.reset = response.double_clicked();
    gesture.hovered = response.hover_pos().and_then(|p| pixel_at(p, rect, size));
    gesture
}

fn pixel_at(p: Pos2, rect: Rect, size: [u32; 2]) -> Option<(u32, u32)> {
    let u = (p - rect.min) / rect.size();
    let x = (u.x * size[0] as f32).floor();
    let y = (u.y * size[1] as f32).floor();
    (x >= 0.0 && y >= 0.0 && x < size[0] as f32 && y < size[1] as f32)
        .then_some((x as u32, y as u32))
}

/// Pixels on each side of the loupe's centre.
pub const LOUPE_RADIUS: i64 = 6;

/// The pixels around (`x`, `y`) of `image`, magnified into a square of `side`
/// points; the centre pixel outlined.
pub fn loupe(ui: &mut egui::Ui, image: &ColorImage, (x, y): (u32, u32), side: f32) {
    let (rect, _) = ui.allocate_exact_size(Vec2::splat(side), Sense::hover());
    let cells = 2 * LOUPE_RADIUS + 1;
    let cell = side / cells as f32;
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(24));
    for dy in -LOUPE_RADIUS..=LOUPE_RADIUS {
        for dx in -LOUPE_RADIUS..=LOUPE_RADIUS {
            let (px, py) = (i64::from(x) + dx, i64::from(y) + dy);
            if px < 0 || py < 0 || px >= image.size[0] as i64 || py >= image.size[1] as i64 {
                continue;
            }
            let color = image.pixels[py as usize * image.size[0] + px as usize];
            let min =
                rect.min + vec2((dx + LOUPE_RADIUS) as f32, (dy + LOUPE_RADIUS) as f32) * cell;
            painter.rect_filled(Rect::from_min_size(min, Vec2::splat(cell)), 0.0, color);
        }
    }
    let centre = Rect::from_min_size(
        rect.min + Vec2::splat(LOUPE_RADIUS as f32 * cell),
        Vec2::splat(cell),
    );
    painter.rect_stroke(
        centre,
        0.0,
        Stroke::new(2.0, Color32::from_rgb(0, 255, 255)),
        StrokeKind::Outside,
    );
}

/// The heat map's scale: inferno on `ln(1+n)/ln(1+max)` from `min` to `max`
/// evaluations, with the counts at a few positions along it.
pub fn heat_legend(ui: &mut egui::Ui, min: u32, max: u32, width: f32) {
    let height = 14.0;
    let (rect, _) = ui.allocate_exact_size(vec2(width, height), Sense::hover());
    let painter = ui.painter_at(rect);
    let steps = 128;
    for i in 0..steps {
        let t = (i as f64 + 0.5) / steps as f64;
        let [r, g, b, _] = heat_color(t);
        let x0 = rect.left() + rect.width() * i as f32 / steps as f32;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / steps as f32;
        painter.rect_filled(
            Rect::from_min_max(pos2(x0, rect.top()), pos2(x1 + 0.5, rect.bottom())),
            0.0,
            Color32::from_rgb(r, g, b),
        );
    }
    let (tick_rect, _) = ui.allocate_exact_size(vec2(width, 16.0), Sense::hover());
    let painter = ui.painter_at(tick_rect.expand2(vec2(30.0, 0.0)));
    // Counts along the bar, none crowding the next or the maximum.
    let x_of = |n: u32| tick_rect.left() + tick_rect.width() * heat_position(n, max) as f32;
    let max_x = x_of(max);
    let mut last_x = f32::NEG_INFINITY;
    for n in legend_ticks(max) {
        let x = x_of(n);
        if n != max && (x - last_x < 34.0 || max_x - x < 34.0) {
            continue;
        }
        last_x = x;
        painter.text(
            pos2(x, tick_rect.top()),
            egui::Align2::CENTER_TOP,
            n.to_string(),
            egui::FontId::monospace(11.0),
            ui.visuals().text_color(),
        );
    }
    ui.label(format!(
        "edge evaluations per pixel: min {min}, max {max} (log scale)"
    ));
}

/// 0, then 1, 2, 5, 10, 20, 50 … below `max`, then `max`.
fn legend_ticks(max: u32) -> Vec<u32> {
    let mut ticks = vec![0];
    let mut decade = 1u64;
    'outer: loop {
        for m in [1, 2, 5] {
            let n = decade * m;
            if n >= u64::from(max) {
                break 'outer;
            }
            ticks.push(n as u32);
        }
        decade *= 10;
    }
    if max > 0 {
        ticks.push(max);
    }
    ticks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_scale_keeps_whole_pixels_when_the_image_fits() {
        assert_eq!(fit_scale([100, 50], vec2(350.0, 400.0), 1.0), 3.0);
        assert_eq!(fit_scale([100, 50], vec2(350.0, 400.0), 2.0), 3.5);
        assert_eq!(fit_scale([1000, 500], vec2(500.0, 500.0), 1.0), 0.5);
    }

    #[test]
    fn pixels_under_the_cursor() {
        let rect = Rect::from_min_size(pos2(10.0, 20.0), vec2(200.0, 100.0));
        assert_eq!(pixel_at(pos2(10.0, 20.0), rect, [100, 50]), Some((0, 0)));
        assert_eq!(
            pixel_at(pos2(209.9, 119.9), rect, [100, 50]),
            Some((99, 49))
        );
        assert_eq!(pixel_at(pos2(210.0, 50.0), rect, [100, 50]), None);
        assert_eq!(pixel_at(pos2(9.0, 50.0), rect, [100, 50]), None);
    }

    #[test]
    fn legend_ticks_step_1_2_5_and_end_at_max() {
        assert_eq!(legend_ticks(0), vec![0]);
        assert_eq!(legend_ticks(1), vec![0, 1]);
        assert_eq!(legend_ticks(60), vec![0, 1, 2, 5, 10, 20, 50, 60]);
    }
}

//! Vertex welding: merge vertices closer than a tolerance, so patches and seams
//! share vertices (and therefore edges) exactly.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

/// Welds `points` with tolerance `tol`; returns the unique positions (in first-seen
/// order, rounded to f32) and, per input point, its index among them.
pub(crate) fn weld(points: &[DVec3], tol: f64) -> (Vec<Vec3>, Vec<u32>) {
    let cell = |p: DVec3| {
        (
            (p.x / tol).floor() as i64,
            (p.y / tol).floor() as i64,
            (p.z / tol).floor() as i64,
        )
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    let mut unique: Vec<DVec3> = Vec::new();
    let mut remap = Vec::with_capacity(points.len());
    for &p in points {
        let (cx, cy, cz) = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&(cx + dx, cy + dy, cz + dz))
                        && let Some(&i) = list
                            .iter()
                            .find(|&&i| unique[i as usize].distance(p) <= tol)
                    {
                        found = Some(i);
                        break 'search;
                    }
                }
            }
        }
        let index = found.unwrap_or_else(|| {
            let i = unique.len() as u32;
            unique.push(p);
            grid.entry((cx, cy, cz)).or_default().push(i);
            i
        });
        remap.push(index);
    }
    (unique.into_iter().map(|p| p.as_vec3()).collect(), remap)
}

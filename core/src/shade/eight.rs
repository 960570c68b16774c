//! Eight samples shaded at once: [`Shader::shade`]'s local shading — the
//! shaded point on the triangle's plane, the §3.2 barycentrics, the
//! interpolated normal, Lambert over every light, base colour and emission —
//! on lanes, for the samples of a planar view whose material asks for nothing
//! else (no texture, vertex colours, mirror or shadow ray).
//!
//! Every lane performs the IEEE operations of the scalar path (glam's `Vec3`:
//! `dot` as `(x·x' + y·y') + z·z'`, `cross`, `1 / sqrt` for normalizing) in the
//! same order with no fused multiply-add, so a lane's colour is the scalar
//! colour bit for bit. Lanes that meet one of the scalar path's special cases
//! (a ray along the plane when a light has a position, degenerate
//! barycentrics, a zero vertex normal, an interpolated normal or light vector
//! that does not normalize, a NaN) are not shaded here: the caller shades them
//! with [`Shader::shade`].

use glam::{Vec3, Vec4};

use super::{AMBIENT, LightFrom, Shader};
use crate::simd::{self, Lanes, finite};

/// Three lanes of f32: eight vectors.
#[derive(Clone, Copy)]
struct V3<L> {
    x: L,
    y: L,
    z: L,
}

impl<L: Lanes> V3<L> {
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        V3 {
            x: L::splat(v.x),
            y: L::splat(v.y),
            z: L::splat(v.z),
        }
    }

    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    fn scale(self, s: L) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// Fields 0–2 of the rows `index` of `flat` (rows of `stride` floats).
    #[inline(always)]
    fn gathered(flat: &[f32], stride: u32, index: [u32; 8]) -> Self {
        let [x, y, z] = L::gather_xyz(flat, stride, index);
        V3 { x, y, z }
    }

    /// glam's `normalize_or`: `self · (1 / |self|)`, and the lanes where
    /// that reciprocal is finite and positive (elsewhere the scalar path
    /// takes a fallback).
    #[inline(always)]
    fn normalized(self) -> (Self, u8) {
        let rcp = L::splat(1.0) / self.dot(self).sqrt();
        let ok = finite(rcp) & rcp.gt(L::splat(0.0));
        (self.scale(rcp), ok)
    }
}

/// `v0 + vx·x + vy·y` on lanes, as `View::direction` and `View::origin_offset`
/// evaluate it.
#[inline(always)]
fn along<L: Lanes>([v0, vx, vy]: [Vec3; 3], x: L, y: L) -> V3<L> {
    V3::splat(v0)
        .add(V3::splat(vx).scale(x))
        .add(V3::splat(vy).scale(y))
}

/// The lit share of a base colour channel: `AMBIENT + (1 − AMBIENT)·lit`.
#[inline(always)]
fn ambient<L: Lanes>(lit: L) -> L {
    L::splat(AMBIENT) + L::splat(1.0 - AMBIENT) * lit
}

/// Eight samples of one row, at `(x + l) + ox` and `y` for lane `l`:
/// triangle ids, positions and the lanes to shade.
#[derive(Clone, Copy, Debug)]
pub(crate) struct EightSamples {
    pub ids: [u32; 8],
    /// The first lane's pixel column (an integer).
    pub x: f32,
    /// The sample's offset in its pixel.
    pub ox: f32,
    pub y: f32,
    /// Lanes holding a triangle whose material [`Shader::shades_in_lanes`].
    pub lanes: u8,
}

impl EightSamples {
    /// Each lane's x: its column, `x + l` (integers add exactly in f32),
    /// plus the offset — what `column as f32 + ox` gives.
    #[inline(always)]
    pub(crate) fn lane_x<L: Lanes>(&self) -> L {
        let steps = L::from_array(std::array::from_fn(|l| l as f32));
        (L::splat(self.x) + steps) + L::splat(self.ox)
    }
}

impl Shader<'_> {
    /// Whether triangle `id`'s samples can be shaded by [`Shader::shade_eight`].
    #[inline(always)]
    pub(crate) fn shades_in_lanes(&self, id: u32) -> bool {
        self.lane_materials.get(self.material_of(id) as usize) == Some(&true)
    }

    /// Of the eight ids, bit per lane: those of `lanes` that [`Shader::shades_in_lanes`].
    #[inline(always)]
    pub(crate) fn lanes_shaded(&self, ids: &[u32; 8], lanes: u8) -> u8 {
        if self.all_in_lanes {
            return lanes;
        }
        (0..8)
            .filter(|&l| lanes & (1 << l) != 0 && self.shades_in_lanes(ids[l]))
            .fold(0, |m, l| m | 1 << l)
    }

    /// The linear colour [`Shader::shade`] gives each lane of `s`, channel
    /// by channel (red, green, blue), and the lanes it holds: those of
    /// `s.lanes` that met none of the scalar path's special cases (see the
    /// module documentation).
    #[inline(always)]
    pub(crate) fn shade_eight<L: Lanes>(&self, s: &EightSamples) -> ([L; 3], u8) {
        let prepared = self.scene;
        let mesh = &prepared.scene.mesh;
        let interpolated = !mesh.normals.is_empty();
        debug_assert!(s.lanes != 0, "at least one lane to shade");
        let mut done = s.lanes;
        // 1. What each lane's triangle brings (lanes without one take the
        // first that has one, so that every lane computes on real values).
        // Eight lanes of one triangle (most eights of a scene of large
        // triangles) read it once and broadcast it; other eights read in
        // lanes: each lane's face normal and, where they are needed, its
        // vertex record, then its three corners and normals, a row load each
        // ([`Ops::gather_xyz`]) — no branch on how
        // many triangles they hold, so the reads of every lane are on their
        // way at once. Either way every lane holds the same values, so the
        // same colour.
        let first = s.ids[done.trailing_zeros() as usize];
        let uniform = L::differ(s.ids, first) & done == 0;
        let ids: [u32; 8] = std::array::from_fn(|l| match done & (1 << l) {
            0 => first,
            _ => s.ids[l],
        });
        // The corners only where the barycentrics or the plane distance
        // read them: the face normal is the scene's, as the scalar path
        // reads it.
        let cornered = interpolated || self.point_lights;
        // (No closure around a lane operation: it would be compiled without
        // the lanes' instruction set.)
        let mut normals = [V3::<L>::splat(Vec3::ZERO); 3];
        let mut corners = [V3::<L>::splat(Vec3::ZERO); 3];
        let facing = if uniform {
            if cornered {
                let [a, b, c] = mesh.triangles[first as usize].map(|v| v as usize);
                if interpolated {
                    let n = &mesh.normals;
                    normals = [V3::splat(n[a]), V3::splat(n[b]), V3::splat(n[c])];
                }
                let p = &mesh.positions;
                corners = [V3::splat(p[a]), V3::splat(p[b]), V3::splat(p[c])];
            }
            V3::splat(prepared.face_normals[first as usize])
        } else {
            if cornered {
                let triangles = mesh.triangles.as_flattened();
                let [a, b, c] = simd::gather_xyz_u32::<L>(triangles, 3, ids);
                if interpolated {
                    let flat = bytemuck::cast_slice(&mesh.normals);
                    normals = [
                        V3::gathered(flat, 3, a),
                        V3::gathered(flat, 3, b),
                        V3::gathered(flat, 3, c),
                    ];
                }
                let flat = bytemuck::cast_slice(&mesh.positions);
                corners = [
                    V3::gathered(flat, 3, a),
                    V3::gathered(flat, 3, b),
                    V3::gathered(flat, 3, c),
                ];
            }
            V3::gathered(bytemuck::cast_slice(&prepared.face_normals), 3, ids)
        };
        let [p0, p1, p2] = corners;
        if interpolated {
            // The scalar path's case (a zero vertex normal): these lanes go there.
            let zero = L::splat(0.0);
            for n in normals {
                done &= !(n.x.eq(zero) & n.y.eq(zero) & n.z.eq(zero));
            }
        }
        let (base, emissive): (V3<L>, V3<L>) = match &self.material_rows[..] {
            [] => {
                let material = &prepared.scene.materials[0];
                (
                    V3::splat(Vec4::from(material.base_color).truncate()),
                    V3::splat(Vec3::from(material.emissive)),
                )
            }
            rows if uniform => {
                let row = rows[mesh.material_ids[first as usize] as usize];
                (
                    V3::splat(Vec3::new(row[0], row[1], row[2])),
                    V3::splat(Vec3::new(row[4], row[5], row[6])),
                )
            }
            rows => {
                let of = L::gather(bytemuck::cast_slice(&mesh.material_ids), ids);
                let of = bytemuck::cast(of.to_array());
                let flat = rows.as_flattened();
                (V3::gathered(flat, 8, of), V3::gathered(&flat[4..], 8, of))
            }
        };

        // 2. The ray through each sample (`View::origin`, `View::direction`).
        let view = self.view;
        let (x, y) = (s.lane_x::<L>(), L::splat(s.y));
        let dir = along([view.d0, view.dx, view.dy], x, y);
        let origin = V3::splat(view.eye).add(along([view.o0, view.ox, view.oy], x, y));

        // 3. Where the ray meets the triangle's plane (`plane_distance`):
        // only a light with a position reads it (elsewhere the colour does
        // not depend on it, nor on whether the scalar path finds it).
        let mut point = origin;
        if self.point_lights {
            let normal = p1.sub(p0).cross(p2.sub(p0));
            let denom = normal.dot(dir);
            let t = normal.dot(p0.sub(origin)) / denom;
            done &= !denom.eq(L::splat(0.0)) & finite(t);
            point = origin.add(dir.scale(t));
        }

        // 4. The shading normal, facing the ray (`shading_normal`).
        let flip = facing.dot(dir).gt(L::splat(0.0));
        let toward = L::select(flip, L::splat(-1.0), L::splat(1.0));
        let normal = if interpolated {
            // The §3.2 barycentrics `V_i / ΣV` (`barycentrics`).
            let q = [p0.sub(origin), p1.sub(origin), p2.sub(origin)];
            let v0 = q[1].cross(q[2]).dot(dir);
            let v1 = q[2].cross(q[0]).dot(dir);
            let v2 = q[0].cross(q[1]).dot(dir);
            let total = v0 + v1 + v2;
            done &= !total.eq(L::splat(0.0)) & finite(total);
            let n0 = normals[0].scale(v0 / total);
            let n1 = normals[1].scale(v1 / total);
            let n2 = normals[2].scale(v2 / total);
            let n = n0.add(n1).add(n2);
            let (n, ok) = n.normalized();
            done &= ok;
            n.scale(toward)
        } else {
            facing.scale(toward)
        };

        // 5. Lambert over the lights, or a headlight at the eye.
        let zero = L::splat(0.0);
        let mut lit = V3::splat(Vec3::ZERO);
        if self.light_terms.is_empty() {
            let (d, ok) = dir.normalized();
            done &= ok;
            let s = normal.dot(d.scale(L::splat(-1.0))).max(zero);
            lit = V3 { x: s, y: s, z: s };
        }
        for &(from, color) in &self.light_terms {
            let to_light = match from {
                LightFrom::Direction(toward) => V3::splat(toward),
                LightFrom::Position(position) => {
                    let (to, ok) = V3::splat(position).sub(point).normalized();
                    done &= ok;
                    to
                }
            };
            let lambert = normal.dot(to_light);
            // A lane whose term the scalar path skips (`lambert ≤ 0`) adds
            // `color · 0`, which leaves its sum as it is; a NaN goes scalar.
            done &= lambert.eq(lambert);
            lit = lit.add(V3::splat(color).scale(lambert.max(zero)));
        }
        let r = base.x * ambient(lit.x) + emissive.x;
        let g = base.y * ambient(lit.y) + emissive.y;
        let b = base.z * ambient(lit.z) + emissive.z;
        ([r, g, b], done)
    }
}

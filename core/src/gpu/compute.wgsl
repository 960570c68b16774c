// The continuum as compute shaders (paper §5 and its future work): setup
// kernels for 2D, homogeneous 2D and 3D edge functions, a bounding-box raster
// with one thread per triangle, and a sort-middle pipeline (bin → prefix sum →
// one workgroup per tile). The arithmetic follows the CPU code operation by
// operation (`edge/edge3d.rs`, `edge/homogeneous.rs`, `edge/edge2d.rs`): the
// same products in the same order, so results differ only where the driver
// fuses a multiply and an add. Where f32 cannot be sure, the CPU decides
// exactly (`edge/exact.rs`), as it does for its own algorithms: the 3D and
// homogeneous setups carry the CPU's certified bound on each edge's f32
// error (`Triangle3D::tolerance`), and a sample whose edge value lies within
// it is listed for the CPU (`defer`) instead of being decided; a triangle
// whose orientation (the determinant's f32 sign) is not certain is listed
// for the CPU's setup. Every other decision is the exact one already.
//
// A set-up triangle is a `Tri`: seven vec4s.
//   linear (3D, homogeneous): r0..r2 = (A_i | nd0), (B_i | nd1), (C_i | nd2),
//     r3 = (volume, w_min), r4 = (w_max, 0, 0, 0)
//   2D: r0..r2 = (lo_x, lo_y, Δx, Δy) per edge, r3 = (sign_0..2, q0),
//     r4 = (q1, q2, w_min, w_max)
//   r5 = (tolerance_0..2, 0): per edge the bound on its f32 error over the
//     image (0 in 2D records: their f32 decision is final);
//   r6 = (id, x0 | y0 << 16, x1 | y1 << 16, flags) as u32 bits,
//   flags: bits 0..2 own the tie on edge i, bit 3 a 2D record, bit 4 affine
//   depth (orthographic 2D). An empty box (x0 >= x1) is no triangle.

struct Tri {
    r: array<vec4<f32>, 7>,
}

struct Params {
    eye: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    forward: vec4<f32>,
    d0: vec4<f32>,
    dx: vec4<f32>,
    dy: vec4<f32>,
    o0: vec4<f32>,
    ox: vec4<f32>,
    oy: vec4<f32>,
    // half_x, half_y, near, guard band (in half-extents)
    lens: vec4<f32>,
    // the pattern's span: lo.x, lo.y, hi.x, hi.y
    span: vec4<f32>,
    // sample positions (x, y) in the pixel, two per vec4
    samples: array<vec4<f32>, 2>,
    // width, height, triangles (or records), stored samples
    size: vec4<u32>,
    // orthographic, pass (0: depth, 1: ids; the 32-bit fallback), tiles across, tiles down
    mode: vec4<u32>,
    // x: 1 with the depth test off (each sample keeps the smallest id),
    // y: the first big triangle of this dispatch, z: the list segment,
    // w: the capacity of `cpu_list` in (id, sample) pairs (raster passes)
    flags: vec4<u32>,
}

@group(0) @binding(0) var<uniform> P: Params;
// Per drawable triangle its id; per triangle its three vertex indices;
// per vertex three coordinates.
@group(0) @binding(1) var<storage, read> drawable: array<u32>;
@group(0) @binding(2) var<storage, read> corners: array<u32>;
@group(0) @binding(3) var<storage, read> positions: array<f32>;
@group(0) @binding(4) var<storage, read_write> tris: array<Tri>;
// [0] set-up triangles, [1] triangles left to the CPU's clipper,
// [2] tiles tested, [3] accepted, [4] rejected, [5] list entries,
// [6] big triangles, [7] the longest tile list, [8] the most chunks a big
// triangle's box spans, [9] samples left to the CPU's exact decision
@group(0) @binding(5) var<storage, read_write> counters: array<atomic<u32>>;
// What the CPU finishes. Setup passes: the ids of the triangles the 2D
// setup leaves to the CPU's clipper, or whose orientation the 3D and
// homogeneous setups cannot be sure of. Raster passes: (id, sample index)
// pairs whose edge decision f32 cannot be sure of.
@group(0) @binding(6) var<storage, read_write> cpu_list: array<u32>;
// Triangles whose box holds more than BIG_AREA pixels: rasterized (binned)
// by workgroups per CHUNK² pixels of their box, not by one thread. (Mesa's
// llvmpipe ends any invocation after 65,535 loop iterations in all, so no
// thread may loop over a large box or a long list.)
@group(0) @binding(7) var<storage, read_write> big_list: array<u32>;

const TILE: u32 = 8u;
const BIG_AREA: u32 = 4096u;
const CHUNK: u32 = 64u;
const EMPTY: u32 = 0xffffffffu;
const F32_EPS: f32 = 5.9604645e-8;

// ---- shared arithmetic (the CPU's operation order) -------------------------

fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

fn cross3(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}

fn along(n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot3(n, P.d0.xyz), dot3(n, P.dx.xyz), dot3(n, P.dy.xyz));
}

fn finite(v: f32) -> bool {
    // NaN fails both; ±∞ fails the bound.
    return abs(v) <= 3.4028235e38;
}

fn finite3(v: vec3<f32>) -> bool {
    return finite(v.x) && finite(v.y) && finite(v.z);
}

fn vertex(i: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

fn to_camera(p: vec3<f32>) -> vec3<f32> {
    let v = p - P.eye.xyz;
    return vec3<f32>(dot3(v, P.right.xyz), dot3(v, P.up.xyz), dot3(v, P.forward.xyz));
}

// Pixel coordinates of a camera-space point (`View::project`).
fn project(c: vec3<f32>) -> vec2<f32> {
    let half_w = f32(P.size.x) * 0.5;
    let half_h = f32(P.size.y) * 0.5;
    var p = c.xy;
    if P.mode.x == 0u {
        p = c.xy / c.z;
    }
    return vec2<f32>((p.x / P.lens.x + 1.0) * half_w, (1.0 - p.y / P.lens.y) * half_h);
}

// §3.4 tie rule: the edge owns a sample on it when it grows to the right, or
// (a horizontal edge) downwards.
fn owns_tie(de_dx: f32, de_dy: f32) -> bool {
    return de_dx > 0.0 || (de_dx == 0.0 && de_dy > 0.0);
}

fn inside_edge(e: f32, owns: bool) -> bool {
    return e > 0.0 || (e == 0.0 && owns);
}

// The pixels whose samples may lie in [lo, hi] (`PixelRect::from_bounds`),
// widened by `margin` pixels; packed as (x0 | y0 << 16, x1 | y1 << 16), or
// an empty box.
fn pixel_box(lo: vec2<f32>, hi: vec2<f32>, margin: f32) -> vec2<u32> {
    let w = f32(P.size.x);
    let h = f32(P.size.y);
    let x0 = max(ceil(lo.x - margin - P.span.z), 0.0);
    let y0 = max(ceil(lo.y - margin - P.span.w), 0.0);
    let x1 = min(floor(hi.x + margin - P.span.x), w - 1.0);
    let y1 = min(floor(hi.y + margin - P.span.y), h - 1.0);
    if !(x0 <= x1 && y0 <= y1) {
        return vec2<u32>(0u, 0u);
    }
    return vec2<u32>(u32(x0) | (u32(y0) << 16u), (u32(x1) + 1u) | ((u32(y1) + 1u) << 16u));
}

fn box_of(t: Tri) -> vec4<u32> {
    let a = bitcast<u32>(t.r[6].y);
    let b = bitcast<u32>(t.r[6].z);
    return vec4<u32>(a & 0xffffu, a >> 16u, b & 0xffffu, b >> 16u);
}

fn empty_tri() -> Tri {
    var t: Tri;
    t.r[6] = vec4<f32>(bitcast<f32>(EMPTY), 0.0, 0.0, 0.0);
    return t;
}

// |a| ⊗ |b| (`edge3d::abs_cross`): per component the magnitudes of the two
// products a cross-product component subtracts, which bound its rounding.
fn abs_cross(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    let p = abs(a);
    let q = abs(b);
    return vec3<f32>(p.y * q.z + p.z * q.y, p.z * q.x + p.x * q.z, p.x * q.y + p.y * q.x);
}

// The image's largest sample coordinates (`View::sample_extent`).
fn extent() -> vec2<f32> {
    return vec2<f32>(f32(P.size.x) + 1.0, f32(P.size.y) + 1.0);
}

// `|d(x, y)|` per component, the sample direction at image point (x, y).
fn direction_size(x: f32, y: f32) -> vec3<f32> {
    return abs(P.d0.xyz + P.dx.xyz * x + P.dy.xyz * y);
}

// `BOUND_MARGIN` of `edge3d.rs`: the first-order error bounds are taken
// with it (their O(ε²) terms and their own rounding).
const BOUND_MARGIN: f32 = 1.0009765625;

// Is the f32 determinant `d` (error at most `bound`) of certain sign? If
// not, the triangle `id` is listed for the CPU, whose setup takes the exact
// sign (`edge3d::orientation`), and this returns false.
fn oriented(id: u32, d: f32, bound: f32) -> bool {
    if abs(d) > bound {
        return true;
    }
    if finite(d) && finite(bound) {
        cpu_list[atomicAdd(&counters[1], 1u)] = id;
    }
    return false;
}

// A 3D or homogeneous triangle from its linear edge functions (rows: A, B, C
// per edge), `nd` and `volume`, and each edge's coefficient error over the
// image (`Triangle3D::from_linear`, which adds the evaluation's rounding:
// (A + x·B) + y·C is within 3ε of the terms' magnitudes; both bounds taken
// with BOUND_MARGIN).
fn linear_tri(id: u32, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, nd: vec3<f32>, volume: vec3<f32>, w: vec3<f32>, coefficient_error: vec3<f32>, pbox: vec2<u32>) -> Tri {
    var t: Tri;
    let x = extent();
    let tolerance = BOUND_MARGIN * (coefficient_error + 3.0 * F32_EPS * (abs(a) + x.x * abs(b) + x.y * abs(c)));
    if !(finite3(a) && finite3(b) && finite3(c) && finite3(nd) && finite3(volume) && finite3(w) && finite3(tolerance)) || pbox.x == pbox.y {
        return empty_tri();
    }
    t.r[5] = vec4<f32>(tolerance, 0.0);
    t.r[0] = vec4<f32>(a, nd.x);
    t.r[1] = vec4<f32>(b, nd.y);
    t.r[2] = vec4<f32>(c, nd.z);
    t.r[3] = vec4<f32>(volume, min(min(w.x, w.y), w.z));
    t.r[4] = vec4<f32>(max(max(w.x, w.y), w.z), 0.0, 0.0, 0.0);
    var flags = 0u;
    for (var i = 0u; i < 3u; i++) {
        if owns_tie(b[i], c[i]) {
            flags |= 1u << i;
        }
    }
    t.r[6] = vec4<f32>(bitcast<f32>(id), bitcast<f32>(pbox.x), bitcast<f32>(pbox.y), bitcast<f32>(flags));
    return t;
}

// The screen box of a triangle given in camera space, clipped to w >= near
// (3D edge functions need no clipping; the box only bounds the search), with
// a margin for the f32 projection.
fn camera_box(c: array<vec3<f32>, 3>) -> vec2<u32> {
    let near = P.lens.z;
    var lo = vec2<f32>(3.0e38);
    var hi = vec2<f32>(-3.0e38);
    var any = false;
    for (var i = 0u; i < 3u; i++) {
        let a = c[i];
        let b = c[(i + 1u) % 3u];
        if a.z >= near || P.mode.x == 1u {
            let p = project(a);
            lo = min(lo, p);
            hi = max(hi, p);
            any = true;
        }
        if P.mode.x == 0u && (a.z >= near) != (b.z >= near) {
            let t = (near - a.z) / (b.z - a.z);
            let q = vec3<f32>(a.xy + (b.xy - a.xy) * t, near);
            let p = project(q);
            lo = min(lo, p);
            hi = max(hi, p);
        }
    }
    if !any || !(finite(lo.x) && finite(lo.y) && finite(hi.x) && finite(hi.y)) {
        if any && P.mode.x == 0u {
            // Overflowing projections: the whole image.
            return pixel_box(vec2<f32>(0.0), vec2<f32>(f32(P.size.x), f32(P.size.y)), 1.0);
        }
        return vec2<u32>(0u, 0u);
    }
    // f32 projections are within a few ulps; edge decisions near the box's
    // border within ~1e-4 pixel of the true edge.
    let margin = 1e-3 + 1e-6 * max(max(abs(lo.x), abs(lo.y)), max(abs(hi.x), abs(hi.y)));
    return pixel_box(lo, hi, margin);
}

// Vertices beyond 2³² make the setup's products overflow: scaled by a power
// of two so that the largest coordinate is about 1 (`edge3d::scaled`;
// exact, no sign changes). Returns the factor that undoes it.
fn scale_down(c: ptr<function, array<vec3<f32>, 3>>) -> f32 {
    let m = max(max(max_abs((*c)[0]), max_abs((*c)[1])), max_abs((*c)[2]));
    if !(m > 4294967296.0 && finite(m)) {
        return 1.0;
    }
    let k = i32(ceil(log2(m)));
    for (var i = 0u; i < 3u; i++) {
        (*c)[i] = ldexp((*c)[i], vec3<i32>(-k));
    }
    return ldexp(1.0, k);
}

fn max_abs(v: vec3<f32>) -> f32 {
    let a = abs(v);
    return max(max(a.x, a.y), a.z);
}

fn thread_index(wg: vec3<u32>, groups: vec3<u32>, local: u32) -> u32 {
    return (wg.y * groups.x + wg.x) * 64u + local;
}

// ---- setup kernels: one thread per drawable triangle -----------------------

struct Loaded {
    id: u32,
    p: array<vec3<f32>, 3>,
}

fn load(k: u32) -> Loaded {
    var l: Loaded;
    l.id = drawable[k];
    for (var i = 0u; i < 3u; i++) {
        l.p[i] = vertex(corners[3u * l.id + i]);
    }
    return l;
}

fn set_up(k: u32, t: Tri) {
    tris[k] = t;
    if bitcast<u32>(t.r[6].x) != EMPTY {
        atomicAdd(&counters[0], 1u);
        let b = box_of(t);
        if is_big(b) {
            big_list[atomicAdd(&counters[6], 1u)] = k;
            atomicMax(&counters[8], box_chunks(b));
        }
    }
}

fn is_big(b: vec4<u32>) -> bool {
    return (b.z - b.x) * (b.w - b.y) > BIG_AREA;
}

// The big triangle of workgroup row `wg_y` (`None`: EMPTY past the list).
fn big_triangle(wg_y: u32) -> u32 {
    let i = P.flags.y + wg_y;
    if i >= P.size.z {
        return EMPTY;
    }
    return big_list[i];
}

// The chunks of CHUNK² pixels (anchored at the box's corner) or of 8×8
// tiles (anchored at its first tile) the box `b` spans, whichever is more.
fn box_chunks(b: vec4<u32>) -> u32 {
    let pixels = ((b.z - b.x + CHUNK - 1u) / CHUNK) * ((b.w - b.y + CHUNK - 1u) / CHUNK);
    let tx = (b.z - 1u) / TILE - b.x / TILE + 1u;
    let ty = (b.w - 1u) / TILE - b.y / TILE + 1u;
    return max(pixels, ((tx + 7u) / 8u) * ((ty + 7u) / 8u));
}

// The pixels [x0, x1) × [y0, y1) a thread of an 8×8 workgroup takes in
// chunk `chunk` of box `b` (CHUNK² pixels from the box's corner, row-major):
// an 8×8-pixel block.
fn chunk_block(b: vec4<u32>, chunk: u32, lid: vec2<u32>) -> vec4<u32> {
    let across = (b.z - b.x + CHUNK - 1u) / CHUNK;
    let x0 = b.x + (chunk % across) * CHUNK + lid.x * 8u;
    let y0 = b.y + (chunk / across) * CHUNK + lid.y * 8u;
    return vec4<u32>(x0, y0, x0 + 8u, y0 + 8u);
}

// The tile a thread of an 8×8 workgroup takes in chunk `chunk` of box `b`
// (8×8 tiles from the box's first tile, row-major).
fn chunk_tile(b: vec4<u32>, chunk: u32, lid: vec2<u32>) -> vec2<u32> {
    let across = ((b.z - 1u) / TILE - b.x / TILE + 8u) / 8u;
    return vec2<u32>(
        b.x / TILE + (chunk % across) * 8u + lid.x,
        b.y / TILE + (chunk / across) * 8u + lid.y,
    );
}

// Paper §3.2 (perspective) and §3.3 (orthographic): `Triangle3D::setup`.
@compute @workgroup_size(64)
fn setup_3d(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = thread_index(wg, groups, local);
    if k >= P.size.z {
        return;
    }
    let l = load(k);
    var c: array<vec3<f32>, 3>;
    var cam: array<vec3<f32>, 3>;
    for (var i = 0u; i < 3u; i++) {
        c[i] = l.p[i] - P.eye.xyz;
        cam[i] = to_camera(l.p[i]);
    }
    let w = vec3<f32>(dot3(c[0], P.forward.xyz), dot3(c[1], P.forward.xyz), dot3(c[2], P.forward.xyz));
    let pbox = camera_box(cam);
    let scale = scale_down(&c);
    let down = 1.0 / scale;
    let e1 = c[1] - c[0];
    let e2 = c[2] - c[0];
    let normal = cross3(e1, e2);
    var a: vec3<f32>;
    var b: vec3<f32>;
    var cc: vec3<f32>;
    var error: vec3<f32>;
    let x = extent();
    if P.mode.x == 0u {
        let d = dot3(normal, c[0]);
        if !oriented(l.id, d, 16.0 * F32_EPS * dot3(abs_cross(e1, e2), abs(c[0]))) {
            set_up(k, empty_tri());
            return;
        }
        let s = select(-1.0, 1.0, d > 0.0);
        // Each edge's normal is within 4ε of |m| ⊗ |u|, which moves its value
        // by at most that along the largest |d|; its three coefficients round
        // by 3ε of |n| along `reach` (`perspective_edge` of edge3d.rs).
        let largest = max(max(direction_size(-1.0, -1.0), direction_size(x.x, -1.0)),
                          max(direction_size(-1.0, x.y), direction_size(x.x, x.y)));
        let reach = abs(P.d0.xyz) + abs(P.dx.xyz) * x.x + abs(P.dy.xyz) * x.y;
        for (var i = 0u; i < 3u; i++) {
            let p = c[(i + 1u) % 3u];
            let q = c[(i + 2u) % 3u];
            let n = cross3(-(p + q) * 0.5, p - q);
            let e = along(n * s);
            a[i] = e.x;
            b[i] = e.y;
            cc[i] = e.z;
            error[i] = 4.0 * F32_EPS * dot3(abs_cross((p + q) * 0.5, p - q), largest)
                + 3.0 * F32_EPS * dot3(abs(n), reach);
        }
        set_up(k, linear_tri(l.id, a, b, cc, along(normal * s), vec3<f32>(abs(d) * scale, 0.0, 0.0), w, error, pbox));
    } else {
        let dp = P.forward.xyz;
        let facing = dot3(normal, dp);
        if !oriented(l.id, facing, 16.0 * F32_EPS * dot3(abs_cross(e1, e2), abs(dp))) {
            set_up(k, empty_tri());
            return;
        }
        let s = select(-1.0, 1.0, facing > 0.0);
        let o_abs = abs(P.o0.xyz * down) + abs(P.ox.xyz * down) * x.x + abs(P.oy.xyz * down) * x.y;
        for (var i = 0u; i < 3u; i++) {
            let p = c[(i + 1u) % 3u];
            let q = c[(i + 2u) % 3u];
            let m = (p + q) * 0.5;
            let n = cross3(dp, p - q) * s;
            a[i] = dot3(n, m - P.o0.xyz * down);
            b[i] = -dot3(n, P.ox.xyz * down);
            cc[i] = -dot3(n, P.oy.xyz * down);
            error[i] = 8.0 * F32_EPS * dot3(abs_cross(dp, p - q), abs(m) + o_abs);
        }
        let ns = normal * s;
        let volume = vec3<f32>(dot3(ns, c[0] - P.o0.xyz * down), -dot3(ns, P.ox.xyz * down), -dot3(ns, P.oy.xyz * down)) * scale;
        set_up(k, linear_tri(l.id, a, b, cc, vec3<f32>(abs(facing), 0.0, 0.0), volume, w, error, pbox));
    }
}

// Olano–Greer (paper Fig. 10, middle): `setup_homogeneous_from`.
@compute @workgroup_size(64)
fn setup_homogeneous(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = thread_index(wg, groups, local);
    if k >= P.size.z {
        return;
    }
    let l = load(k);
    let half_w = f32(P.size.x) * 0.5;
    let half_h = f32(P.size.y) * 0.5;
    var h: array<vec3<f32>, 3>;
    var cam: array<vec3<f32>, 3>;
    var w: vec3<f32>;
    for (var i = 0u; i < 3u; i++) {
        let c = to_camera(l.p[i]);
        cam[i] = c;
        let hw = select(c.z, 1.0, P.mode.x == 1u);
        h[i] = vec3<f32>((c.x / P.lens.x + hw) * half_w, (hw - c.y / P.lens.y) * half_h, hw);
        w[i] = c.z;
    }
    let pbox = camera_box(cam);
    let scale = scale_down(&h);
    var rows: array<vec3<f32>, 3>;
    for (var i = 0u; i < 3u; i++) {
        let p = h[(i + 1u) % 3u];
        let q = h[(i + 2u) % 3u];
        rows[i] = cross3((p + q) * 0.5, q - p);
    }
    let e1 = h[1] - h[0];
    let e2 = h[2] - h[0];
    let normal = cross3(e1, e2);
    let det = dot3(normal, h[0]);
    if !oriented(l.id, det, 16.0 * F32_EPS * dot3(abs_cross(e1, e2), abs(h[0]))) {
        set_up(k, empty_tri());
        return;
    }
    let s = select(-1.0, 1.0, det > 0.0);
    var a: vec3<f32>;
    var b: vec3<f32>;
    var c: vec3<f32>;
    for (var i = 0u; i < 3u; i++) {
        a[i] = rows[i].z * s;
        b[i] = rows[i].x * s;
        c[i] = rows[i].y * s;
    }
    let nd = vec3<f32>(normal.z * s, normal.x * s, normal.y * s);
    var volume = vec3<f32>(abs(det) * scale, 0.0, 0.0);
    if P.mode.x == 1u {
        let r = rows[0] * w[0] + rows[1] * w[1] + rows[2] * w[2];
        volume = vec3<f32>(r.z * s, r.x * s, r.y * s);
    }
    // Each row's coefficients are within 6ε of |m| ⊗ |u| at (x, y, 1).
    let x = extent();
    var error: vec3<f32>;
    for (var i = 0u; i < 3u; i++) {
        let p = h[(i + 1u) % 3u];
        let q = h[(i + 2u) % 3u];
        let t = abs_cross((p + q) * 0.5, q - p);
        error[i] = 6.0 * F32_EPS * (t.z + x.x * t.x + x.y * t.y);
    }
    set_up(k, linear_tri(l.id, a, b, c, nd, volume, w, error, pbox));
}

// Paper §3.1: project and set up 2D edge functions (`Triangle2D::setup`).
// Triangles that cross the near plane or the guard band are not clipped
// here: they are listed for the CPU, which clips them in f64 exactly as
// `2dr-brute` does and adds their pieces as further records.
@compute @workgroup_size(64)
fn setup_2d(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = thread_index(wg, groups, local);
    if k >= P.size.z {
        return;
    }
    let l = load(k);
    var v: array<vec3<f32>, 3>;
    var clip = false;
    let gx = P.lens.w * P.lens.x;
    let gy = P.lens.w * P.lens.y;
    for (var i = 0u; i < 3u; i++) {
        let c = to_camera(l.p[i]);
        let scale = select(c.z, 1.0, P.mode.x == 1u);
        if c.z < P.lens.z || abs(c.x) > gx * scale || abs(c.y) > gy * scale || !finite3(c) {
            clip = true;
        }
        let xy = project(c);
        v[i] = vec3<f32>(xy, select(1.0 / c.z, c.z, P.mode.x == 1u));
    }
    if clip {
        cpu_list[atomicAdd(&counters[1], 1u)] = l.id;
        tris[k] = empty_tri();
        return;
    }
    set_up(k, tri_2d(l.id, v));
}

fn raw_2d(lo: vec2<f32>, delta: vec2<f32>, x: f32, y: f32) -> f32 {
    return delta.x * (y - lo.y) - delta.y * (x - lo.x);
}

fn tri_2d(id: u32, v: array<vec3<f32>, 3>) -> Tri {
    let affine = P.mode.x == 1u;
    var w: vec3<f32>;
    for (var i = 0u; i < 3u; i++) {
        w[i] = select(1.0 / v[i].z, v[i].z, affine);
    }
    if !finite3(w) {
        return empty_tri();
    }
    var t: Tri;
    var lo: array<vec2<f32>, 3>;
    var delta: array<vec2<f32>, 3>;
    var sign: vec3<f32>;
    for (var i = 0u; i < 3u; i++) {
        let a = v[(i + 1u) % 3u].xy;
        let b = v[(i + 2u) % 3u].xy;
        if a.x < b.x || (a.x == b.x && a.y <= b.y) {
            lo[i] = a;
            delta[i] = b - a;
            sign[i] = 1.0;
        } else {
            lo[i] = b;
            delta[i] = a - b;
            sign[i] = -1.0;
        }
    }
    let orientation = raw_2d(lo[0], delta[0], v[0].x, v[0].y) * sign[0];
    if !(orientation != 0.0 && finite(orientation)) {
        return empty_tri();
    }
    let orient = select(-1.0, 1.0, orientation > 0.0);
    var flags = 8u;
    if affine {
        flags |= 16u;
    }
    for (var i = 0u; i < 3u; i++) {
        sign[i] *= orient;
        let inside = raw_2d(lo[i], delta[i], v[i].x, v[i].y) * sign[i];
        if !(inside > 0.0) {
            return empty_tri();
        }
        if owns_tie(-delta[i].y * sign[i], delta[i].x * sign[i]) {
            flags |= 1u << i;
        }
        t.r[i] = vec4<f32>(lo[i], delta[i]);
    }
    let lo_xy = min(min(v[0].xy, v[1].xy), v[2].xy);
    let hi_xy = max(max(v[0].xy, v[1].xy), v[2].xy);
    let pbox = pixel_box(lo_xy, hi_xy, 0.0);
    if pbox.x == pbox.y {
        return empty_tri();
    }
    t.r[3] = vec4<f32>(sign, v[0].z);
    t.r[4] = vec4<f32>(v[1].z, v[2].z, min(min(w.x, w.y), w.z), max(max(w.x, w.y), w.z));
    t.r[6] = vec4<f32>(bitcast<f32>(id), bitcast<f32>(pbox.x), bitcast<f32>(pbox.y), bitcast<f32>(flags));
    return t;
}

// ---- coverage and depth of one sample --------------------------------------

// The three signed edge values at (x, y).
fn edges(t: Tri, x: f32, y: f32) -> vec3<f32> {
    let flags = bitcast<u32>(t.r[6].w);
    if (flags & 8u) != 0u {
        return vec3<f32>(
            raw_2d(t.r[0].xy, t.r[0].zw, x, y) * t.r[3].x,
            raw_2d(t.r[1].xy, t.r[1].zw, x, y) * t.r[3].y,
            raw_2d(t.r[2].xy, t.r[2].zw, x, y) * t.r[3].z,
        );
    }
    return vec3<f32>(
        t.r[0].x + x * t.r[1].x + y * t.r[2].x,
        t.r[0].y + x * t.r[1].y + y * t.r[2].y,
        t.r[0].z + x * t.r[1].z + y * t.r[2].z,
    );
}

const OUTSIDE: u32 = 0u;
const INSIDE: u32 = 1u;
const UNSURE: u32 = 2u;

// Edge value `e` against its f32 error bound `tolerance`: certainly inside
// or outside beyond it, unsure within it (the CPU decides exactly); with no
// bound (2D) the f32 sign and the tie rule decide.
fn edge_side(e: f32, tolerance: f32, owns: bool) -> u32 {
    if e > tolerance {
        return INSIDE;
    }
    if e < -tolerance {
        return OUTSIDE;
    }
    if tolerance > 0.0 {
        return UNSURE;
    }
    return select(OUTSIDE, INSIDE, inside_edge(e, owns));
}

// Whether a sample with edge values `e` is inside `t` (all three edges),
// outside (some edge), or unsure (no edge outside, some unsure).
fn covers(t: Tri, e: vec3<f32>) -> u32 {
    let flags = bitcast<u32>(t.r[6].w);
    let sides = vec3<u32>(
        edge_side(e.x, t.r[5].x, (flags & 1u) != 0u),
        edge_side(e.y, t.r[5].y, (flags & 2u) != 0u),
        edge_side(e.z, t.r[5].z, (flags & 4u) != 0u),
    );
    if any(sides == vec3<u32>(OUTSIDE)) {
        return OUTSIDE;
    }
    return max(max(sides.x, sides.y), sides.z);
}

// Leaves sample `i` (layer-major index) of triangle `id` to the CPU's
// exact decision (`ComputeSamples::unsure`). Past the list's capacity only
// the count grows, and the host renders again with room for all.
fn defer(id: u32, i: u32) {
    let slot = atomicAdd(&counters[9], 1u);
    if slot < P.flags.w {
        cpu_list[2u * slot] = id;
        cpu_list[2u * slot + 1u] = i;
    }
}

// The sample's w (view-axis distance), or a negative value for none: 2D by
// perspective-correct interpolation (§3.1), 3D as |D| / (N·d) (Fig. 10);
// clamped to the vertices' range, rejected nearer than `near`.
fn depth(t: Tri, e: vec3<f32>, x: f32, y: f32) -> f32 {
    let flags = bitcast<u32>(t.r[6].w);
    if (flags & 8u) != 0u {
        let sum = e.x + e.y + e.z;
        let q = e.x * t.r[3].w + e.y * t.r[4].x + e.z * t.r[4].y;
        var w = sum / q;
        if (flags & 16u) != 0u {
            w = q / sum;
        }
        if !(w > 0.0 && w <= 3.4028235e38) {
            return -1.0;
        }
        return min(max(w, t.r[4].z), t.r[4].w);
    }
    let facing = t.r[0].w + x * t.r[1].w + y * t.r[2].w;
    if facing <= 0.0 {
        return -1.0;
    }
    let volume = t.r[3].x + x * t.r[3].y + y * t.r[3].z;
    let w = min(max(volume / facing, t.r[3].w), t.r[4].x);
    if !(w >= P.lens.z) {
        return -1.0;
    }
    return w;
}

fn sample_position(s: u32) -> vec2<f32> {
    let v = P.samples[s / 2u];
    return select(v.zw, v.xy, s % 2u == 0u);
}

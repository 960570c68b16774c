// `gpu-2dr`, `gpu-2dr-homogeneous`, `gpu-3dr`: one thread per set-up triangle
// tests every sample of its bounding box (paper §5: a setup kernel, then edge
// functions per pixel), counting the tests per pixel and the covered samples
// per sample; visibility by `store` (visibility64.wgsl or visibility32.wgsl).
// Triangles with large boxes are split over workgroups (`raster_big`).
// Bindings 0..7 are compute.wgsl's.

@group(0) @binding(8) var<storage, read_write> edge_evals: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read_write> coverage_writes: array<atomic<u32>>;

// Tests the pixel's samples against `t` (triangle `id`).
fn raster_pixel(t: Tri, id: u32, x: u32, y: u32) {
    let pixels = P.size.x * P.size.y;
    let pixel = y * P.size.x + x;
    let stored = P.size.w;
    let counting = P.mode.y == 0u;
    for (var s = 0u; s < stored; s++) {
        let o = sample_position(s);
        let sx = f32(x) + o.x;
        let sy = f32(y) + o.y;
        let e = edges(t, sx, sy);
        let side = covers(t, e);
        let i = s * pixels + pixel;
        if side != INSIDE {
            if side == UNSURE && counting {
                defer(id, i);
            }
            continue;
        }
        let w = depth(t, e, sx, sy);
        if w < 0.0 {
            continue;
        }
        if counting {
            atomicAdd(&coverage_writes[i], 1u);
        }
        store(i, w, id);
    }
    if counting {
        atomicAdd(&edge_evals[pixel], stored);
    }
}

// Every pixel of `t`'s box within `r` ([x0, x1) × [y0, y1)).
fn raster_rect(t: Tri, r: vec4<u32>) {
    let id = bitcast<u32>(t.r[6].x);
    let b = box_of(t);
    let lo = max(b.xy, r.xy);
    let hi = min(b.zw, r.zw);
    for (var y = lo.y; y < hi.y; y++) {
        for (var x = lo.x; x < hi.x; x++) {
            raster_pixel(t, id, x, y);
        }
    }
}

@compute @workgroup_size(64)
fn raster_brute(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = thread_index(wg, groups, local);
    if k >= P.size.z {
        return;
    }
    let t = tris[k];
    if bitcast<u32>(t.r[6].x) == EMPTY || is_big(box_of(t)) {
        return;
    }
    raster_rect(t, box_of(t));
}

// A big triangle's box, one workgroup per CHUNK² pixels of it and big
// triangle, one thread per 8×8 pixels.
@compute @workgroup_size(8, 8)
fn raster_big(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let k = big_triangle(wg.y);
    if k == EMPTY {
        return;
    }
    let t = tris[k];
    raster_rect(t, chunk_block(box_of(t), wg.x, lid.xy));
}

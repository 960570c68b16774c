// `gpu-3dr-binned`: the sort-middle pipeline the paper's conclusion asks for
// (Laine and Karras's bin → coarse → fine, with 3D edge functions). After the
// 3D setup, every triangle's box is cut into 64×64-pixel blocks and those
// into 8×8-pixel tiles, hierarchically as `3dr-bin` refines its blocks: a
// block is tested against the three edges at its corners (rejected, accepted
// whole, or partly covered), the tiles of a partly covered one likewise,
// and only a partly covered tile's samples are tested one by one; a pass
// counts each tile's triangles, one workgroup turns the counts into offsets
// (an exclusive prefix sum), a pass writes the lists, and one workgroup per
// tile rasterizes its list with one thread per pixel, depth and id kept in
// registers and written once. Big triangles are binned by workgroups of
// 8×8 tiles (`bin_big`), and long lists rasterized in segments, so that no
// thread loops long. Bindings 0..7 are compute.wgsl's.

@group(0) @binding(8) var<storage, read_write> tile_counts: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read_write> tile_offsets: array<u32>;
@group(0) @binding(10) var<storage, read_write> tile_cursor: array<atomic<u32>>;
@group(0) @binding(11) var<storage, read_write> tile_list: array<u32>;
@group(0) @binding(12) var<storage, read_write> out_depth: array<u32>;
@group(0) @binding(13) var<storage, read_write> out_ids: array<u32>;
@group(0) @binding(14) var<storage, read_write> out_writes: array<u32>;
@group(0) @binding(15) var<storage, read_write> out_evals: array<u32>;

const REJECT: u32 = 0u;
const PARTIAL: u32 = 1u;
const ACCEPT: u32 = 2u;
// A tile of a block accepted whole: accepted without a test of its own.
const UNTESTED: u32 = 3u;
const ACCEPTED_BIT: u32 = 0x80000000u;

// Tiles per side of a block (64×64 pixels: the first level of the tests).
const BLOCK: u32 = 8u;

// Where the tiles [t0, t1] (inclusive, in tiles) stand against triangle t:
// their samples' box tested at the corners where each edge is largest and
// smallest (the edge functions are linear in the image point), with a
// margin of 2⁻²⁰ of the terms' magnitudes for the f32 rounding of a corner
// against a sample, beyond the edge's own tolerance: tiles are rejected or
// accepted only where every sample's decision is certain (the exact one).
fn tiles_test(t: Tri, t0: vec2<u32>, t1: vec2<u32>) -> u32 {
    let x0 = f32(t0.x * TILE) + P.span.x;
    let y0 = f32(t0.y * TILE) + P.span.y;
    let x1 = f32(min((t1.x + 1u) * TILE, P.size.x) - 1u) + P.span.z;
    let y1 = f32(min((t1.y + 1u) * TILE, P.size.y) - 1u) + P.span.w;
    var inside = true;
    for (var i = 0u; i < 3u; i++) {
        let a = t.r[0][i];
        let b = t.r[1][i];
        let c = t.r[2][i];
        let hi = a + select(x0, x1, b > 0.0) * b + select(y0, y1, c > 0.0) * c;
        let lo = a + select(x1, x0, b > 0.0) * b + select(y1, y0, c > 0.0) * c;
        let margin = 9.5367432e-7 * (abs(a) + x1 * abs(b) + y1 * abs(c)) + t.r[5][i];
        if hi < -margin {
            return REJECT;
        }
        if !(lo > margin) {
            inside = false;
        }
    }
    return select(PARTIAL, ACCEPT, inside);
}

// Tile (tx, ty) against triangle k, in a block whose test said `block`:
// tested unless the block was accepted whole; then pass 0 counts it in the
// tile's list, pass 1 writes it there. Returns the tile's outcome, or
// UNTESTED for a tile of an accepted block.
fn bin_tile(t: Tri, k: u32, tx: u32, ty: u32, block: u32) -> u32 {
    var outcome = UNTESTED;
    if block != ACCEPT {
        outcome = tiles_test(t, vec2<u32>(tx, ty), vec2<u32>(tx, ty));
        if outcome == REJECT {
            return outcome;
        }
    }
    let tile = ty * P.mode.z + tx;
    if P.mode.y == 0u {
        atomicAdd(&tile_counts[tile], 1u);
    } else {
        let slot = tile_offsets[tile] + atomicAdd(&tile_cursor[tile], 1u);
        tile_list[slot] = k | select(0u, ACCEPTED_BIT, outcome == ACCEPT || outcome == UNTESTED);
    }
    return outcome;
}

// The block and tile tests' totals (pass 0 only).
fn count_tests(tests: Tests) {
    if P.mode.y == 0u && tests.tested > 0u {
        atomicAdd(&counters[2], tests.tested);
        atomicAdd(&counters[3], tests.accepted);
        atomicAdd(&counters[4], tests.rejected);
    }
}

// Pass 0 counts each tile's triangles (and the tile tests); pass 1 writes
// the lists at the offsets the prefix sum made. One thread per triangle
// whose box is small; `bin_big` takes the others.
@compute @workgroup_size(64)
fn bin(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = thread_index(wg, groups, local);
    if k >= P.size.z {
        return;
    }
    let t = tris[k];
    let b = box_of(t);
    if bitcast<u32>(t.r[6].x) == EMPTY || is_big(b) {
        return;
    }
    var tests = Tests(0u, 0u, 0u);
    let first = vec2<u32>(b.x, b.y) / TILE;
    let last = (vec2<u32>(b.z, b.w) - 1u) / TILE;
    for (var by = first.y / BLOCK; by <= last.y / BLOCK; by++) {
        for (var bx = first.x / BLOCK; bx <= last.x / BLOCK; bx++) {
            let t0 = max(vec2<u32>(bx, by) * BLOCK, first);
            let t1 = min(vec2<u32>(bx, by) * BLOCK + BLOCK - 1u, last);
            let block = block_test(t, t0, t1, &tests);
            if block == REJECT {
                continue;
            }
            for (var ty = t0.y; ty <= t1.y; ty++) {
                for (var tx = t0.x; tx <= t1.x; tx++) {
                    count(&tests, bin_tile(t, k, tx, ty, block));
                }
            }
        }
    }
    count_tests(tests);
}

// Tests made: tested, accepted whole, rejected.
struct Tests {
    tested: u32,
    accepted: u32,
    rejected: u32,
}

// Counts an outcome of a test (not the untested tiles of an accepted block).
fn count(tests: ptr<function, Tests>, outcome: u32) {
    if outcome != UNTESTED {
        (*tests).tested += 1u;
        (*tests).accepted += u32(outcome == ACCEPT);
        (*tests).rejected += u32(outcome == REJECT);
    }
}

// The first level: the block of tiles [t0, t1] tested whole when it holds
// at least 4×4 of them (a test that decides then saves 16 or more; the
// few tiles of a small triangle's box are tested one by one). Counted in
// `tests`.
fn block_test(t: Tri, t0: vec2<u32>, t1: vec2<u32>, tests: ptr<function, Tests>) -> u32 {
    let n = t1 - t0 + 1u;
    if n.x * n.y < 16u {
        return PARTIAL;
    }
    let outcome = tiles_test(t, t0, t1);
    count(tests, outcome);
    return outcome;
}

// A big triangle's tiles: one workgroup per block of 8×8 tiles of its box
// and big triangle, one thread per tile; each thread makes the block's test
// (the first thread counts it), then its tile's unless the block decided.
@compute @workgroup_size(8, 8)
fn bin_big(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let k = big_triangle(wg.y);
    if k == EMPTY {
        return;
    }
    let t = tris[k];
    let b = box_of(t);
    let last = (vec2<u32>(b.z, b.w) - 1u) / TILE;
    let t0 = chunk_tile(b, wg.x, vec2<u32>(0u));
    if t0.x > last.x || t0.y > last.y {
        return;
    }
    var tests = Tests(0u, 0u, 0u);
    let block = block_test(t, t0, min(t0 + BLOCK - 1u, last), &tests);
    if any(lid.xy != vec2<u32>(0u)) {
        tests = Tests(0u, 0u, 0u);
    }
    let tile = chunk_tile(b, wg.x, lid.xy);
    if block != REJECT && tile.x <= last.x && tile.y <= last.y {
        count(&tests, bin_tile(t, k, tile.x, tile.y, block));
    }
    count_tests(tests);
}

var<workgroup> partial: array<u32, 256>;

// The exclusive prefix sum of the tile counts, in one workgroup: each thread
// sums a run of tiles, the 256 sums are scanned (Hillis–Steele), then each
// thread writes its run's offsets; the total follows the last tile.
@compute @workgroup_size(256)
fn scan(@builtin(local_invocation_index) l: u32) {
    let n = P.mode.z * P.mode.w;
    let run = (n + 255u) / 256u;
    let start = min(l * run, n);
    let end = min(start + run, n);
    var sum = 0u;
    var longest = 0u;
    for (var i = start; i < end; i++) {
        let c = atomicLoad(&tile_counts[i]);
        sum += c;
        longest = max(longest, c);
    }
    atomicMax(&counters[7], longest);
    partial[l] = sum;
    workgroupBarrier();
    for (var d = 1u; d < 256u; d *= 2u) {
        var v = 0u;
        if l >= d {
            v = partial[l - d];
        }
        workgroupBarrier();
        partial[l] += v;
        workgroupBarrier();
    }
    var offset = partial[l] - sum;
    for (var i = start; i < end; i++) {
        tile_offsets[i] = offset;
        offset += atomicLoad(&tile_counts[i]);
    }
    if l == 255u {
        tile_offsets[n] = partial[255];
        atomicStore(&counters[5], partial[255]);
    }
}


// One sample's nearest triangle so far, and its coverage writes.
struct Best {
    w: f32,
    id: u32,
    writes: u32,
}

// Tests sample `s` of pixel (x, y) against `t` and keeps the nearer of it
// and `best` (an exact depth tie to the smaller id).
fn test_sample(best: ptr<function, Best>, t: Tri, accepted: bool, s: u32, x: u32, y: u32) {
    let o = sample_position(s);
    let sx = f32(x) + o.x;
    let sy = f32(y) + o.y;
    let e = edges(t, sx, sy);
    let id = bitcast<u32>(t.r[6].x);
    if !accepted {
        let side = covers(t, e);
        if side == UNSURE {
            defer(id, s * P.size.x * P.size.y + y * P.size.x + x);
        }
        if side != INSIDE {
            return;
        }
    }
    let w = depth(t, e, sx, sy);
    if w < 0.0 {
        return;
    }
    (*best).writes += 1u;
    let nearer = select(w < (*best).w || (w == (*best).w && id < (*best).id), id < (*best).id, P.flags.x == 1u);
    if (*best).id == EMPTY || nearer {
        (*best).w = w;
        (*best).id = id;
    }
}

// Entries of a tile's list one dispatch of `raster_binned` takes.
const SEGMENT: u32 = 16384u;

fn read_sample(s: u32, pixel: u32) -> Best {
    if s >= P.size.w {
        return Best(0.0, EMPTY, 0u);
    }
    let i = s * P.size.x * P.size.y + pixel;
    return Best(bitcast<f32>(out_depth[i]), out_ids[i], out_writes[i]);
}

fn write_sample(b: Best, s: u32, pixel: u32) {
    let i = s * P.size.x * P.size.y + pixel;
    out_depth[i] = bitcast<u32>(b.w);
    out_ids[i] = b.id;
    out_writes[i] = b.writes;
}

// One workgroup per tile, one thread per pixel: every thread walks the
// tile's list, tests its pixel against each triangle's box, then its
// samples against the triangle (accepted tiles skip the edge decision),
// keeping the nearest per sample in registers: the tile's buffer lives in
// its threads and is written once (no atomics). The (at most four) samples
// are four named variables: private arrays indexed at run time are slow on
// CPU drivers. (Staging the list in workgroup memory behind barriers was
// slower on lavapipe.)
@compute @workgroup_size(8, 8)
fn raster_binned(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let tile = wg.y * P.mode.z + wg.x;
    let x = wg.x * TILE + lid.x;
    let y = wg.y * TILE + lid.y;
    if x >= P.size.x || y >= P.size.y {
        return;
    }
    let stored = P.size.w;
    let pixel = y * P.size.x + x;
    // Segment z of the list: the first starts afresh, the others go on
    // from what the one before wrote.
    var b0 = Best(0.0, EMPTY, 0u);
    var b1 = b0;
    var b2 = b0;
    var b3 = b0;
    var evals = 0u;
    if P.flags.z > 0u {
        b0 = read_sample(0u, pixel);
        b1 = read_sample(1u, pixel);
        b2 = read_sample(2u, pixel);
        b3 = read_sample(3u, pixel);
        evals = out_evals[pixel];
    }
    let start = tile_offsets[tile] + P.flags.z * SEGMENT;
    let end = min(tile_offsets[tile + 1u], start + SEGMENT);
    for (var i = start; i < end; i++) {
        let entry = tile_list[i];
        let k = entry & ~ACCEPTED_BIT;
        // The triangle's box first (a pixel outside it has no sample the
        // triangle covers), then its samples.
        let a = bitcast<u32>(tris[k].r[6].y);
        let b = bitcast<u32>(tris[k].r[6].z);
        if x < (a & 0xffffu) || y < (a >> 16u) || x >= (b & 0xffffu) || y >= (b >> 16u) {
            continue;
        }
        evals += stored;
        let t = tris[k];
        let accepted = (entry & ACCEPTED_BIT) != 0u;
        test_sample(&b0, t, accepted, 0u, x, y);
        if stored > 1u {
            test_sample(&b1, t, accepted, 1u, x, y);
        }
        if stored > 2u {
            test_sample(&b2, t, accepted, 2u, x, y);
            test_sample(&b3, t, accepted, 3u, x, y);
        }
    }
    write_sample(b0, 0u, pixel);
    if stored > 1u {
        write_sample(b1, 1u, pixel);
    }
    if stored > 2u {
        write_sample(b2, 2u, pixel);
        write_sample(b3, 3u, pixel);
    }
    out_evals[pixel] = evals;
}

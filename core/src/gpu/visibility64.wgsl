// Visibility in one 64-bit atomic per covered sample on the key
// (w bits << 32 | id): a positive f32's bits order like the value, so the
// smallest key is the nearest sample, an exact depth tie going to the
// smaller id (`wins_depth_test`). With the depth test off the key is
// (id << 32 | w bits): the smallest id. The buffer keeps the key's
// complement with atomicMax, so the zeroed buffer is empty. Needs
// SHADER_INT64_ATOMIC_MIN_MAX.

@group(0) @binding(10) var<storage, read_write> visible: array<atomic<u64>>;

fn store(i: u32, w: f32, id: u32) {
    var key = (u64(bitcast<u32>(w)) << 32u) | u64(id);
    if P.flags.x == 1u {
        key = (u64(id) << 32u) | u64(bitcast<u32>(w));
    }
    atomicMax(&visible[i], ~key);
}

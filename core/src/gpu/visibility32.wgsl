// Visibility without 64-bit atomics, in two passes over the same triangles:
// pass 0 keeps each sample's nearest w bits, pass 1 the smallest id among
// the samples at exactly that w: the result of the one 64-bit key. With the
// depth test off the roles swap: pass 0 keeps the smallest id, pass 1 its
// w. Both buffers keep complements with atomicMax (a zeroed buffer is
// empty).

@group(0) @binding(10) var<storage, read_write> nearest: array<atomic<u32>>;
@group(0) @binding(11) var<storage, read_write> ids: array<atomic<u32>>;

fn store(i: u32, w: f32, id: u32) {
    let bits = bitcast<u32>(w);
    if P.flags.x == 1u {
        if P.mode.y == 0u {
            atomicMax(&ids[i], ~id);
        } else if atomicLoad(&ids[i]) == ~id {
            atomicMax(&nearest[i], ~bits);
        }
    } else if P.mode.y == 0u {
        atomicMax(&nearest[i], ~bits);
    } else if atomicLoad(&nearest[i]) == ~bits {
        atomicMax(&ids[i], ~id);
    }
}

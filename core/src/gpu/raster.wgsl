// gpu-raster: the hardware pipeline as a reference. Vertices are taken to
// camera space exactly as the CPU does it (p − eye, then three dot products),
// then to clip space with a reversed, infinite-far depth (perspective) or a
// reversed linear depth (orthographic). The fragment writes the triangle id and
// the view-axis distance w; the stencil counts every fragment.

struct Camera {
    eye: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    forward: vec4<f32>,
    // half_x, half_y, near, far (far: orthographic only)
    params: vec4<f32>,
    // x: 1 for orthographic
    mode: vec4<u32>,
}

@group(0) @binding(0) var<uniform> cam: Camera;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) w: f32,
    @location(1) @interpolate(flat) id: u32,
}

@vertex
fn vs(@location(0) p: vec3<f32>, @location(1) id: u32) -> VertexOut {
    let v = p - cam.eye.xyz;
    let c = vec3<f32>(dot(v, cam.right.xyz), dot(v, cam.up.xyz), dot(v, cam.forward.xyz));
    var out: VertexOut;
    if cam.mode.x == 1u {
        // z = 1 at near, 0 at far: kept for near <= w <= far.
        let z = (cam.params.w - c.z) / (cam.params.w - cam.params.z);
        out.clip = vec4<f32>(c.x / cam.params.x, c.y / cam.params.y, z, 1.0);
    } else {
        // z/w = near/w: 1 at near, towards 0 at infinity; clipped where w < near.
        out.clip = vec4<f32>(c.x / cam.params.x, c.y / cam.params.y, cam.params.z, c.z);
    }
    out.w = c.z;
    out.id = id;
    return out;
}

struct FragmentOut {
    @location(0) id: u32,
    @location(1) w: f32,
}

@fragment
fn fs(in: VertexOut) -> FragmentOut {
    var out: FragmentOut;
    out.id = in.id;
    out.w = in.w;
    return out;
}

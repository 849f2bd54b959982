// Tone map of the film (facet_render::film's, written once there): per pixel the mean
// L = film.rgb (the film holds running means), v = 1 − exp(−2^exposure · max(L, 0)), the sRGB transfer
// function, 8 bits, packed RGBA with alpha 255. Rust: facet_render::tonemap::ToneMap.

const WG: u32 = 64u;

// Rust: facet_render::tonemap::ToneMapParams.
struct Params {
    pixels: u32,
    // 2^exposure
    scale: f32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> film: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;

fn encode_srgb(v: f32) -> f32 {
    // NaN compares false both ways: it becomes 0, as on the CPU.
    var x = 0.0;
    if (v > 0.0) {
        x = min(v, 1.0);
    }
    if (x <= 0.0031308) {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(WG)
fn tonemap(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= params.pixels) {
        return;
    }
    let f = film[i];
    let l = f.xyz;
    let v = vec3<f32>(1.0) - exp(-params.scale * max(l, vec3<f32>(0.0)));
    let s = vec3<f32>(encode_srgb(v.x), encode_srgb(v.y), encode_srgb(v.z));
    // Round half up, as the CPU's (s · 255 + 0.5) as u8.
    let b = vec3<u32>(floor(s * 255.0 + 0.5));
    out[i] = b.x | (b.y << 8u) | (b.z << 16u) | (255u << 24u);
}

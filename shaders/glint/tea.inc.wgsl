// Include-only. TEA, 8 rounds, and pcg3d (Rust twins: facet_glint::tea). The key and δ are override
// constants that every pipeline gets from Rust (facet_glint::tea::pipeline_constants), so they
// are written once. Returns (v0, v1) after TEA_ROUNDS rounds: the 64-bit hash is (v1 << 32) + v0.
override TEA_K0: u32;
override TEA_K1: u32;
override TEA_K2: u32;
override TEA_K3: u32;
override TEA_DELTA: u32;
override TEA_ROUNDS: u32;

// One round on (v0, v1, sum).
fn tea_round(s: vec3<u32>) -> vec3<u32> {
    let sum = s.z + TEA_DELTA;
    let v0 = s.x + (((s.y << 4u) + TEA_K0) ^ (s.y + sum) ^ ((s.y >> 5u) + TEA_K1));
    let v1 = s.y + (((v0 << 4u) + TEA_K2) ^ (v0 + sum) ^ ((v0 >> 5u) + TEA_K3));
    return vec3<u32>(v0, v1, sum);
}

// The rounds are written out rather than looped: llvmpipe (lavapipe) stops a loop after 65 535
// iterations counted over the whole invocation, which a glint walk's thousands of hashes
// exceeded (footprints of more than ~2400 flakes came back short). At most 16 rounds
// (facet_glint::tea::ROUNDS is checked against that).
fn tea(a: u32, b: u32) -> vec2<u32> {
    var s = vec3<u32>(a, b, 0u);
    if (TEA_ROUNDS > 0u) { s = tea_round(s); }
    if (TEA_ROUNDS > 1u) { s = tea_round(s); }
    if (TEA_ROUNDS > 2u) { s = tea_round(s); }
    if (TEA_ROUNDS > 3u) { s = tea_round(s); }
    if (TEA_ROUNDS > 4u) { s = tea_round(s); }
    if (TEA_ROUNDS > 5u) { s = tea_round(s); }
    if (TEA_ROUNDS > 6u) { s = tea_round(s); }
    if (TEA_ROUNDS > 7u) { s = tea_round(s); }
    if (TEA_ROUNDS > 8u) { s = tea_round(s); }
    if (TEA_ROUNDS > 9u) { s = tea_round(s); }
    if (TEA_ROUNDS > 10u) { s = tea_round(s); }
    if (TEA_ROUNDS > 11u) { s = tea_round(s); }
    if (TEA_ROUNDS > 12u) { s = tea_round(s); }
    if (TEA_ROUNDS > 13u) { s = tea_round(s); }
    if (TEA_ROUNDS > 14u) { s = tea_round(s); }
    if (TEA_ROUNDS > 15u) { s = tea_round(s); }
    return s.xy;
}

// Uniform in [0, 1): the low word's top 23 bits as a mantissa in [1, 2), minus 1.
fn tea_unit(a: u32, b: u32) -> f32 {
    return bitcast<f32>(0x3f800000u | (tea(a, b).x >> 9u)) - 1.0;
}

// pcg3d (Jarzynski & Olano 2020): facet_glint::tea::pcg3d.
fn pcg3d(x: vec3<u32>) -> vec3<u32> {
    var v = x * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> vec3<u32>(16u);
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

// 24 bits to [0, 1).
fn unit24(x: u32) -> f32 {
    return f32(x >> 8u) / 16777216.0;
}

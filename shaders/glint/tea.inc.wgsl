// Include-only. TEA, 8 rounds (Rust twin: facet_glint::tea). The key and δ are override
// constants that every pipeline gets from Rust (facet_glint::tea::pipeline_constants), so they
// are written once. Returns (v0, v1) after TEA_ROUNDS rounds: the 64-bit hash is (v1 << 32) + v0.
override TEA_K0: u32;
override TEA_K1: u32;
override TEA_K2: u32;
override TEA_K3: u32;
override TEA_DELTA: u32;
override TEA_ROUNDS: u32;

fn tea(a: u32, b: u32) -> vec2<u32> {
    var v0 = a;
    var v1 = b;
    var sum = 0u;
    for (var r = 0u; r < TEA_ROUNDS; r++) {
        sum += TEA_DELTA;
        v0 += ((v1 << 4u) + TEA_K0) ^ (v1 + sum) ^ ((v1 >> 5u) + TEA_K1);
        v1 += ((v0 << 4u) + TEA_K2) ^ (v0 + sum) ^ ((v0 >> 5u) + TEA_K3);
    }
    return vec2<u32>(v0, v1);
}

// Uniform in [0, 1): the low word's top 23 bits as a mantissa in [1, 2), minus 1.
fn tea_unit(a: u32, b: u32) -> f32 {
    return bitcast<f32>(0x3f800000u | (tea(a, b).x >> 9u)) - 1.0;
}

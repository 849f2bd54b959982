// Logic stage (Laine, Karras, Aila 2013, "Megakernels considered harmful"): one thread per
// path slot. Accumulates finished paths into the film, plays Russian roulette on the living,
// queues the living for extension and the finished for regeneration.

#include "render/frame.inc.wgsl"

// Accumulation and regeneration: the slot's pixel is owned by the slot for the whole tile, so
// the film is written without atomics and the image does not depend on scheduling. The film
// holds each pixel's running mean and count, and with moments the root mean square of its
// samples: both stay below the largest sample, so no finite radiance overflows them (a sum of
// 16 samples of 1e38, or the square of one of 1e20, would be inf in f32).
fn finish(slot: u32) {
    let l = path_get(R_L, slot).xyz;
    let px = slot_pixel(slot);
    // A non-finite sample is dropped (counted, not added) rather than poisoning the pixel.
    let ok = all(l == l) && all(abs(l) < vec3<f32>(3.0e38));
    let v = select(vec3<f32>(0.0), l, ok);
    let f = film[px];
    let n = f.w + 1.0;
    // m' = m + (v − m) / n
    film[px] = vec4<f32>(f.xyz + (v - f.xyz) / n, n);
    if (frame.moments != 0u) {
        // r' = k √((r/k)² + ((v/k)² − (r/k)²) / n), k = max(r, |v|): no square overflows.
        let r = film_sq[px].xyz;
        let k = max(max(r, abs(v)), vec3<f32>(1.0e-30));
        let a = r / k;
        let b = v / k;
        film_sq[px] = vec4<f32>(k * sqrt(max(a * a + (b * b - a * a) / n, vec3<f32>(0.0))), 0.0);
    }
}

@compute @workgroup_size(WG)
fn logic(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = thread_index(gid, nwg);
    if (slot >= frame.tile_pixels) {
        return;
    }
    var i = info[slot];
    if (i.x == SLOT_FLYING && i.z >= frame.rr_depth) {
        // Russian roulette: survive with q = min(max β, 0.95), β /= q.
        let beta = path_get(R_BETA, slot);
        let q = min(max(max(beta.x, beta.y), beta.z), 0.95);
        if (path_rand(slot, 7u) >= q) {
            i.x = SLOT_ENDED;
        } else {
            path_set(R_BETA, slot, vec4<f32>(beta.xyz / q, beta.w));
        }
    }
    if (i.x == SLOT_FLYING) {
        push(Q_EXTEND, slot);
        return;
    }
    if (i.x == SLOT_ENDED) {
        finish(slot);
        i.x = SLOT_START;
    }
    if (i.x == SLOT_START) {
        if (i.y < frame.sample_end) {
            push(Q_GEN, slot);
        } else {
            i.x = SLOT_IDLE;
        }
    }
    info[slot] = i;
}

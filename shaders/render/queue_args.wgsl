// Closes queues [FIRST, FIRST + COUNT): their sizes for the consumers, indirect dispatch
// arguments (2D as facet_gpu::dispatch::workgroups lays them out), and zeroed counters for the
// next producers. One thread.

// The consuming stage's workgroup size.
override STAGE_WG: u32;
override FIRST: u32;
override COUNT: u32;
// A persistent consumer's cap on its workgroups, and counters [ZERO_FIRST, ZERO_FIRST +
// ZERO_COUNT) zeroed here for the consumers (a persistent extend stage's fetch counter, the
// glint stages' footprint histograms).
override MAX_GROUPS: u32 = 0xffffffffu;
override ZERO_FIRST: u32 = 0u;
override ZERO_COUNT: u32 = 0u;

@group(0) @binding(0) var<storage, read_write> counters: array<u32>;
@group(0) @binding(1) var<storage, read_write> sizes: array<u32>;
@group(0) @binding(2) var<storage, read_write> args: array<u32>;

@compute @workgroup_size(1)
fn queue_args() {
    for (var q = FIRST; q < FIRST + COUNT; q++) {
        let n = counters[q];
        counters[q] = 0u;
        sizes[q] = n;
        let groups = min((n + STAGE_WG - 1u) / STAGE_WG, MAX_GROUPS);
        let x = min(groups, 65535u);
        args[3u * q] = x;
        args[3u * q + 1u] = select(0u, (groups + x - 1u) / max(x, 1u), x > 0u);
        args[3u * q + 2u] = 1u;
    }
    for (var c = ZERO_FIRST; c < ZERO_FIRST + ZERO_COUNT; c++) {
        counters[c] = 0u;
    }
}

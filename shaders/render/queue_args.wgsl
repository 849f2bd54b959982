// Closes queues [FIRST, FIRST + COUNT): their sizes for the consumers, indirect dispatch
// arguments (2D as facet_gpu::dispatch::workgroups lays them out), and zeroed counters for the
// next producers. One thread.

// The consuming stage's workgroup size.
override STAGE_WG: u32;
override FIRST: u32;
override COUNT: u32;

@group(0) @binding(0) var<storage, read_write> counters: array<u32>;
@group(0) @binding(1) var<storage, read_write> sizes: array<u32>;
@group(0) @binding(2) var<storage, read_write> args: array<u32>;

@compute @workgroup_size(1)
fn queue_args() {
    for (var q = FIRST; q < FIRST + COUNT; q++) {
        let n = counters[q];
        counters[q] = 0u;
        sizes[q] = n;
        let groups = (n + STAGE_WG - 1u) / STAGE_WG;
        let x = min(groups, 65535u);
        args[3u * q] = x;
        args[3u * q + 1u] = select(0u, (groups + x - 1u) / max(x, 1u), x > 0u);
        args[3u * q + 2u] = 1u;
    }
}

//! The pacing of a progressive preview: batches of samples sized to take about one frame. The
//! viewer's preview worker paces its renders with it, and `facet bench`'s viewer section replays
//! that pacing to measure it.

/// The time one batch of a progressive preview aims at, ms (a frame at 60 Hz).
pub const FRAME_MS: f64 = 16.0;
/// The most samples per pixel in one preview batch.
pub const MAX_SPP_PER_FRAME: u32 = 64;

/// The next preview batch (spp): the last one, which took `ms`, scaled toward FRAME_MS, at
/// most doubling or halving, within 1 … MAX_SPP_PER_FRAME.
pub fn next_batch(spp: u32, ms: f64) -> u32 {
    let scale = (FRAME_MS / ms.max(1e-3)).clamp(0.5, 2.0);
    ((spp as f64 * scale).floor() as u32).clamp(1, MAX_SPP_PER_FRAME)
}

//! A real window: the viewer binary under the current X display renders on the GPU adapter
//! (lavapipe in CI, under Xvfb), captures itself, and the screenshot is checked: not blank,
//! and the sphere's region differs from the sky's. Prints the measured frame time, samples
//! per second and the edit-to-frame latency (run with --nocapture).
//!
//! Skips without `DISPLAY` (a `SKIPPED` line through `facet_gpu::report_skip`), unless
//! `FACET_REQUIRE_GPU=1` and `FACET_REQUIRE_DISPLAY=1`, where it fails instead; skips without
//! a GPU adapter as every GPU test does (`facet_gpu::gpu_for_tests`, checked in this process
//! before the window is opened). Once there is a display and an adapter, a viewer that exits
//! with an error, dies on a signal or writes no screenshot fails the test, whatever the
//! variables say.

use std::process::Command;

fn stats(img: &image::RgbaImage, x0: u32, y0: u32, x1: u32, y1: u32) -> ([f64; 3], f64) {
    let mut sum = [0f64; 3];
    let mut sq = 0f64;
    let mut n = 0f64;
    for y in y0..y1 {
        for x in x0..x1 {
            let p = img.get_pixel(x, y).0;
            let l = (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
            sq += l * l;
            n += 1.0;
        }
    }
    let mean = sum.map(|s| s / n);
    let ml = (mean[0] + mean[1] + mean[2]) / 3.0;
    (mean, (sq / n - ml * ml).max(0.0).sqrt())
}

#[test]
fn window_renders_the_sphere_on_the_gpu() {
    let require = std::env::var("FACET_REQUIRE_GPU").is_ok_and(|v| v == "1")
        && std::env::var("FACET_REQUIRE_DISPLAY").is_ok_and(|v| v == "1");
    const TEST: &str = "window_renders_the_sphere_on_the_gpu";
    if std::env::var_os("DISPLAY").is_none() {
        if require {
            panic!("FACET_REQUIRE_DISPLAY=1 but DISPLAY is not set (run under xvfb-run -a)");
        }
        facet_gpu::report_skip(TEST, "no DISPLAY (run under xvfb-run -a)");
        return;
    }
    // No adapter at all is a skip (or a failure under FACET_REQUIRE_GPU=1), decided here and
    // not from the viewer's exit status, which only ever means a failure.
    if facet_gpu::gpu_for_tests(TEST).is_none() {
        return;
    }
    let out = std::env::var_os("FACET_VIEWER_SCREENSHOT")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            std::env::temp_dir().join(format!("facet-viewer-{}.png", std::process::id()))
        });
    // A screenshot left by an earlier run must not pass for this one's.
    let _ = std::fs::remove_file(&out);
    let _ = std::fs::remove_file(out.with_extension("json"));
    let frames = std::env::var("FACET_VIEWER_FRAMES").unwrap_or_else(|_| "16".into());
    let t = std::time::Instant::now();
    let status = Command::new(env!("CARGO_BIN_EXE_facet-viewer"))
        .args(["--screenshot", out.to_str().unwrap(), "--frames", &frames])
        .status()
        .expect("run facet-viewer");
    let wall = t.elapsed().as_secs_f64();
    assert!(
        status.success(),
        "facet-viewer failed ({status}) under DISPLAY={:?}",
        std::env::var_os("DISPLAY").unwrap_or_default()
    );
    assert!(
        out.exists(),
        "facet-viewer exited 0 but wrote no screenshot at {}",
        out.display()
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.with_extension("json")).unwrap())
            .unwrap();
    println!("viewer run: {wall:.1} s wall, {meta}");
    assert!(
        meta["error"].is_null(),
        "the preview reported {}",
        meta["error"]
    );
    println!(
        "preview 256x256 on the window's adapter: {:.1} ms/frame, {:.2} Msamples/s ({:.1} spp/s), edit→first frame {} ms",
        meta["frame_ms"].as_f64().unwrap_or(f64::NAN),
        meta["samples_per_s"].as_f64().unwrap_or(f64::NAN) / 1e6,
        meta["spp_per_s"].as_f64().unwrap_or(f64::NAN),
        meta["edit_to_frame_ms"]
    );
    let img = image::open(&out)
        .expect("the screenshot is a PNG")
        .to_rgba8();
    let (w, h) = img.dimensions();
    let (_, sd_all) = stats(&img, 0, 0, w, h);
    assert!(sd_all > 5.0, "the window is blank (std dev {sd_all:.2})");
    let ppp = meta["pixels_per_point"].as_f64().unwrap_or(1.0);
    let r: Vec<f64> = meta["preview_rect"]
        .as_array()
        .expect("the preview was drawn")
        .iter()
        .map(|v| v.as_f64().unwrap() * ppp)
        .collect();
    let (x0, y0, x1, y1) = (r[0], r[1], r[2], r[3]);
    let (pw, ph) = (x1 - x0, y1 - y0);
    let px = |fx: f64, fy: f64| {
        (
            ((x0 + fx * pw) as u32).min(w - 1),
            ((y0 + fy * ph) as u32).min(h - 1),
        )
    };
    // The sphere (radius 1 at 4.5, 35° field of view) covers the middle of the preview; the
    // sky is the top band.
    let (sa, sb) = (px(0.4, 0.4), px(0.6, 0.6));
    let (ba, bb) = (px(0.05, 0.02), px(0.95, 0.1));
    let (sphere, sd_sphere) = stats(&img, sa.0, sa.1, sb.0, sb.1);
    let (sky, _) = stats(&img, ba.0, ba.1, bb.0, bb.1);
    println!("sphere region mean {sphere:.1?} (sd {sd_sphere:.1}), sky region mean {sky:.1?}");
    let diff: f64 = (0..3).map(|c| (sphere[c] - sky[c]).abs()).sum();
    assert!(
        diff > 10.0,
        "the sphere region looks like the sky: {sphere:?} vs {sky:?}"
    );
    assert!(sphere.iter().sum::<f64>() > 3.0, "the preview is black");
}

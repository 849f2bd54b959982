//! The preview worker without a window: it accumulates, restarts on a material edit (written
//! in place, no pipeline rebuild), and the timings are printed (run with --nocapture).

use facet_viewer::ViewerApp;
use facet_viewer::preview::{Command, Preview, PreviewScene};
use std::time::{Duration, Instant};

fn wait(p: &Preview, what: &str, ok: impl Fn(&facet_viewer::preview::Shared) -> bool) {
    let t = Instant::now();
    loop {
        {
            let s = p.shared.lock().unwrap();
            assert!(s.error.is_none(), "preview error: {:?}", s.error);
            if ok(&s) {
                return;
            }
        }
        assert!(
            t.elapsed() < Duration::from_secs(120),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn preview_accumulates_and_restarts_on_an_edit() {
    let Some(gpu) = facet_gpu::gpu_for_tests("preview_accumulates_and_restarts_on_an_edit") else {
        return;
    };
    let mut app = ViewerApp::with_default_material().unwrap();
    let p = Preview::start(
        gpu,
        PreviewScene::sphere(app.material.render_material().unwrap()),
        (256, 256),
        || {},
    );
    wait(&p, "4 samples", |s| s.samples >= 4);
    let (frame_ms, sps, batch) = {
        let s = p.shared.lock().unwrap();
        (s.frame_ms, s.samples_per_s, s.spp_per_frame)
    };
    let mut latencies = Vec::new();
    for (k, scale) in [0.5, 1.5, 0.8].into_iter().enumerate() {
        let (ax, ay, rot) = app.material.alpha().unwrap();
        app.material.set_alpha(ax * scale, ay * scale, rot);
        let generation = k as u64 + 1;
        let sent = Instant::now();
        p.send(Command::Material {
            generation,
            material: Box::new(app.material.render_material().unwrap()),
            sent,
        });
        wait(&p, "the edited material's first frame", |s| {
            s.generation == generation
        });
        let wall = sent.elapsed().as_secs_f64() * 1e3;
        let s = p.shared.lock().unwrap().clone();
        // Restarted: at most the two batches since the edit, not the samples before it.
        assert!(
            s.samples <= 2 * s.spp_per_frame.max(1),
            "accumulation restarted ({} samples, {} per batch)",
            s.samples,
            s.spp_per_frame
        );
        assert!(!s.last_rebuilt, "an α edit is written in place");
        latencies.push(wall);
        let m: u64 = s
            .rgba
            .iter()
            .map(|c| (c[0] as u64) + c[1] as u64 + c[2] as u64)
            .sum();
        assert!(m > 0);
    }
    println!(
        "preview 256x256, {batch} spp per batch: {frame_ms:.1} ms/frame, {:.3} Msamples/s; edit to first updated frame: {:?} ms",
        sps / 1e6,
        latencies.iter().map(|l| l.round()).collect::<Vec<_>>()
    );
}

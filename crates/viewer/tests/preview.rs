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

/// A measured input: "measured data" renders the measurement itself, and the split puts it on
/// the sphere's −x half (the triangles whose centroid has x < 0, half of the sphere's) beside
/// the edited model; the worker renders the split scene and an edit of the model is written in
/// place while the measurement stays.
#[test]
fn split_preview_shows_the_measurement_beside_the_model() {
    use facet_fit::sources::InputSpec;
    use facet_viewer::material::{EditedMaterial, Shown};
    use facet_viewer::preview::{SPHERE, SPLIT};
    let Some(gpu) =
        facet_gpu::gpu_for_tests("split_preview_shows_the_measurement_beside_the_model")
    else {
        return;
    };
    let spec = InputSpec::parse("nbrdf:gold-metallic-paint");
    let src = facet_fit::sources::nbrdf::NbrdfLibrary::embedded()
        .get("gold-metallic-paint")
        .unwrap();
    // The single layer: a coated model is rebuilt on an edit of α, not written in place (the
    // default fit keeps a coat on this paint).
    let cfg = facet_fit::FitConfig {
        coat: facet_fit::fitting::CoatSearch::Off,
        ..facet_fit::FitConfig::isotropic()
    };
    let fit = facet_fit::fit_material(&src, "gold", &cfg).unwrap();
    let measurement = facet_render::scene::Measurement::of(&spec, &src).unwrap();
    let mut app = ViewerApp::with_default_material().unwrap();
    assert!(
        !app.material.available(Shown::Measured),
        "a fit JSON has no measurement"
    );
    app.material =
        EditedMaterial::with_measurement(fit, "nbrdf:gold-metallic-paint".into(), measurement);
    app.material.shown = Shown::Measured;
    let m = app.material.render_material().unwrap();
    assert!(
        m.measured.is_some() && m.facet.is_none(),
        "the measurement itself"
    );

    app.material.shown = Shown::Ggx;
    app.split = true;
    let ps = app.preview_scene(None).unwrap();
    let count = |k: usize| {
        ps.scene
            .triangle_material
            .iter()
            .filter(|&&t| t == k as u32)
            .count()
    };
    let (model, data) = (count(SPHERE), count(SPLIT));
    assert!(
        model > 1000 && model.abs_diff(data) <= model / 50,
        "{model} / {data} triangles"
    );
    assert!(ps.scene.materials[SPLIT].measured.is_some());
    assert!(ps.scene.materials[SPHERE].facet.is_some());

    let p = Preview::start(gpu, ps, (128, 128), || {});
    wait(&p, "4 samples of the split sphere", |s| s.samples >= 4);
    let (ax, ay, rot) = app.material.alpha().unwrap();
    app.material.set_alpha(ax * 1.5, ay * 1.5, rot);
    p.send(Command::Material {
        generation: 1,
        material: Box::new(app.material.render_material().unwrap()),
        sent: Instant::now(),
    });
    wait(&p, "the edit's first frame", |s| s.generation == 1);
    let s = p.shared.lock().unwrap().clone();
    assert!(
        !s.last_rebuilt,
        "the model's α is written in place beside the measurement"
    );
    // Both halves of the sphere are lit: the image's middle row left and right of the centre.
    let row = &s.rgba[(s.height / 2 * s.width) as usize..((s.height / 2 + 1) * s.width) as usize];
    let half = |r: std::ops::Range<u32>| -> u64 {
        r.map(|x| {
            row[x as usize]
                .iter()
                .take(3)
                .map(|&c| c as u64)
                .sum::<u64>()
        })
        .sum()
    };
    let w = s.width;
    assert!(half(w / 2 - 20..w / 2 - 2) > 0 && half(w / 2 + 2..w / 2 + 20) > 0);
}

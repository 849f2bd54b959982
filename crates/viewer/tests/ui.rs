//! UI tests with egui_kittest (no GPU: the preview is off, the renderer-facing material and
//! its generation counter are what the preview would get).

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_viewer::ViewerApp;
use facet_viewer::material::Shown;

fn harness() -> Harness<'static, ViewerApp> {
    let app = ViewerApp::with_default_material().expect("the demo fit loads");
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 900.0))
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app);
    h.run_steps(2);
    h
}

/// The α the renderer's sphere material has (the shown model's).
fn rendered_alpha(app: &ViewerApp) -> (f64, f64) {
    let m = app.material.render_material().unwrap();
    let f = m.facet.unwrap();
    match f.model {
        ModelChoice::Tabulated => {
            let s = f.fit.record.tabulated.stretch;
            (s.alpha_x, s.alpha_y)
        }
        ModelChoice::Ggx => {
            let p = f.fit.record.ggx.as_ref().unwrap();
            (p.alpha_x, p.alpha_y)
        }
        ModelChoice::Beckmann => {
            let p = f.fit.record.beckmann.as_ref().unwrap();
            (p.alpha_x, p.alpha_y)
        }
    }
}

#[test]
fn alpha_x_slider_changes_the_rendered_material_and_restarts_accumulation() {
    for shown in [Shown::Tabulated, Shown::Ggx] {
        let mut h = harness();
        h.state_mut().material.shown = shown;
        h.run_steps(2);
        let gen0 = h.state().generation;
        let (ax0, ay0) = rendered_alpha(h.state());
        h.get_by_role_and_label(Role::Slider, "αx")
            .set_value_accesskit(ax0 * 0.5);
        h.run_steps(2);
        let app = h.state();
        let (ax1, ay1) = rendered_alpha(app);
        assert!(
            (ax1 - ax0 * 0.5).abs() < 1e-3 * ax0,
            "{shown:?}: αx {ax0} -> {ax1}"
        );
        // The lock is on by default: αy scales with αx.
        assert!(
            (ay1 / ay0 - 0.5).abs() < 1e-3,
            "{shown:?}: αy {ay0} -> {ay1}"
        );
        assert!(app.generation > gen0, "{shown:?}: generation not bumped");
        assert_eq!(app.samples(), 0, "accumulation restarted");
        assert_eq!(
            app.sent_key.as_ref(),
            Some(&app.material.key()),
            "the renderer got the edited material"
        );
    }
}

#[test]
fn unlocked_alpha_y_stays() {
    let mut h = harness();
    h.state_mut().material.shown = Shown::Ggx;
    h.state_mut().material.lock = false;
    h.run_steps(2);
    let (ax0, ay0) = rendered_alpha(h.state());
    h.get_by_role_and_label(Role::Slider, "αx")
        .set_value_accesskit(ax0 * 2.0);
    h.run_steps(2);
    let (ax1, ay1) = rendered_alpha(h.state());
    assert!((ax1 / ax0 - 2.0).abs() < 1e-3);
    assert_eq!(ay1, ay0);
}

fn open_in_ui(h: &mut Harness<'static, ViewerApp>, path: &std::path::Path) {
    h.state_mut().open_text = path.display().to_string();
    h.get_by_role_and_label(Role::Button, "Open").click();
    // A MERL file is read (and fitted) on a thread: wait for its answer.
    for _ in 0..200 {
        h.run_steps(1);
        if h.state().fit_job.is_none() && h.state().error.is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

#[test]
fn opening_a_bad_file_shows_an_error_and_keeps_the_material() {
    let dir = std::env::temp_dir().join(format!("facet-viewer-ui-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad_merl = dir.join("x.binary");
    std::fs::write(&bad_merl, "this is not a MERL file\n").unwrap();
    let bad_json = dir.join("broken.json");
    std::fs::write(&bad_json, "{ \"name\": \"half a record\", ").unwrap();
    let missing = dir.join("missing.binary");
    for bad in [&bad_merl, &bad_json, &missing] {
        let mut h = harness();
        let before = h.state().material.record.clone();
        let gen0 = h.state().generation;
        open_in_ui(&mut h, bad);
        let app = h.state();
        let err = app.error.clone().unwrap_or_default();
        assert!(
            err.contains("cannot open"),
            "{}: error {err:?}",
            bad.display()
        );
        assert_eq!(app.material.record, before, "the previous material stays");
        assert_eq!(app.generation, gen0, "the renderer's material is unchanged");
        // The error is in the window.
        let _ = h.get_by_label_contains("Error: cannot open");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn saving_writes_a_fit_the_loader_reads_back_equal() {
    let dir = std::env::temp_dir().join(format!("facet-viewer-save-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("edited.json");
    let mut h = harness();
    h.state_mut().material.shown = Shown::Tabulated;
    h.run_steps(2);
    h.get_by_role_and_label(Role::Slider, "αx")
        .set_value_accesskit(0.7);
    h.run_steps(2);
    h.state_mut().material.tint = [1.0, 0.8, 0.6];
    h.state_mut().save_text = out.display().to_string();
    h.run_steps(1);
    h.get_by_role_and_label(Role::Button, "Save fit JSON")
        .click();
    h.run_steps(2);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    let loaded = FittedMaterial::load(&out).expect("the fit loader reads the saved JSON");
    let expected = h.state().material.edited_record();
    assert_eq!(loaded.record, expected);
    assert!((loaded.record.tabulated.stretch.alpha_x - 0.7).abs() < 1e-9);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fitting_runs_in_the_background_and_replaces_the_material() {
    let mut h = harness();
    let gen0 = h.state().generation;
    h.state_mut().open_text = "analytic:ggx?alpha=0.3&conductor=gold".into();
    h.get_by_role_and_label(Role::Button, "Open").click();
    h.run_steps(1);
    assert!(h.state().fit_job.is_some(), "the fit runs on a thread");
    let _ = h.get_by_label_contains("fitting analytic:ggx");
    let t = std::time::Instant::now();
    while h.state().fit_job.is_some() {
        assert!(t.elapsed().as_secs() < 300, "the fit did not finish");
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    h.run_steps(1);
    let app = h.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let ggx = app.material.record.ggx.as_ref().unwrap();
    assert!(
        (ggx.alpha_x / 0.3 - 1.0).abs() < 0.05,
        "fitted α {}",
        ggx.alpha_x
    );
    assert!(app.generation > gen0);
    assert_eq!(app.material.source, "analytic:ggx?alpha=0.3&conductor=gold");
}

#[test]
fn neural_proxies_are_listed_and_fitted_by_name() {
    let mut h = harness();
    match h.state_mut().proxies().clone() {
        Ok(names) => {
            assert!(names.len() >= 100, "{} proxies", names.len());
            let spec = format!("nbrdf:{}", names[0]);
            h.state_mut().open(&spec);
            let t = std::time::Instant::now();
            while h.state().fit_job.is_some() {
                assert!(t.elapsed().as_secs() < 300, "the fit did not finish");
                std::thread::sleep(std::time::Duration::from_millis(50));
                h.run_steps(1);
            }
            assert!(h.state().error.is_none(), "{:?}", h.state().error);
            assert_eq!(h.state().material.source, spec);
            println!("fitted {spec} in {:.1} s", t.elapsed().as_secs_f64());
        }
        Err(e) => facet_gpu::report_skip("neural_proxies_are_listed_and_fitted_by_name", &e),
    }
}

#[test]
fn a_gltf_scene_opens_and_a_bad_one_is_an_error() {
    let mut h = harness();
    let demo = facet_viewer::demo_dir().join("demo.gltf");
    h.state_mut().open(&demo.display().to_string());
    h.run_steps(1);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    assert!(
        h.state().status.contains("is edited"),
        "{}",
        h.state().status
    );
    let bad = std::env::temp_dir().join(format!("facet-viewer-bad-{}.gltf", std::process::id()));
    std::fs::write(&bad, "{ not gltf").unwrap();
    let before = h.state().material.record.clone();
    h.state_mut().open(&bad.display().to_string());
    h.run_steps(1);
    assert!(
        h.state()
            .error
            .as_deref()
            .unwrap_or("")
            .contains("cannot open")
    );
    assert_eq!(h.state().material.record, before);
    let _ = std::fs::remove_file(&bad);
}

#[test]
fn diffuse_albedo_edits_reach_the_renderer_and_reset_to_the_fit() {
    for shown in [Shown::Tabulated, Shown::Ggx] {
        let mut h = harness();
        h.state_mut().material.shown = shown;
        h.run_steps(2);
        let fitted = h.state().material.fitted_diffuse().unwrap();
        let gen0 = h.state().generation;
        h.state_mut().material.set_diffuse([0.2, 0.3, 1.5]);
        h.run_steps(2);
        let app = h.state();
        let m = app.material.render_material().unwrap().facet.unwrap();
        let choice = match shown {
            Shown::Tabulated => facet_fit::model::material::ModelChoice::Tabulated,
            _ => facet_fit::model::material::ModelChoice::Ggx,
        };
        // Clamped to [0, 1]; the renderer's model carries it.
        assert_eq!(
            m.fit.model(choice).unwrap().diffuse,
            [0.2, 0.3, 1.0],
            "{shown:?}"
        );
        assert!(app.generation > gen0, "{shown:?}: generation not bumped");
        assert_eq!(app.sent_key.as_ref(), Some(&app.material.key()));
        h.get_by_role_and_label(Role::Button, "fitted").click();
        h.run_steps(2);
        assert_eq!(h.state().material.diffuse(), Some(fitted), "{shown:?}");
    }
}

/// Runs the UI until the fit in progress has arrived.
fn wait_for_fit(h: &mut Harness<'static, ViewerApp>) {
    let t = std::time::Instant::now();
    while h.state().fit_job.is_some() {
        assert!(t.elapsed().as_secs() < 300, "the fit did not finish");
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    h.run_steps(2);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
}

/// `facet-viewer INPUT --shown MODEL` on an input fitted in the background: the model asked
/// for is the one shown once the fit has arrived (not GGX, the default of a new fit), and its
/// radio button is the one selected.
#[test]
fn the_model_asked_for_is_shown_when_the_fit_arrives() {
    use egui_kittest::kittest::NodeT;
    for shown in [Shown::Tabulated, Shown::Beckmann] {
        let mut h = harness();
        // As `main` does: open INPUT, then --shown.
        h.state_mut().open("analytic:ggx?alpha=0.3&conductor=gold");
        h.state_mut().ask_shown(shown);
        assert!(h.state().fit_job.is_some(), "the fit runs on a thread");
        wait_for_fit(&mut h);
        let app = h.state();
        assert_eq!(app.material.source, "analytic:ggx?alpha=0.3&conductor=gold");
        assert_eq!(app.material.shown, shown, "--shown {}", shown.label());
        assert_eq!(app.sent_key.as_ref(), Some(&app.material.key()));
        let radio = h.get_by_role_and_label(Role::RadioButton, shown.label());
        assert_eq!(
            radio.accesskit_node().toggled(),
            Some(egui::accesskit::Toggled::True),
            "{} selected",
            shown.label()
        );
    }
}

/// A model picked while a fit runs is the one shown when it arrives; one the fit has not is
/// said on the status line.
#[test]
fn a_model_picked_while_the_fit_runs_stays_picked() {
    let mut h = harness();
    h.state_mut().open("analytic:ggx?alpha=0.3&conductor=gold");
    h.run_steps(1);
    assert!(h.state().fit_job.is_some(), "the fit runs on a thread");
    // By its id (the fit's status line above may change height meanwhile).
    h.get_by_role_and_label(Role::RadioButton, Shown::Beckmann.label())
        .click_accesskit();
    h.run_steps(1);
    assert_eq!(h.state().material.shown, Shown::Beckmann);
    wait_for_fit(&mut h);
    assert_eq!(h.state().material.shown, Shown::Beckmann);

    // A fit JSON opens at once: a model it lacks is said, and the default stays.
    let mut h = harness();
    let fit =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/demo/default_fit.json");
    h.state_mut().open(&fit.display().to_string());
    h.state_mut().ask_shown(Shown::Measured);
    let app = h.state();
    assert!(app.wanted.is_none() && app.material.shown != Shown::Measured);
    assert!(
        app.status.contains("measured data asked for"),
        "{}",
        app.status
    );
}

/// A glTF scene whose material names a measurement without a fit opens through a visible job:
/// loading fits nothing, the job's line names the measurement, and the scene is shown (with the
/// step's time in the status) once the fit arrives.
#[test]
fn a_scene_measurement_without_a_fit_is_fitted_as_a_visible_job() {
    let dir = std::env::temp_dir().join(format!("facet-viewer-measured-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let demo = facet_viewer::demo_dir();
    let mut gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(demo.join("demo.gltf")).unwrap()).unwrap();
    gltf["materials"][1]["extras"]["facet"] =
        serde_json::json!({"model": "measured", "source": "nbrdf:alum-bronze"});
    for file in ["default_fit.json", "sky.exr"] {
        std::fs::copy(demo.join(file), dir.join(file)).unwrap();
    }
    let path = dir.join("measured.gltf");
    std::fs::write(&path, gltf.to_string()).unwrap();
    let mut h = harness();
    h.state_mut().open(&path.display().to_string());
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    let job = h.state().scene_fit.as_ref().expect("a scene fit job");
    assert_eq!(job.label, "nbrdf:alum-bronze");
    assert!(h.state().gltf.is_none(), "the scene waits for its fit");
    h.run_steps(1);
    let text = "fitting the sampling NDF of nbrdf:alum-bronze for the scene";
    assert!(
        h.query_by_label_contains(text).is_some(),
        "the job's line is shown"
    );
    let t = std::time::Instant::now();
    while h.state().scene_fit.is_some() && t.elapsed().as_secs() < 300 {
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    assert_eq!(h.state().gltf.as_deref(), Some(path.as_path()));
    let status = &h.state().status;
    assert!(status.contains("is edited"), "{status}");
    assert!(
        status.contains("fitted the sampling NDF of nbrdf:alum-bronze in"),
        "{status}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

//! `facet-viewer`'s command line, as a user types it: the input as `facet` takes it (a
//! positional INPUT), help text per option, and bad arguments refused before a window opens
//! (none of these runs needs a display).

use std::process::Command;

fn viewer(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_facet-viewer"))
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `--help` names every option with its own text.
#[test]
fn help_describes_each_option() {
    let (ok, out, err) = viewer(&["--help"]);
    assert!(ok, "{err}");
    for (option, text) in [
        ("[INPUT]", "as `facet fit` takes it"),
        ("--material <SPEC>", "The same as INPUT"),
        ("--shown <MODEL>", "measured (the measurement itself"),
        ("--split", "Split the sphere"),
        ("--scene <PATH.gltf>", "A glTF scene for the preview"),
        ("--screenshot <PATH.png>", "Save a screenshot"),
        ("--frames <N>", "Frames of the preview"),
    ] {
        assert!(
            out.contains(option) && out.contains(text),
            "{option}: {out}"
        );
    }
}

/// A bad argument is refused naming it, before any window: an input that is not there, a
/// scene that is not there, two inputs, an unknown model, --frames without --screenshot.
#[test]
fn bad_arguments_are_refused_by_name() {
    for (args, needle) in [
        (&["nosuch.binary"][..], "nosuch.binary"),
        (&["--material", "nosuch.bsdf"][..], "nosuch.bsdf"),
        (&["--scene", "nosuch.gltf"][..], "--scene nosuch.gltf"),
        (&["nosuch.glb"][..], "nosuch.glb"),
        (
            &["nbrdf:nickel", "--material", "nbrdf:chrome"][..],
            "cannot be used with",
        ),
        (
            &["--shown", "phong"][..],
            "phong: measured, tabulated, ggx, beckmann or glint",
        ),
        (&["--frames", "3"][..], "--screenshot"),
    ] {
        let (ok, out, err) = viewer(args);
        assert!(!ok, "{args:?} was accepted: {out}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

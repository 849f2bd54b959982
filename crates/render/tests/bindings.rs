//! The integrator's bind groups by name (`facet_render::layout::bindings`) against the WGSL: every
//! pipeline file's `@group`/`@binding` globals, as naga reflects them, are exactly its groups'
//! lists — the same names at the same binding numbers, holding the same kind of resource. No
//! GPU needed.

use facet_gpu::shader;
use facet_render::layout::bindings::{BindingKind, Group, PIPELINES};
use facet_render::layout::tags::MaterialKind;

/// Every integrator pipeline file with its groups: `PIPELINES` and the material classes'
/// shading stages (one file may serve several classes).
fn pipelines() -> Vec<(&'static str, &'static [Group])> {
    let mut all = PIPELINES.to_vec();
    for kind in MaterialKind::ALL {
        let stage = kind.stage();
        if !all.iter().any(|(f, _)| *f == stage.file) {
            all.push((stage.file, stage.groups));
        }
    }
    all
}

/// (group, binding, name, kind) of every global of `file` that has a binding, sorted.
fn wgsl_bindings(file: &str) -> Vec<(u32, u32, String, BindingKind)> {
    let module = shader::validate(file, &shader::expand(file).unwrap()).unwrap();
    let mut out: Vec<_> = module
        .global_variables
        .iter()
        .filter_map(|(_, g)| {
            let b = g.binding.as_ref()?;
            let name = g.name.clone().unwrap_or_default();
            let kind = match g.space {
                naga::AddressSpace::Uniform => BindingKind::Uniform,
                naga::AddressSpace::Storage { access }
                    if access.contains(naga::StorageAccess::STORE) =>
                {
                    BindingKind::Storage
                }
                naga::AddressSpace::Storage { .. } => BindingKind::StorageReadOnly,
                naga::AddressSpace::Handle => match module.types[g.ty].inner {
                    naga::TypeInner::Image {
                        dim: naga::ImageDimension::D3,
                        arrayed: false,
                        class:
                            naga::ImageClass::Sampled {
                                kind: naga::ScalarKind::Float,
                                multi: false,
                            },
                    } => BindingKind::Texture3d,
                    ref other => panic!("{file}: `{name}` is a {other:?}"),
                },
                other => panic!("{file}: `{name}` is in {other:?}"),
            };
            Some((b.group, b.binding, name, kind))
        })
        .collect();
    out.sort_by_key(|b| (b.0, b.1));
    out
}

/// What the Rust lists say `groups` hold, in the same form.
fn listed_bindings(groups: &[Group]) -> Vec<(u32, u32, String, BindingKind)> {
    groups
        .iter()
        .flat_map(|g| {
            g.bindings()
                .iter()
                .zip(0..)
                .map(|((name, kind), binding)| (g.number(), binding, name.to_string(), *kind))
        })
        .collect()
}

/// Every group a pipeline file declares a global of is declared whole: its globals are the
/// group's list, name for name and binding for binding. (A stage may declare fewer groups than
/// its layout has: `logic.wgsl` reads no scene.) Every group is declared whole by some file.
#[test]
fn every_group_list_is_the_wgsl_globals_of_its_pipelines() {
    let mut declared = Vec::new();
    for (file, groups) in pipelines() {
        // The groups of a layout are numbered 0, 1, 2 … in order.
        let numbers: Vec<u32> = groups.iter().map(|g| g.number()).collect();
        assert_eq!(
            numbers,
            (0..groups.len() as u32).collect::<Vec<_>>(),
            "{file}"
        );
        let wgsl = wgsl_bindings(file);
        let mut used: Vec<u32> = wgsl.iter().map(|b| b.0).collect();
        used.dedup();
        for n in used {
            let group = groups.get(n as usize).unwrap_or_else(|| {
                panic!("{file} declares @group({n}), its layout has no such group")
            });
            let in_wgsl: Vec<_> = wgsl.iter().filter(|b| b.0 == n).cloned().collect();
            assert_eq!(
                in_wgsl,
                listed_bindings(&[*group]),
                "{file}: the WGSL globals of @group({n}) (left) and the list of {group:?} (right) differ"
            );
            println!("{file}: {group:?} matches ({} bindings)", in_wgsl.len());
            declared.push(*group);
        }
    }
    for g in Group::ALL {
        assert!(declared.contains(&g), "no pipeline file declares {g:?}");
    }
}

/// Every pipeline file under `render/` that binds the frame (an integrator stage) is listed, and
/// every group is used by some listed file.
#[test]
fn every_integrator_pipeline_is_listed() {
    for file in shader::pipeline_files().filter(|f| f.starts_with("render/")) {
        let binds_frame = wgsl_bindings(file)
            .iter()
            .any(|(g, b, name, _)| (*g, *b, name.as_str()) == (0, 0, "frame"));
        if binds_frame {
            assert!(
                pipelines().iter().any(|(f, _)| *f == file),
                "{file} is neither in PIPELINES nor a material class's stage"
            );
        }
    }
    for g in Group::ALL {
        assert!(
            pipelines().iter().any(|(_, groups)| groups.contains(&g)),
            "{g:?} is used by no pipeline"
        );
    }
}

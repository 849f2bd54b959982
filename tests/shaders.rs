//! Every WGSL file parses and validates with naga; every struct shared with Rust has, field by
//! field, the same names, offsets and sizes on both sides, and the same total size. No GPU
//! needed.

use facet_gpu::shader;

#[test]
fn every_wgsl_file_validates() {
    let files: Vec<&str> = shader::pipeline_files().collect();
    assert!(files.len() >= 3, "found {files:?}");
    for name in files {
        let src = shader::expand(name).unwrap();
        shader::validate(name, &src).unwrap_or_else(|e| panic!("{e}"));
        println!("{name}: valid");
    }
    // Every include-only file is validated as part of some pipeline file.
    let expanded: Vec<String> = shader::pipeline_files()
        .map(|n| shader::expand(n).unwrap())
        .collect();
    for (name, src) in shader::SHADERS
        .iter()
        .filter(|(n, _)| n.ends_with(".inc.wgsl"))
    {
        let first = src
            .lines()
            .find(|l| {
                ["fn ", "struct ", "const "]
                    .iter()
                    .any(|k| l.starts_with(k))
            })
            .unwrap_or_else(|| panic!("{name} declares nothing"));
        assert!(
            expanded.iter().any(|e| e.contains(first)),
            "{name} is included by no pipeline file"
        );
    }
}

#[test]
fn include_errors_name_the_file() {
    let err = shader::expand("fit/no-such-file.wgsl")
        .unwrap_err()
        .to_string();
    assert!(err.contains("fit/no-such-file.wgsl"), "{err}");
    let bad = shader::validate("broken.wgsl", "fn f() -> f32 { return x; }")
        .unwrap_err()
        .to_string();
    assert!(bad.contains("broken.wgsl") && bad.contains("x"), "{bad}");
}

/// One run of Rust fields and the run of WGSL members that holds the same bytes: usually one
/// field and the member of the same name; `cell: [u32; 2]` against `cell_x, cell_y`, say.
struct Group {
    /// (name, offset, size) of each Rust field, in order.
    rust: Vec<(&'static str, usize, usize)>,
    /// WGSL member names, in order.
    wgsl: Vec<&'static str>,
}

/// What differs between Rust struct `rust` (`rust_size` bytes, fields in `groups`) and WGSL
/// struct `wgsl` of `file` as naga lays it out; empty when they agree.
fn layout_problems(
    file: &str,
    wgsl: &str,
    rust: &str,
    rust_size: usize,
    groups: &[Group],
) -> Vec<String> {
    let module = shader::validate(file, &shader::expand(file).unwrap()).unwrap();
    let Some(layout) = shader::struct_layout(&module, wgsl) else {
        return vec![format!("{file} has no struct {wgsl} (Rust {rust})")];
    };
    let mut problems = Vec::new();
    let mut fail = |p: String| problems.push(format!("{rust} / {file} {wgsl}: {p}"));
    if rust_size != layout.size as usize {
        fail(format!("size {rust_size} in Rust, {} in WGSL", layout.size));
    }
    // Every WGSL member is listed, once, in its order.
    let listed: Vec<&str> = groups.iter().flat_map(|g| g.wgsl.iter().copied()).collect();
    let members: Vec<&str> = layout.members.iter().map(|m| m.name.as_str()).collect();
    if listed != members {
        fail(format!(
            "the WGSL members are {members:?}, the check lists {listed:?}"
        ));
        return problems;
    }
    let mut next = 0;
    for g in groups {
        let wgsl_members = &layout.members[next..next + g.wgsl.len()];
        next += g.wgsl.len();
        // Each side's run is contiguous: no bytes in between that the other side could hold.
        for w in g.rust.windows(2) {
            if w[0].1 + w[0].2 != w[1].1 {
                fail(format!(
                    "Rust fields {} and {} are not adjacent",
                    w[0].0, w[1].0
                ));
            }
        }
        for w in wgsl_members.windows(2) {
            if w[0].offset + w[0].size != w[1].offset {
                fail(format!(
                    "WGSL members {} and {} are not adjacent",
                    w[0].name, w[1].name
                ));
            }
        }
        let (first, last) = (g.rust[0], g.rust[g.rust.len() - 1]);
        let rust_range = first.1..last.1 + last.2;
        let (wf, wl) = (&wgsl_members[0], &wgsl_members[wgsl_members.len() - 1]);
        let wgsl_range = wf.offset as usize..(wl.offset + wl.size) as usize;
        if rust_range != wgsl_range {
            let names = |v: Vec<&str>| v.join(", ");
            fail(format!(
                "Rust {} at bytes {rust_range:?}, WGSL {} at bytes {wgsl_range:?}",
                names(g.rust.iter().map(|f| f.0).collect()),
                names(g.wgsl.clone()),
            ));
        }
    }
    problems
}

/// The checks of one Rust struct against its WGSL twin, each Rust field named once:
///
/// `layout_check!(Type, "file.wgsl", "WgslName", { a, b, c => [c_x, c_y], [d, e] => [de] })`
///
/// `a` is the Rust field `a` against the WGSL member `a`; `c => [..]` one Rust field against
/// several adjacent members; `[d, e] => [..]` several adjacent fields against members. A
/// pattern that destructures the struct with exactly the listed fields makes a Rust field that
/// is not listed a compile error; the WGSL members must be exactly the listed ones, in order.
/// Evaluates to (the Rust struct's name, the list of differences).
macro_rules! layout_check {
    (@munch $rust:path, $file:expr, $wgsl:expr, [$($done:tt)*]
        [$($f:ident),+ $(,)?] => [$($m:ident),+ $(,)?] $(, $($rest:tt)*)?) => {
        layout_check!(@munch $rust, $file, $wgsl, [$($done)* ([$($f),+] [$($m),+])] $($($rest)*)?)
    };
    (@munch $rust:path, $file:expr, $wgsl:expr, [$($done:tt)*]
        $f:ident => [$($m:ident),+ $(,)?] $(, $($rest:tt)*)?) => {
        layout_check!(@munch $rust, $file, $wgsl, [$($done)* ([$f] [$($m),+])] $($($rest)*)?)
    };
    (@munch $rust:path, $file:expr, $wgsl:expr, [$($done:tt)*] $f:ident $(, $($rest:tt)*)?) => {
        layout_check!(@munch $rust, $file, $wgsl, [$($done)* ([$f] [$f])] $($($rest)*)?)
    };
    (@munch $rust:path, $file:expr, $wgsl:expr, [$(([$($f:ident),+] [$($m:ident),+]))*]) => {{
        #[allow(dead_code)]
        fn every_field_is_listed(v: &$rust) {
            // A compile error here ("pattern does not mention field", or "requires `..` due
            // to inaccessible fields") is a Rust field missing from the list.
            let $rust { $($($f: _),+),* } = v;
        }
        let zero: $rust = bytemuck::Zeroable::zeroed();
        let groups = vec![$(Group {
            rust: vec![$((
                stringify!($f),
                std::mem::offset_of!($rust, $f),
                std::mem::size_of_val(&zero.$f),
            )),+],
            wgsl: vec![$(stringify!($m)),+],
        }),*];
        (
            stringify!($rust),
            layout_problems($file, $wgsl, stringify!($rust), std::mem::size_of::<$rust>(), &groups),
        )
    }};
    ($rust:path, $file:expr, $wgsl:expr, { $($body:tt)* }) => {
        layout_check!(@munch $rust, $file, $wgsl, [] $($body)*)
    };
}

/// Every Rust struct uploaded to or read back from a WGSL buffer, with its WGSL twin. The
/// struct is named by its last path segment (`every_repr_c_struct_is_checked` finds the
/// `#[repr(C)]` structs by that name).
fn shared_struct_checks() -> Vec<(&'static str, Vec<String>)> {
    use facet_fit::gpu::{GpuNode, GpuState};
    use facet_glint::cone_rule::Ring;
    use facet_glint::gpu::{DpfParams, GlintEvalParams, GlintEvalQuery, GlintField, GlintQuery};
    use facet_render::bvh::query::{GpuHit, GpuRay};
    use facet_render::layout::gpu_types::{GpuFrame, GpuLight, GpuSceneInfo};
    use facet_render::materials::GpuMaterial;
    use facet_render::obvhs::cwbvh::node::CwBvhNode;
    use facet_render::output::tonemap::ToneMapParams;
    use facet_render::resources::light_bvh::GpuLightNode;
    vec![
        layout_check!(GpuNode, "fit/kernel.wgsl", "Node", {
            x, y, z, row_scale, col_weight, norm_weight, pad0, pad1,
        }),
        layout_check!(GpuState, "fit/normalise_reduce.wgsl", "State", {
            iteration, lambda, pad0, pad1,
        }),
        layout_check!(DpfParams, "glint/dpf_build.wgsl", "Params", {
            n_theta, n_dphi, n_rings, ndf_kind, alpha_x, alpha_y, rotation,
            table_nu, table_nphi, n_radial, n_angular, n_tail_angular, gamma, lobe_width, pad0,
            pad1,
        }),
        layout_check!(Ring, "glint/dpf_build.wgsl", "Ring", {
            cos_psi, sin_psi, weight, n_chi,
        }),
        layout_check!(GlintField, "glint/glint_count.wgsl", "Field", {
            density, seed, root_count, filtered, threshold, blend, table_levels, pad,
        }),
        layout_check!(GlintQuery, "glint/glint_count.wgsl", "Query", {
            center, a, b, p, coords0, coords1,
        }),
        layout_check!(GlintEvalParams, "glint/glint_eval.wgsl", "EvalParams", {
            gamma, sigma, sigma0, sigma1, level_t, n_theta, n_dphi, ndf_kind, alpha_x,
            alpha_y, rotation, pad0,
        }),
        layout_check!(GlintEvalQuery, "glint/glint_eval.wgsl", "EvalQuery", {
            wi, wo, center, a, b, pad,
        }),
        layout_check!(GpuFrame, "render/extend.wgsl", "Frame", {
            width, height, tile_base, tile_pixels, wavefront, sample_end, max_depth, seed,
            rr_depth, ray_epsilon, strategy, ndf_sampling, moments, sequence, pad1, pad2, scene,
            cam_pos, cam_forward, cam_up, cam_right,
        }),
        layout_check!(GpuSceneInfo, "render/extend.wgsl", "SceneInfo", {
            n_vertices, n_lights, light_cdf, env_kind, env_width, env_height, env_texels,
            env_marginal, env_conditional, scene_radius, light_tree_share, light_tree_nodes,
            env_color,
        }),
        layout_check!(GpuMaterial, "render/extend.wgsl", "Material", {
            emissive, tex_emissive, tex_normal, normal_scale, queue, coat, block,
        }),
        layout_check!(GpuLight, "render/extend.wgsl", "Light", {
            kind, prim, cos_inner, cos_outer, position, direction, intensity, leaf, pad0, pad1,
            pad2,
        }),
        layout_check!(GpuLightNode, "render/extend.wgsl", "LightNode", {
            centre_phi, axis_cos_o, radius, cos_e, sin_o, child, parent, leaf, pad0, pad1,
        }),
        layout_check!(ToneMapParams, "render/tonemap.wgsl", "Params", {
            pixels, scale, pad0, pad1,
        }),
        layout_check!(GpuRay, "render/trace_closest.wgsl", "Ray", { origin, tmin, dir, tmax }),
        layout_check!(GpuHit, "render/trace_closest.wgsl", "Hit", { t, prim, u, v }),
        // obvhs's node is uploaded as it is: WGSL CwNode packs its u8 fields into u32 words;
        // e[0..3] and imask are the bytes of e_imask.
        layout_check!(CwBvhNode, "render/trace_closest.wgsl", "CwNode", {
                p, [e, imask] => [e_imask], child_base_idx, primitive_base_idx, child_meta,
            child_min_x, child_max_x, child_min_y, child_max_y, child_min_z, child_max_z,
        }),
    ]
}

#[test]
fn shared_structs_match_naga_field_by_field() {
    let checks = shared_struct_checks();
    let problems: Vec<&String> = checks.iter().flat_map(|(_, p)| p).collect();
    for (name, p) in &checks {
        println!(
            "{name}: {}",
            if p.is_empty() { "matches" } else { "DIFFERS" }
        );
    }
    assert!(
        problems.is_empty(),
        "Rust and WGSL layouts differ:\n{}",
        problems
            .iter()
            .map(|p| p.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
    // imask is the byte after e[0..3], the top byte of the e_imask word.
    use facet_render::obvhs::cwbvh::node::CwBvhNode;
    assert_eq!(
        std::mem::offset_of!(CwBvhNode, imask),
        std::mem::offset_of!(CwBvhNode, e) + 3
    );
}

/// Every `#[repr(C)]` struct in the crates' sources is in [`shared_struct_checks`] (they are
/// all shared with WGSL; one that is not would be named here with the reason).
#[test]
fn every_repr_c_struct_is_checked() {
    fn rust_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                rust_files(&p, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    for krate in std::fs::read_dir(root.join("crates")).unwrap() {
        rust_files(&krate.unwrap().path().join("src"), &mut files);
    }
    let checked: Vec<&str> = shared_struct_checks().iter().map(|(n, _)| *n).collect();
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let lines: Vec<&str> = text.lines().map(str::trim).collect();
        for (i, l) in lines.iter().enumerate() {
            if !l.starts_with("#[repr(C") {
                continue;
            }
            // The item after the attributes and doc comments that follow.
            let item = lines[i + 1..]
                .iter()
                .find(|l| !l.starts_with("#[") && !l.starts_with("///"))
                .unwrap();
            // A macro's template (`pub struct $name`): facet-render's class blocks, whose WGSL
            // is generated from them and whose size is asserted where they are declared.
            if let Some(rest) = item
                .strip_prefix("pub struct ")
                .or(item.strip_prefix("struct "))
                .filter(|r| !r.starts_with('$'))
            {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                found.push((name, f.strip_prefix(root).unwrap().display().to_string()));
            }
        }
    }
    assert!(found.len() >= 13, "found only {found:?}");
    let missing: Vec<_> = found
        .iter()
        .filter(|(n, _)| !checked.contains(&n.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "#[repr(C)] structs without a field-by-field layout check in shared_struct_checks: {missing:?}"
    );
}

/// The value of `const NAME: u32 = …u;` in shader file `file`.
fn wgsl_u32_const(file: &str, name: &str) -> u32 {
    let src = facet_gpu::shader::raw_source(file).expect(file);
    let prefix = format!("const {name}: u32 =");
    let line = src
        .lines()
        .find(|l| l.trim_start().starts_with(&prefix))
        .unwrap_or_else(|| panic!("{file}: a `{prefix} …u;` line"));
    line.split('=')
        .nth(1)
        .and_then(|v| {
            v.trim()
                .trim_end_matches(';')
                .trim_end_matches('u')
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("{file}: {name} is not an integer"))
}

/// The glint walk's stack holds what the quadtree needs and no more: 3 · MAX_DEPTH + 1 nodes
/// (facet_glint::lit::STACK_DEPTH), written as a WGSL `const` because a private array's size
/// cannot be an override.
#[test]
fn glint_stack_is_sized_to_the_tree() {
    assert_eq!(
        wgsl_u32_const("glint/lit.inc.wgsl", "STACK"),
        facet_glint::lit::STACK_DEPTH
    );
}

/// The BVH traversal's stack has the depth the host counts with (a private array's size cannot
/// be an override).
#[test]
fn bvh_stack_is_the_hosts() {
    assert_eq!(
        wgsl_u32_const("render/bvh.inc.wgsl", "BVH_STACK_SIZE"),
        facet_render::bvh::query::STACK_ENTRIES
    );
}

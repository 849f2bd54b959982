//! Every WGSL file parses and validates with naga; every struct shared with Rust has the same
//! size and offsets on both sides. No GPU needed.

use facet_fit::gpu::{GpuNode, GpuSample, GpuState};
use facet_gpu::shader;
use std::mem::{offset_of, size_of};

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
            .find(|l| l.starts_with("fn ") || l.starts_with("struct "))
            .unwrap();
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

fn layout(file: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module = shader::validate(file, &shader::expand(file).unwrap()).unwrap();
    shader::struct_layout(&module, name).unwrap_or_else(|| panic!("{file} has no struct {name}"))
}

#[test]
fn shared_structs_match_naga_layouts() {
    let (size, members) = layout("fit/kernel.wgsl", "Node");
    assert_eq!(size as usize, size_of::<GpuNode>());
    let rust = [
        ("x", offset_of!(GpuNode, x)),
        ("y", offset_of!(GpuNode, y)),
        ("z", offset_of!(GpuNode, z)),
        ("row_scale", offset_of!(GpuNode, row_scale)),
        ("col_weight", offset_of!(GpuNode, col_weight)),
        ("norm_weight", offset_of!(GpuNode, norm_weight)),
    ];
    for (name, off) in rust {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Node.{name}: {members:?}"
        );
    }
    let (size, members) = layout("fit/normalise.wgsl", "State");
    assert_eq!(size as usize, size_of::<GpuState>());
    assert!(members.contains(&("iteration".into(), offset_of!(GpuState, iteration) as u32)));
    assert!(members.contains(&("lambda".into(), offset_of!(GpuState, lambda) as u32)));
    let (size, members) = layout("fit/fresnel.wgsl", "Sample");
    assert_eq!(size as usize, size_of::<GpuSample>());
    let rust = [
        ("x", offset_of!(GpuSample, x)),
        ("i", offset_of!(GpuSample, i)),
        ("gi", offset_of!(GpuSample, gi)),
        ("go", offset_of!(GpuSample, go)),
        ("inv_cos_i", offset_of!(GpuSample, inv_cos_i)),
        ("inv_cos_o", offset_of!(GpuSample, inv_cos_o)),
        ("corr", offset_of!(GpuSample, corr)),
    ];
    for (name, off) in rust {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Sample.{name}: {members:?}"
        );
    }
}

#[test]
fn dpf_params_match_naga() {
    use facet_glint::gpu::DpfParams;
    let (size, members) = layout("glint/dpf_build.wgsl", "Params");
    assert_eq!(size as usize, size_of::<DpfParams>());
    for (name, off) in [
        ("n_theta", offset_of!(DpfParams, n_theta)),
        ("gamma", offset_of!(DpfParams, gamma)),
        ("ndf_kind", offset_of!(DpfParams, ndf_kind)),
        ("rotation", offset_of!(DpfParams, rotation)),
        ("table_nphi", offset_of!(DpfParams, table_nphi)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Params.{name}: {members:?}"
        );
    }
}

#[test]
fn glint_structs_match_naga() {
    use facet_glint::gpu::{GlintField, GlintQuery};
    let (size, members) = layout("glint/glint_count.wgsl", "Field");
    assert_eq!(size as usize, size_of::<GlintField>());
    for (name, off) in [
        ("density", offset_of!(GlintField, density)),
        ("root_count", offset_of!(GlintField, root_count)),
        ("threshold", offset_of!(GlintField, threshold)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Field.{name}: {members:?}"
        );
    }
    let (size, members) = layout("glint/glint_count.wgsl", "Query");
    assert_eq!(size as usize, size_of::<GlintQuery>());
    for (name, off) in [
        ("center", offset_of!(GlintQuery, center)),
        ("a", offset_of!(GlintQuery, a)),
        ("b", offset_of!(GlintQuery, b)),
        ("p", offset_of!(GlintQuery, p)),
        ("cell_x", offset_of!(GlintQuery, cell)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Query.{name}: {members:?}"
        );
    }
}

#[test]
fn glint_eval_structs_match_naga() {
    use facet_glint::gpu::{GlintEvalParams, GlintEvalQuery};
    let (size, members) = layout("glint/glint_eval.wgsl", "EvalParams");
    assert_eq!(size as usize, size_of::<GlintEvalParams>());
    for (name, off) in [
        ("sigma1", offset_of!(GlintEvalParams, sigma1)),
        ("level_t", offset_of!(GlintEvalParams, level_t)),
        ("ndf_kind", offset_of!(GlintEvalParams, ndf_kind)),
        ("rotation", offset_of!(GlintEvalParams, rotation)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "EvalParams.{name}: {members:?}"
        );
    }
    let (size, members) = layout("glint/glint_eval.wgsl", "EvalQuery");
    assert_eq!(size as usize, size_of::<GlintEvalQuery>());
    for (name, off) in [
        ("wo", offset_of!(GlintEvalQuery, wo)),
        ("center", offset_of!(GlintEvalQuery, center)),
        ("b", offset_of!(GlintEvalQuery, b)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "EvalQuery.{name}: {members:?}"
        );
    }
}

/// Every member of a WGSL struct at the offset of the Rust field of the same name.
macro_rules! check_struct {
    ($file:expr, $wgsl:expr, $rust:ty, [$($field:ident),* $(,)?]) => {{
        let (size, members) = layout($file, $wgsl);
        assert_eq!(size as usize, size_of::<$rust>(), "{} size", $wgsl);
        $(
            assert!(
                members.contains(&(stringify!($field).to_string(), offset_of!($rust, $field) as u32)),
                "{}.{}: {members:?}", $wgsl, stringify!($field)
            );
        )*
        assert_eq!(members.len(), [$(stringify!($field)),*].len(), "{} members: {members:?}", $wgsl);
    }};
}

#[test]
fn render_structs_match_naga() {
    use facet_render::gpu_types::{GpuFrame, GpuLight, GpuMaterial};
    check_struct!(
        "render/extend.wgsl",
        "Frame",
        GpuFrame,
        [
            width,
            height,
            tile_base,
            tile_pixels,
            wavefront,
            sample_end,
            max_depth,
            seed,
            rr_depth,
            n_vertices,
            n_lights,
            light_cdf,
            env_kind,
            env_width,
            env_height,
            env_texels,
            env_marginal,
            env_conditional,
            scene_radius,
            ray_epsilon,
            env_color,
            cam_pos,
            cam_forward,
            cam_up,
            cam_right
        ]
    );
    check_struct!(
        "render/extend.wgsl",
        "Material",
        GpuMaterial,
        [
            base_color,
            emissive,
            diffuse,
            kind,
            ndf_kind,
            alpha_x,
            alpha_y,
            rotation,
            metallic,
            roughness,
            normal_scale,
            tex_base,
            tex_mr,
            tex_normal,
            tex_emissive,
            fresnel_offset,
            fresnel_count,
            tab_offset,
            queue
        ]
    );
    check_struct!(
        "render/extend.wgsl",
        "Light",
        GpuLight,
        [
            kind, prim, cos_inner, cos_outer, position, direction, intensity
        ]
    );
}

#[test]
fn trace_structs_match_naga() {
    use facet_render::obvhs::cwbvh::node::CwBvhNode;
    use facet_render::trace::{GpuHit, GpuRay};
    let file = "render/trace.wgsl";
    let (size, members) = layout(file, "Ray");
    assert_eq!(size as usize, size_of::<GpuRay>());
    for (name, off) in [
        ("origin", offset_of!(GpuRay, origin)),
        ("tmin", offset_of!(GpuRay, tmin)),
        ("dir", offset_of!(GpuRay, dir)),
        ("tmax", offset_of!(GpuRay, tmax)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Ray.{name}: {members:?}"
        );
    }
    let (size, members) = layout(file, "Hit");
    assert_eq!(size as usize, size_of::<GpuHit>());
    for (name, off) in [
        ("t", offset_of!(GpuHit, t)),
        ("prim", offset_of!(GpuHit, prim)),
        ("u", offset_of!(GpuHit, u)),
        ("v", offset_of!(GpuHit, v)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "Hit.{name}: {members:?}"
        );
    }
    // obvhs's node is uploaded as it is: WGSL CwNode packs its u8 fields into u32 words.
    let (size, members) = layout(file, "CwNode");
    assert_eq!(size as usize, size_of::<CwBvhNode>());
    for (name, off) in [
        ("p", offset_of!(CwBvhNode, p)),
        ("e_imask", offset_of!(CwBvhNode, e)),
        ("child_base_idx", offset_of!(CwBvhNode, child_base_idx)),
        (
            "primitive_base_idx",
            offset_of!(CwBvhNode, primitive_base_idx),
        ),
        ("child_meta", offset_of!(CwBvhNode, child_meta)),
        ("child_min_x", offset_of!(CwBvhNode, child_min_x)),
        ("child_max_x", offset_of!(CwBvhNode, child_max_x)),
        ("child_min_y", offset_of!(CwBvhNode, child_min_y)),
        ("child_max_y", offset_of!(CwBvhNode, child_max_y)),
        ("child_min_z", offset_of!(CwBvhNode, child_min_z)),
        ("child_max_z", offset_of!(CwBvhNode, child_max_z)),
    ] {
        assert!(
            members.contains(&(name.to_string(), off as u32)),
            "CwNode.{name}: {members:?}"
        );
    }
    // imask is the byte after e[0..3], the top byte of the e_imask word.
    assert_eq!(offset_of!(CwBvhNode, imask), offset_of!(CwBvhNode, e) + 3);
}

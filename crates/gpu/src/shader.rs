//! WGSL from `shaders/` (embedded at build time): `#include "path"` expansion, naga validation
//! with errors that name the file, compute pipelines, and struct layouts as naga computes them.
//!
//! Files ending in `.inc.wgsl` are include-only. An include line is `#include "common/x.inc.wgsl"`
//! on a line of its own; each file is included once. Constants shared with Rust are WGSL
//! `override`s, set through [`compute_pipeline`]'s `constants`.

use crate::error::GpuError;
use std::collections::{HashMap, HashSet};

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// The raw text of a shader file.
pub fn raw_source(name: &str) -> Option<&'static str> {
    SHADERS.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Every shader file, includes too.
pub fn all_files() -> impl Iterator<Item = &'static str> {
    SHADERS.iter().map(|(n, _)| *n)
}

/// Every pipeline (non-include) shader file.
pub fn pipeline_files() -> impl Iterator<Item = &'static str> {
    SHADERS
        .iter()
        .map(|(n, _)| *n)
        .filter(|n| !n.ends_with(".inc.wgsl"))
}

/// `name` with its includes expanded.
pub fn expand(name: &str) -> Result<String, GpuError> {
    let mut out = String::new();
    let mut seen = HashSet::new();
    expand_into(name, &mut out, &mut seen, 0)?;
    Ok(out)
}

fn expand_into(
    name: &str,
    out: &mut String,
    seen: &mut HashSet<String>,
    depth: usize,
) -> Result<(), GpuError> {
    let err = |message: String| GpuError::Shader {
        name: name.to_owned(),
        message,
    };
    if depth > 16 {
        return Err(err("includes nest deeper than 16".into()));
    }
    if !seen.insert(name.to_owned()) {
        return Ok(());
    }
    let src = raw_source(name).ok_or_else(|| err("no such file under shaders/".into()))?;
    for line in src.lines() {
        match line.trim().strip_prefix("#include") {
            Some(rest) => {
                let inc = rest.trim().trim_matches('"');
                expand_into(inc, out, seen, depth + 1).map_err(|e| match e {
                    GpuError::Shader { name: n, message } => err(format!("in {n}: {message}")),
                    other => other,
                })?;
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    Ok(())
}

/// Parses and validates expanded WGSL with naga. On failure the expanded source is written to
/// the temporary folder and named in the error.
pub fn validate(name: &str, source: &str) -> Result<naga::Module, GpuError> {
    let fail = |message: String| {
        let dump = std::env::temp_dir().join(format!("facet-{}", name.replace('/', "_")));
        let _ = std::fs::write(&dump, source);
        GpuError::Shader {
            name: name.to_owned(),
            message: format!("{message}\n(expanded source: {})", dump.display()),
        }
    };
    let module =
        naga::front::wgsl::parse_str(source).map_err(|e| fail(e.emit_to_string(source)))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| fail(e.emit_to_string(source)))?;
    Ok(module)
}

/// A compute pipeline for entry point `entry` of shader file `name`, with override constants.
pub fn compute_pipeline(
    device: &wgpu::Device,
    name: &str,
    entry: &str,
    constants: &[(&str, f64)],
) -> Result<wgpu::ComputePipeline, GpuError> {
    compute_pipeline_with_layout(device, name, entry, None, constants)
}

/// [`compute_pipeline`] with an explicit pipeline layout (None: derived from the shader), for
/// stages that share bind groups.
pub fn compute_pipeline_with_layout(
    device: &wgpu::Device,
    name: &str,
    entry: &str,
    layout: Option<&wgpu::PipelineLayout>,
    constants: &[(&str, f64)],
) -> Result<wgpu::ComputePipeline, GpuError> {
    let source = expand(name)?;
    validate(name, &source)?;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let constants: HashMap<String, f64> =
        constants.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    let constants: Vec<(&str, f64)> = constants.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    Ok(
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout,
            module: &module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        }),
    )
}

/// A WGSL struct's layout as naga computes it (WGSL's alignment and size rules).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StructLayout {
    /// The struct's size in bytes (its span, trailing padding included).
    pub size: u32,
    /// The members in declaration order.
    pub members: Vec<MemberLayout>,
}

/// One member of a [`StructLayout`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemberLayout {
    /// The member's name.
    pub name: String,
    /// Byte offset in the struct.
    pub offset: u32,
    /// Size of the member's type in bytes (what the host must write there; padding after it,
    /// from alignment or `@size`, is not included).
    pub size: u32,
}

/// The layout of struct `name` of `module`, `None` if it has no such struct (or naga cannot
/// lay its types out).
pub fn struct_layout(module: &naga::Module, name: &str) -> Option<StructLayout> {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).ok()?;
    module.types.iter().find_map(|(_, ty)| match &ty.inner {
        naga::TypeInner::Struct { members, span } if ty.name.as_deref() == Some(name) => {
            Some(StructLayout {
                size: *span,
                members: members
                    .iter()
                    .map(|m| MemberLayout {
                        name: m.name.clone().unwrap_or_default(),
                        offset: m.offset,
                        size: layouter[m.ty].size,
                    })
                    .collect(),
            })
        }
        _ => None,
    })
}

/// `@workgroup_size` x of entry point `entry` of shader file `name`, as naga reads it: drivers
/// take it from the shader, where it is written once.
pub fn workgroup_size(name: &str, entry: &str) -> Result<u32, GpuError> {
    let module = validate(name, &expand(name)?)?;
    module
        .entry_points
        .iter()
        .find(|e| e.name == entry)
        .map(|e| e.workgroup_size[0])
        .ok_or_else(|| GpuError::Shader {
            name: name.into(),
            message: format!("no entry point {entry}"),
        })
}

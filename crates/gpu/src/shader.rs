//! WGSL from `shaders/` (embedded at build time): `#include "path"` expansion, naga validation
//! against WebGPU core ([`WEBGPU_CORE`]) with errors that name the file, compute pipelines, and
//! struct layouts as naga computes them.
//!
//! Files ending in `.inc.wgsl` are include-only. An include line is `#include "common/x.inc.wgsl"`
//! on a line of its own (a path relative to `shaders/`); it is replaced by that file, expanded in
//! turn, the first time the file is reached and by nothing after that, so a file may include what
//! it uses without the includer's order mattering (WGSL declarations may come in any order).
//! Constants shared with Rust are WGSL `override`s, set through [`compute_pipeline`]'s
//! `constants`, or closed sets generated into a committed include ([`tags`](mod@crate::tags)).

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
    expand_from(name, &raw_source)
}

/// [`expand`] over the files `source` returns (the embedded `shaders/` for [`expand`]).
fn expand_from<'a>(
    name: &str,
    source: &dyn Fn(&str) -> Option<&'a str>,
) -> Result<String, GpuError> {
    let mut out = String::new();
    let mut seen = HashSet::new();
    expand_into(name, source, &mut out, &mut seen, 0)?;
    Ok(out)
}

fn expand_into<'a>(
    name: &str,
    source: &dyn Fn(&str) -> Option<&'a str>,
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
    let src = source(name).ok_or_else(|| err("no such file under shaders/".into()))?;
    for line in src.lines() {
        match line.trim().strip_prefix("#include") {
            Some(rest) => {
                let inc = rest.trim().trim_matches('"');
                expand_into(inc, source, out, seen, depth + 1).map_err(|e| match e {
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

/// The naga capabilities of a WebGPU-core device: what wgpu grants a device with no optional
/// feature on an adapter with every downlevel flag (`wgpu_naga_bridge::
/// features_to_naga_capabilities`). Facet asks for no shader feature outside WebGPU core, so
/// every shader validates with these and no more.
pub const WEBGPU_CORE: naga::valid::Capabilities = naga::valid::Capabilities::MULTISAMPLED_SHADING
    .union(naga::valid::Capabilities::CUBE_ARRAY_TEXTURES)
    .union(naga::valid::Capabilities::SHADER_FLOAT16_IN_FLOAT32);

/// Parses and validates expanded WGSL with naga, allowing only [`WEBGPU_CORE`]. On failure the expanded source is written to
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
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), WEBGPU_CORE)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Expands `name` over in-memory (name, text) files.
    fn expand_files(name: &str, files: &[(&str, &str)]) -> Result<String, GpuError> {
        expand_from(name, &|n: &str| {
            files.iter().find(|(f, _)| *f == n).map(|(_, s)| *s)
        })
    }

    fn shader_error(e: GpuError) -> (String, String) {
        match e {
            GpuError::Shader { name, message } => (name, message),
            other => panic!("not a shader error: {other}"),
        }
    }

    #[test]
    fn an_include_line_is_replaced_by_the_file_in_place() {
        let out = expand_files(
            "main.wgsl",
            &[
                ("main.wgsl", "// top\n#include \"a.inc.wgsl\"\nfn main() {}"),
                ("a.inc.wgsl", "const A: u32 = 1u;\n"),
            ],
        )
        .unwrap();
        assert_eq!(out, "// top\nconst A: u32 = 1u;\nfn main() {}\n");
    }

    #[test]
    fn includes_nest_and_each_file_comes_once() {
        // main → a → c, main → b → c, main → a again: c and a appear once, at first use.
        let out = expand_files(
            "main.wgsl",
            &[
                (
                    "main.wgsl",
                    "#include \"a.inc.wgsl\"\n#include \"b.inc.wgsl\"\n#include \"a.inc.wgsl\"\nmain",
                ),
                ("a.inc.wgsl", "#include \"c.inc.wgsl\"\na"),
                ("b.inc.wgsl", "#include \"c.inc.wgsl\"\nb"),
                ("c.inc.wgsl", "c"),
            ],
        )
        .unwrap();
        assert_eq!(out, "c\na\nb\nmain\n");
    }

    #[test]
    fn an_include_cycle_ends_at_the_first_repeat() {
        let out = expand_files(
            "a.wgsl",
            &[
                ("a.wgsl", "#include \"b.inc.wgsl\"\na"),
                ("b.inc.wgsl", "#include \"a.wgsl\"\nb"),
            ],
        )
        .unwrap();
        assert_eq!(out, "b\na\n");
    }

    #[test]
    fn indentation_and_surrounding_spaces_are_allowed() {
        let out = expand_files(
            "main.wgsl",
            &[
                ("main.wgsl", "  #include   \"a.inc.wgsl\"  \r\nx"),
                ("a.inc.wgsl", "a"),
            ],
        )
        .unwrap();
        assert_eq!(out, "a\nx\n");
    }

    #[test]
    fn an_include_in_a_comment_or_after_code_is_text() {
        let src = "// #include \"missing.wgsl\"\nlet x = 1; #include \"missing.wgsl\"";
        let out = expand_files("main.wgsl", &[("main.wgsl", src)]).unwrap();
        assert_eq!(out, format!("{src}\n"));
    }

    #[test]
    fn a_missing_include_names_the_file_and_its_includers() {
        let e = expand_files(
            "main.wgsl",
            &[
                ("main.wgsl", "#include \"a.inc.wgsl\""),
                ("a.inc.wgsl", "#include \"gone.inc.wgsl\""),
            ],
        )
        .unwrap_err();
        let (name, message) = shader_error(e);
        assert_eq!(name, "main.wgsl");
        assert_eq!(
            message,
            "in a.inc.wgsl: in gone.inc.wgsl: no such file under shaders/"
        );
        let (name, message) = shader_error(expand_files("nothing.wgsl", &[]).unwrap_err());
        assert_eq!(name, "nothing.wgsl");
        assert_eq!(message, "no such file under shaders/");
    }

    #[test]
    fn includes_deeper_than_16_are_refused() {
        // f0 includes f1, …, f16 includes f17.
        let texts: Vec<(String, String)> = (0..=17)
            .map(|i| {
                let body = if i < 17 {
                    format!("#include \"f{}.wgsl\"", i + 1)
                } else {
                    "end".to_string()
                };
                (format!("f{i}.wgsl"), body)
            })
            .collect();
        let files: Vec<(&str, &str)> = texts
            .iter()
            .map(|(n, b)| (n.as_str(), b.as_str()))
            .collect();
        // 16 levels below the root are fine, 17 are not.
        assert_eq!(expand_files("f1.wgsl", &files).unwrap(), "end\n");
        let (_, message) = shader_error(expand_files("f0.wgsl", &files).unwrap_err());
        assert!(
            message.ends_with("includes nest deeper than 16"),
            "{message}"
        );
    }
}

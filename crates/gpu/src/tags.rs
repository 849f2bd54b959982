//! Closed sets shared by Rust and WGSL, written once in Rust.
//!
//! [`tags!`](crate::tags!) declares a `#[repr(u32)]` enum whose variants are also WGSL
//! constants, `PREFIX` + name. A crate gathers its sets ([`TagSet`]), renders them with [`wgsl`]
//! into a WGSL include it commits beside its shaders, and checks in a test that the committed
//! file is the generated one, that naga reads the Rust values back ([`u32_constants`]) and that
//! no other WGSL file defines a constant with one of the prefixes ([`defined_elsewhere`]).
//!
//! ```
//! facet_gpu::tags!(
//!     /// Fruit kinds.
//!     Fruit, "FRUIT_" {
//!         /// a round one
//!         Apple = 0 => "APPLE",
//!         Pear = 1 => "PEAR",
//!     }
//! );
//! let text = facet_gpu::tags::wgsl("my_crate::tags", "src/tags.rs", "my-crate", &[Fruit::tag_set()]);
//! assert!(text.contains("const FRUIT_APPLE: u32 = 0u; // a round one\n"));
//! assert_eq!(facet_gpu::tags::u32_constants(&text).unwrap()["FRUIT_PEAR"], 1);
//! ```

use crate::error::GpuError;
use std::collections::HashMap;

/// Declares a `#[repr(u32)]` enum whose variants are WGSL constants `PREFIX` + name (the
/// [module](mod@crate::tags)'s example shows the form). The enum gets `ALL`, `WGSL_PREFIX`,
/// `wgsl_name`, `doc` (a variant's first doc line, the WGSL comment) and `tag_set` (for
/// [`tags::wgsl`](crate::tags::wgsl)). Doc comments are taken on the enum and on each variant;
/// other attributes on the enum only.
#[macro_export]
macro_rules! tags {
    ($(#[$meta:meta])* $name:ident, $prefix:literal {
        $($(#[doc = $doc:literal])* $variant:ident = $value:literal => $wgsl:literal,)+
    }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u32)]
        pub enum $name {
            $($(#[doc = $doc])* $variant = $value,)+
        }

        impl $name {
            /// Every tag, in value order.
            pub const ALL: &[$name] = &[$($name::$variant),+];
            /// The prefix of the WGSL constants' names.
            pub const WGSL_PREFIX: &str = $prefix;

            /// The WGSL constant's name.
            pub const fn wgsl_name(self) -> &'static str {
                match self {
                    $($name::$variant => concat!($prefix, $wgsl),)+
                }
            }

            /// The first line of the variant's doc, for the WGSL comment.
            pub const fn doc(self) -> &'static str {
                match self {
                    $($name::$variant => $crate::tags!(@first $($doc)*),)+
                }
            }

            /// The set, for the generated WGSL.
            pub fn tag_set() -> $crate::tags::TagSet {
                $crate::tags::TagSet {
                    rust: stringify!($name),
                    prefix: $prefix,
                    tags: Self::ALL
                        .iter()
                        .map(|&v| (v.wgsl_name(), v as u32, v.doc()))
                        .collect(),
                }
            }
        }
    };
    (@first) => { "" };
    (@first $first:literal $($rest:literal)*) => { $first };
}

/// One tag enum: its Rust name, its WGSL prefix and its (WGSL name, value, doc) constants.
pub struct TagSet {
    /// The Rust enum's name.
    pub rust: &'static str,
    /// The WGSL constants' prefix.
    pub prefix: &'static str,
    /// (WGSL name, value, doc) of each tag.
    pub tags: Vec<(&'static str, u32, &'static str)>,
}

/// The WGSL include of `sets`, declared in Rust module `module` (file `source`) of package
/// `package`: a header that says so and how to regenerate it (`FACET_REGENERATE=1 cargo test
/// -p <package> --test tags`), then one `const NAME: u32 = value;` a tag, set by set.
pub fn wgsl(module: &str, source: &str, package: &str, sets: &[TagSet]) -> String {
    let mut s = format!(
        "// Include-only. Generated from {module} ({source}): do not edit;\n\
         // `FACET_REGENERATE=1 cargo test -p {package} --test tags` rewrites it.\n"
    );
    for set in sets {
        s += &format!("\n// {module}::{}\n", set.rust);
        for (name, value, doc) in &set.tags {
            s += &format!("const {name}: u32 = {value}u; // {}\n", doc.trim());
        }
    }
    s
}

/// Every `u32` constant of WGSL source `source` and its value, as naga parses them.
pub fn u32_constants(source: &str) -> Result<HashMap<String, u32>, GpuError> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| GpuError::Shader {
        name: "(tags)".into(),
        message: e.emit_to_string(source),
    })?;
    let mut found = HashMap::new();
    for (_, c) in module.constants.iter() {
        if let (Some(name), naga::Expression::Literal(naga::Literal::U32(v))) =
            (&c.name, &module.global_expressions[c.init])
        {
            found.insert(name.clone(), *v);
        }
    }
    Ok(found)
}

/// `file:line: text` of each `const` or `override` whose name starts with one of `prefixes`, in
/// every shader file but `file` (the generated one).
pub fn defined_elsewhere(file: &str, prefixes: &[&str]) -> Vec<String> {
    let mut offenders = Vec::new();
    for name in crate::shader::all_files().filter(|&n| n != file) {
        let src = crate::shader::raw_source(name).unwrap_or_default();
        for (i, line) in src.lines().enumerate() {
            let l = line.trim_start();
            for keyword in ["const ", "override "] {
                if let Some(rest) = l.strip_prefix(keyword)
                    && prefixes.iter().any(|p| rest.starts_with(p))
                {
                    offenders.push(format!("{name}:{}: {l}", i + 1));
                }
            }
        }
    }
    offenders
}

/// The checks every generated tags file passes, for the `tags` test of the crate that owns it:
/// `shaders_dir/file` is exactly `generated` (rewritten first under `FACET_REGENERATE=1`),
/// naga reads back from it the values of `sets` and no other constant, and no other shader file
/// defines a constant with one of the sets' prefixes (a second definition could drift from
/// Rust). Returns the problems found, none when all hold.
pub fn check_generated(
    shaders_dir: &std::path::Path,
    file: &str,
    generated: &str,
    sets: &[TagSet],
) -> Vec<String> {
    let mut problems = Vec::new();
    let path = shaders_dir.join(file);
    if std::env::var_os("FACET_REGENERATE").is_some()
        && let Err(e) = std::fs::write(&path, generated)
    {
        problems.push(format!("{}: cannot rewrite it: {e}", path.display()));
    }
    match std::fs::read_to_string(&path) {
        Ok(committed) if committed == generated => {}
        Ok(_) => problems.push(format!(
            "{} is not the generated text; rerun with FACET_REGENERATE=1",
            path.display()
        )),
        Err(e) => problems.push(format!("{}: {e}", path.display())),
    }
    match u32_constants(generated) {
        Ok(found) => {
            let mut n = 0;
            for set in sets {
                for (name, value, _) in &set.tags {
                    if found.get(*name) != Some(value) {
                        problems.push(format!(
                            "{}: {name} is {:?} in the WGSL, {value} in Rust",
                            set.rust,
                            found.get(*name)
                        ));
                    }
                    n += 1;
                }
            }
            if found.len() != n {
                problems.push(format!(
                    "constants in {file} that no Rust tag has: {found:?}"
                ));
            }
        }
        Err(e) => problems.push(e.to_string()),
    }
    let prefixes: Vec<&str> = sets.iter().map(|t| t.prefix).collect();
    for offender in defined_elsewhere(file, &prefixes) {
        problems.push(format!("a tag defined outside {file}: {offender}"));
    }
    problems
}

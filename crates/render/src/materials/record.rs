//! The material record on the GPU: a header every class shares (emission, normal map, queue,
//! coat layer) and a class block of 16 words whose fields the class defines with
//! [`class_block!`](crate::class_block). A block's WGSL struct and its decoder are generated
//! from the Rust struct ([`wgsl`]), so the two sides cannot disagree on an offset: the committed
//! `shaders/render/materials/blocks.inc.wgsl` is the generated text (`cargo test -p
//! facet-render --test tags` fails when the two differ; `FACET_REGENERATE=1` rewrites it).

use crate::layout::gpu_types::NONE;
use bytemuck::{Pod, Zeroable};

/// Words in a material's class block.
pub const BLOCK_WORDS: usize = 16;

/// WGSL `Material` (`shaders/render/scene.inc.wgsl`): the header and the class block.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Emitted radiance (rgb).
    pub emissive: [f32; 3],
    /// The emission's texture (NONE: none).
    pub tex_emissive: u32,
    /// The tangent-space normal map (NONE: none) and its xy scale.
    pub tex_normal: u32,
    /// The normal map's xy scale.
    pub normal_scale: f32,
    /// The shading queue its hits go to.
    pub queue: u32,
    /// The coat layer's block in the scene tables (NONE: no coat), `materials/coat.inc.wgsl`.
    pub coat: u32,
    /// The class block: the class's fields, written by [`GpuMaterial::put`].
    pub block: [u32; BLOCK_WORDS],
}

impl Default for GpuMaterial {
    fn default() -> Self {
        GpuMaterial {
            emissive: [0.0; 3],
            tex_emissive: NONE,
            tex_normal: NONE,
            normal_scale: 1.0,
            queue: 0,
            coat: NONE,
            block: [0; BLOCK_WORDS],
        }
    }
}

impl GpuMaterial {
    /// Writes `block` into the class block at word `at` (a class may place several blocks one
    /// after the other: the MERL class its table after its sampling lobe).
    pub fn put<B: ClassBlock>(&mut self, at: usize, block: &B) {
        let words: &[u32] = bytemuck::cast_slice(std::slice::from_ref(block));
        debug_assert!(
            at + words.len() <= BLOCK_WORDS,
            "{} overflows the block",
            B::LAYOUT.wgsl
        );
        self.block[at..at + words.len()].copy_from_slice(words);
    }

    /// The block at word `at`, as [`put`](Self::put) wrote it.
    pub fn get<B: ClassBlock>(&self, at: usize) -> B {
        let n = std::mem::size_of::<B>() / 4;
        bytemuck::pod_read_unaligned(bytemuck::cast_slice(&self.block[at..at + n]))
    }
}

/// The WGSL type of a block field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldType {
    /// `f32`, one word.
    F32,
    /// `u32`, one word.
    U32,
    /// `vec3<f32>` from `[f32; 3]`, three words.
    Vec3,
}

impl FieldType {
    /// Words it takes in the block.
    pub const fn words(self) -> usize {
        match self {
            FieldType::Vec3 => 3,
            _ => 1,
        }
    }
}

/// A Rust field type a block may hold.
pub trait BlockField {
    /// Its WGSL type.
    const TYPE: FieldType;
}

impl BlockField for f32 {
    const TYPE: FieldType = FieldType::F32;
}

impl BlockField for u32 {
    const TYPE: FieldType = FieldType::U32;
}

impl BlockField for [f32; 3] {
    const TYPE: FieldType = FieldType::Vec3;
}

/// A class block's layout: its WGSL name, what it is, its fields in order.
#[derive(Clone, Copy, Debug)]
pub struct BlockLayout {
    /// The WGSL struct's name; its decoder is the name in snake case.
    pub wgsl: &'static str,
    /// Its doc comment's first line.
    pub doc: &'static str,
    /// (name, type, doc) of each field, in order.
    pub fields: &'static [(&'static str, FieldType, &'static str)],
}

impl BlockLayout {
    /// Words the block takes.
    pub const fn words(&self) -> usize {
        let mut n = 0;
        let mut i = 0;
        while i < self.fields.len() {
            n += self.fields[i].1.words();
            i += 1;
        }
        n
    }
}

/// A class block: a `#[repr(C)]` struct of `f32`, `u32` and `[f32; 3]` fields, declared with
/// [`class_block!`](crate::class_block).
pub trait ClassBlock: Pod {
    /// Its layout, from the declaration.
    const LAYOUT: BlockLayout;
}

/// Declares a class block: the Rust struct and its [`ClassBlock`] layout, from one list of
/// fields (`f32`, `u32` or `[f32; 3]`), each with a doc comment.
#[macro_export]
macro_rules! class_block {
    ($(#[doc = $doc:literal])+ $name:ident => $wgsl:literal {
        $($(#[doc = $fdoc:literal])+ $field:ident: $ty:ty,)+
    }) => {
        $(#[doc = $doc])+
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        pub struct $name {
            $($(#[doc = $fdoc])+ pub $field: $ty,)+
        }

        impl $crate::materials::record::ClassBlock for $name {
            const LAYOUT: $crate::materials::record::BlockLayout =
                $crate::materials::record::BlockLayout {
                    wgsl: $wgsl,
                    doc: $crate::class_block!(@first $($doc)+),
                    fields: &[$((
                        stringify!($field),
                        <$ty as $crate::materials::record::BlockField>::TYPE,
                        $crate::class_block!(@first $($fdoc)+),
                    )),+],
                };
        }

        // Words without padding: the decoder reads field k at the word the fields before it end.
        const _: () = assert!(
            std::mem::size_of::<$name>()
                == 4 * <$name as $crate::materials::record::ClassBlock>::LAYOUT.words()
        );
    };
    (@first $first:literal $($rest:literal)*) => { $first };
}

/// `CamelCase` → `camel_case`.
fn snake(name: &str) -> String {
    let mut s = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_lowercase());
    }
    s
}

/// One block's WGSL: its struct, its size in words and its decoder, which reads material `m`'s
/// block from word `at`.
pub fn block_wgsl(layout: &BlockLayout) -> String {
    let name = layout.wgsl;
    let fn_name = snake(name);
    let mut s = format!("//{}\nstruct {name} {{\n", layout.doc);
    for (field, ty, doc) in layout.fields {
        let t = match ty {
            FieldType::F32 => "f32",
            FieldType::U32 => "u32",
            FieldType::Vec3 => "vec3<f32>",
        };
        s += &format!("    //{doc}\n    {field}: {t},\n");
    }
    s += "}\n\n";
    s += &format!(
        "const {}_WORDS: u32 = {}u;\n\n",
        fn_name.to_uppercase(),
        layout.words()
    );
    s += &format!("fn {fn_name}(m: u32, at: u32) -> {name} {{\n    return {name}(\n");
    let word = |k: usize| format!("materials[m].block[at + {k}u]");
    let float = |k: usize| format!("bitcast<f32>({})", word(k));
    let mut k = 0;
    let mut args = Vec::new();
    for (_, ty, _) in layout.fields {
        args.push(match ty {
            FieldType::F32 => float(k),
            FieldType::U32 => word(k),
            FieldType::Vec3 => format!(
                "vec3<f32>({}, {}, {})",
                float(k),
                float(k + 1),
                float(k + 2)
            ),
        });
        k += ty.words();
    }
    s += &args
        .iter()
        .map(|a| format!("        {a},\n"))
        .collect::<String>();
    s += "    );\n}\n";
    s
}

/// The committed `shaders/render/materials/blocks.inc.wgsl`: every class block's struct and
/// decoder, generated.
pub fn wgsl(blocks: &[BlockLayout]) -> String {
    let mut s = String::from(
        "// Include-only. Generated from facet_render::materials (crates/render/src/materials/):\n\
         // do not edit; `FACET_REGENERATE=1 cargo test -p facet-render --test tags` rewrites it.\n\
         // Each class block's fields and its decoder from material m's block at word `at`\n\
         // (render/scene.inc.wgsl declares `materials`).\n",
    );
    for b in blocks {
        s += "\n";
        s += &block_wgsl(b);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::class_block!(
        /// A block to test with.
        Probe => "ProbeBlock" {
            /// a float
            x: f32,
            /// a colour
            c: [f32; 3],
            /// an offset
            o: u32,
        }
    );

    #[test]
    fn a_block_round_trips_through_the_record_and_counts_its_words() {
        assert_eq!(Probe::LAYOUT.words() * 4, std::mem::size_of::<Probe>());
        let p = Probe {
            x: 1.5,
            c: [0.25, 0.5, 0.75],
            o: 7,
        };
        let mut m = GpuMaterial::default();
        m.put(3, &p);
        assert_eq!(m.get::<Probe>(3), p);
        assert_eq!(m.block[3], 1.5f32.to_bits());
        assert_eq!(m.block[7], 7);
        let w = block_wgsl(&Probe::LAYOUT);
        assert!(
            w.contains("fn probe_block(m: u32, at: u32) -> ProbeBlock"),
            "{w}"
        );
        assert!(w.contains("materials[m].block[at + 4u],"), "{w}");
        assert!(w.contains("const PROBE_BLOCK_WORDS: u32 = 5u;"), "{w}");
    }
}

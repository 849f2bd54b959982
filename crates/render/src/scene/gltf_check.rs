//! Checks of the glTF values Facet reads, made on the JSON before the `gltf` crate's readers
//! touch them: those readers assume a valid file and panic (or overflow) on byteStrides shorter
//! than the element, index accessors of FLOAT/BYTE/SHORT, UNSIGNED_INT texture coordinates, a
//! camera whose `type` has no matching block, or `count × stride` past `usize`.
//!
//! Accessors (glTF 2.0 §3.6.2, §3.7.2.1), for each attribute Facet reads:
//!
//! | attribute  | type   | componentType                                   |
//! |------------|--------|-------------------------------------------------|
//! | POSITION   | VEC3   | FLOAT                                           |
//! | NORMAL     | VEC3   | FLOAT                                           |
//! | TANGENT    | VEC4   | FLOAT                                           |
//! | TEXCOORD_0 | VEC2   | FLOAT, or UNSIGNED_BYTE / UNSIGNED_SHORT normalized |
//! | indices    | SCALAR | UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT, not normalized |
//!
//! FLOAT is never normalized. `count ≥ 1`; `byteOffset` (and `bufferView.byteOffset +
//! byteOffset`) is a multiple of the component size, and of 4 for vertex attributes; a
//! `byteStride` is at least the element size, at most 252, a multiple of 4 for vertex attributes
//! and of the component size otherwise; with checked 64-bit arithmetic,
//! `byteOffset + (count − 1) × stride + element size ≤ bufferView.byteLength` and
//! `bufferView.byteOffset + byteLength ≤` the buffer's byteLength (which the loaded bytes were
//! checked to cover). Sparse accessors: `1 ≤ sparse.count ≤ count`, and their index and value
//! views checked the same way. An accessor without a bufferView is zeros (only with `sparse`:
//! the `gltf` crate refuses one with neither). Counts are capped by [`MAX_VERTICES`] and
//! [`MAX_TRIANGLES`], since an accessor without a bufferView costs nothing in the file.
//!
//! Cameras: `type` matches a block that is present; perspective `yfov` finite in (0, π),
//! `znear` finite > 0, `zfar` (if given) finite > `znear`, `aspectRatio` (if given) finite > 0;
//! orthographic `xmag`, `ymag` finite and non-zero, `znear` finite ≥ 0, `zfar` finite > `znear`.
//!
//! Lights (KHR_lights_punctual): colour and intensity finite and ≥ 0, `range` (if given)
//! finite > 0, spot `0 ≤ innerConeAngle < outerConeAngle ≤ π/2`.

use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;

/// The most vertices a scene may have (all primitives of all placed nodes together):
/// 2²⁶ ≈ 67 M, 3.2 GB of vertex data on the CPU and 4 GiB on the GPU.
pub const MAX_VERTICES: u64 = 1 << 26;
/// The most triangles a scene may have: 2²⁶ ≈ 67 M.
pub const MAX_TRIANGLES: u64 = 1 << 26;
/// The longest byteStride glTF allows.
pub const MAX_BYTE_STRIDE: u64 = 252;

/// What an accessor is read as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attribute {
    /// `POSITION`.
    Position,
    /// `NORMAL`.
    Normal,
    /// `TANGENT`.
    Tangent,
    /// `TEXCOORD_0`.
    TexCoord0,
    /// The index accessor.
    Indices,
}

impl Attribute {
    /// The glTF name of the attribute.
    pub fn name(self) -> &'static str {
        match self {
            Attribute::Position => "POSITION",
            Attribute::Normal => "NORMAL",
            Attribute::Tangent => "TANGENT",
            Attribute::TexCoord0 => "TEXCOORD_0",
            Attribute::Indices => "indices",
        }
    }

    fn is_vertex(self) -> bool {
        self != Attribute::Indices
    }
}

/// The glTF name of a component type.
pub fn component_name(c: ComponentType) -> &'static str {
    match c {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

fn type_name(t: Type) -> &'static str {
    match t {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

fn component_size(c: ComponentType) -> u64 {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn components(t: Type) -> u64 {
    match t {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

/// Checks accessor `index` for use as `attribute`; `buffer_len(i)` is the byteLength of buffer
/// `i` (its loaded bytes cover it). `Err` is the problem in words, without the accessor's name.
pub fn check_accessor(
    root: &json::Root,
    index: usize,
    attribute: Attribute,
    buffer_len: &dyn Fn(usize) -> Option<u64>,
) -> Result<(), String> {
    let a = root
        .accessors
        .get(index)
        .ok_or_else(|| format!("there is no accessor {index}"))?;
    let Checked::Valid(json::accessor::GenericComponentType(ct)) = a.component_type else {
        return Err("componentType is not a glTF component type".into());
    };
    let Checked::Valid(ty) = a.type_ else {
        return Err("type is not a glTF accessor type".into());
    };
    let what = attribute.name();
    let want_type = match attribute {
        Attribute::Position | Attribute::Normal => Type::Vec3,
        Attribute::Tangent => Type::Vec4,
        Attribute::TexCoord0 => Type::Vec2,
        Attribute::Indices => Type::Scalar,
    };
    if ty != want_type {
        return Err(format!(
            "type {} is not allowed for {what} (it must be {})",
            type_name(ty),
            type_name(want_type)
        ));
    }
    let allowed = match attribute {
        Attribute::Position | Attribute::Normal | Attribute::Tangent => {
            matches!(ct, ComponentType::F32)
        }
        Attribute::TexCoord0 => matches!(
            ct,
            ComponentType::F32 | ComponentType::U8 | ComponentType::U16
        ),
        Attribute::Indices => matches!(
            ct,
            ComponentType::U8 | ComponentType::U16 | ComponentType::U32
        ),
    };
    if !allowed {
        return Err(format!(
            "componentType {} is not allowed for {what}",
            component_name(ct)
        ));
    }
    match (attribute, ct, a.normalized) {
        (_, ComponentType::F32, true) => {
            return Err("a FLOAT accessor cannot be normalized".into());
        }
        (Attribute::TexCoord0, ComponentType::U8 | ComponentType::U16, false) => {
            return Err(format!(
                "componentType {} for TEXCOORD_0 must be normalized",
                component_name(ct)
            ));
        }
        (Attribute::Indices, _, true) => {
            return Err("indices cannot be normalized".into());
        }
        _ => {}
    }
    let count = a.count.0;
    let cap = match attribute {
        Attribute::Indices => 3 * MAX_TRIANGLES,
        _ => MAX_VERTICES,
    };
    if count == 0 {
        return Err("count is 0 (it must be at least 1)".into());
    }
    if count > cap {
        return Err(format!(
            "count {count} is more than the {cap} Facet reads from one accessor"
        ));
    }
    let comp = component_size(ct);
    let element = comp * components(ty);
    let offset = a.byte_offset.map_or(0, |o| o.0);
    match a.buffer_view {
        Some(view) => check_range(
            root,
            view.value(),
            Range {
                offset,
                count,
                element,
                component: comp,
                vertex: attribute.is_vertex(),
            },
            buffer_len,
        )?,
        None if offset != 0 => {
            return Err(format!("byteOffset {offset} without a bufferView"));
        }
        None => {}
    }
    if let Some(sparse) = &a.sparse {
        let n = sparse.count.0;
        if n == 0 || n > count {
            return Err(format!(
                "sparse.count {n} is not between 1 and the accessor's count {count}"
            ));
        }
        let Checked::Valid(json::accessor::IndexComponentType(ict)) = sparse.indices.component_type
        else {
            return Err("sparse.indices.componentType is not an index type".into());
        };
        if !matches!(
            ict,
            ComponentType::U8 | ComponentType::U16 | ComponentType::U32
        ) {
            return Err(format!(
                "sparse.indices.componentType {} is not an index type",
                component_name(ict)
            ));
        }
        let isize = component_size(ict);
        check_range(
            root,
            sparse.indices.buffer_view.value(),
            Range {
                offset: sparse.indices.byte_offset.0,
                count: n,
                element: isize,
                component: isize,
                vertex: false,
            },
            buffer_len,
        )
        .map_err(|e| format!("sparse.indices: {e}"))?;
        check_range(
            root,
            sparse.values.buffer_view.value(),
            Range {
                offset: sparse.values.byte_offset.0,
                count: n,
                element,
                component: comp,
                vertex: false,
            },
            buffer_len,
        )
        .map_err(|e| format!("sparse.values: {e}"))?;
    }
    Ok(())
}

/// `count` elements of `element` bytes at `offset` in a buffer view.
struct Range {
    offset: u64,
    count: u64,
    element: u64,
    component: u64,
    /// Vertex attribute data: offsets and strides aligned to 4 bytes.
    vertex: bool,
}

fn check_range(
    root: &json::Root,
    view_index: usize,
    r: Range,
    buffer_len: &dyn Fn(usize) -> Option<u64>,
) -> Result<(), String> {
    let view = root
        .buffer_views
        .get(view_index)
        .ok_or_else(|| format!("there is no bufferView {view_index}"))?;
    let check = check_view(root, view_index, buffer_len)?;
    let (view_offset, view_len) = check;
    let stride = match view.byte_stride {
        None => r.element,
        Some(s) => {
            let s = s.0 as u64;
            if s < r.element {
                return Err(format!(
                    "byteStride {s} of bufferView {view_index} is shorter than the element ({} bytes)",
                    r.element
                ));
            }
            if s > MAX_BYTE_STRIDE {
                return Err(format!(
                    "byteStride {s} of bufferView {view_index} is more than {MAX_BYTE_STRIDE}"
                ));
            }
            let align = if r.vertex { 4 } else { r.component };
            if !s.is_multiple_of(align) {
                return Err(format!(
                    "byteStride {s} of bufferView {view_index} is not a multiple of {align}"
                ));
            }
            s
        }
    };
    let align = if r.vertex {
        r.component.max(4)
    } else {
        r.component
    };
    if !r.offset.is_multiple_of(align) {
        return Err(format!(
            "byteOffset {} is not a multiple of {align}",
            r.offset
        ));
    }
    if !(view_offset.wrapping_add(r.offset)).is_multiple_of(r.component) {
        return Err(format!(
            "bufferView {view_index}'s byteOffset {view_offset} + byteOffset {} is not a multiple of the component size {}",
            r.offset, r.component
        ));
    }
    let end = (r.count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(r.offset))
        .and_then(|x| x.checked_add(r.element));
    match end {
        None => Err(format!(
            "byteOffset {} + (count {} − 1) × stride {stride} + {} overflows",
            r.offset, r.count, r.element
        )),
        Some(end) if end > view_len => Err(format!(
            "its {} elements (byteOffset {} + (count − 1) × stride {stride} + {} = {end} bytes) run past bufferView {view_index}'s byteLength {view_len}",
            r.count, r.offset, r.element
        )),
        Some(_) => Ok(()),
    }
}

/// Checks that buffer view `index` lies inside its buffer; returns its (byteOffset, byteLength).
pub fn check_view(
    root: &json::Root,
    index: usize,
    buffer_len: &dyn Fn(usize) -> Option<u64>,
) -> Result<(u64, u64), String> {
    let view = root
        .buffer_views
        .get(index)
        .ok_or_else(|| format!("there is no bufferView {index}"))?;
    let buffer = view.buffer.value();
    let len = buffer_len(buffer).ok_or_else(|| format!("there is no buffer {buffer}"))?;
    let offset = view.byte_offset.map_or(0, |o| o.0);
    let length = view.byte_length.0;
    match offset.checked_add(length) {
        Some(end) if end <= len => Ok((offset, length)),
        _ => Err(format!(
            "bufferView {index} (byteOffset {offset} + byteLength {length}) lies past the end of buffer {buffer} ({len} bytes)"
        )),
    }
}

/// What a camera is, once checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraKind {
    /// A perspective camera and its yfov.
    Perspective(f32),
    /// An orthographic camera.
    Orthographic,
}

/// Checks camera JSON `c` as the spec wants it (see the module doc).
pub fn check_camera(c: &json::camera::Camera) -> Result<CameraKind, String> {
    let finite = |x: f32| x.is_finite();
    match c.type_ {
        Checked::Valid(json::camera::Type::Perspective) => {
            let p = c
                .perspective
                .as_ref()
                .ok_or("type is perspective but it has no `perspective` block")?;
            if !(finite(p.yfov) && p.yfov > 0.0 && p.yfov < std::f32::consts::PI) {
                return Err(format!("perspective.yfov {} is not in (0, π)", p.yfov));
            }
            if !(finite(p.znear) && p.znear > 0.0) {
                return Err(format!("perspective.znear {} is not > 0", p.znear));
            }
            if let Some(zfar) = p.zfar
                && !(finite(zfar) && zfar > p.znear)
            {
                return Err(format!(
                    "perspective.zfar {zfar} is not > znear {}",
                    p.znear
                ));
            }
            if let Some(r) = p.aspect_ratio
                && !(finite(r) && r > 0.0)
            {
                return Err(format!("perspective.aspectRatio {r} is not > 0"));
            }
            Ok(CameraKind::Perspective(p.yfov))
        }
        Checked::Valid(json::camera::Type::Orthographic) => {
            let o = c
                .orthographic
                .as_ref()
                .ok_or("type is orthographic but it has no `orthographic` block")?;
            if !(finite(o.xmag) && finite(o.ymag) && o.xmag != 0.0 && o.ymag != 0.0) {
                return Err(format!(
                    "orthographic xmag {} / ymag {} is zero or not finite",
                    o.xmag, o.ymag
                ));
            }
            if !(finite(o.znear) && o.znear >= 0.0 && finite(o.zfar) && o.zfar > o.znear) {
                return Err(format!(
                    "orthographic znear {} / zfar {} is not 0 ≤ znear < zfar",
                    o.znear, o.zfar
                ));
            }
            Ok(CameraKind::Orthographic)
        }
        Checked::Invalid => Err("type is neither perspective nor orthographic".into()),
    }
}

/// Checks a punctual light's values (see the module doc).
pub fn check_light(l: &gltf::khr_lights_punctual::Light) -> Result<(), String> {
    let color = l.color();
    if !color.iter().all(|c| c.is_finite() && *c >= 0.0) {
        return Err(format!("color {color:?} is not finite and ≥ 0"));
    }
    let i = l.intensity();
    if !(i.is_finite() && i >= 0.0) {
        return Err(format!("intensity {i} is not finite and ≥ 0"));
    }
    if let Some(r) = l.range()
        && !(r.is_finite() && r > 0.0)
    {
        return Err(format!("range {r} is not > 0"));
    }
    if let gltf::khr_lights_punctual::Kind::Spot {
        inner_cone_angle: inner,
        outer_cone_angle: outer,
    } = l.kind()
        && !(inner >= 0.0 && inner < outer && outer <= std::f32::consts::FRAC_PI_2)
    {
        return Err(format!(
            "spot cone angles inner {inner}, outer {outer} are not 0 ≤ inner < outer ≤ π/2"
        ));
    }
    Ok(())
}

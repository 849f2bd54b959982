//! The integrator's bind groups by name. Each [`Group`] lists its bindings as the WGSL names its
//! globals, in binding order; the layouts are built from these lists and every bind group from
//! resources given by the same names (`bind_group`), so no binding is matched by position
//! alone. `crates/render/tests/bindings.rs` checks each list against the `@group`/`@binding`
//! globals that naga reflects from every pipeline file of [`PIPELINES`].

/// What a binding holds: the type of its layout entry (compute stages only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// A uniform buffer.
    Uniform,
    /// A read-write storage buffer.
    Storage,
    /// A read-only storage buffer.
    StorageReadOnly,
    /// A non-filterable float 3D texture.
    Texture3d,
}

impl BindingKind {
    /// The layout entry of binding `binding` holding this kind.
    fn entry(self, binding: u32) -> wgpu::BindGroupLayoutEntry {
        let buffer = |ty| wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let ty = match self {
            BindingKind::Uniform => buffer(wgpu::BufferBindingType::Uniform),
            BindingKind::Storage => buffer(wgpu::BufferBindingType::Storage { read_only: false }),
            BindingKind::StorageReadOnly => {
                buffer(wgpu::BufferBindingType::Storage { read_only: true })
            }
            BindingKind::Texture3d => wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D3,
                multisampled: false,
            },
        };
        wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        }
    }
}

/// A bind group of the integrator's pipelines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Group {
    /// `@group(0)` of every stage (`frame.inc.wgsl`): the frame, path state, queues, film.
    Frame,
    /// `@group(1)` of every stage (`scene.inc.wgsl`): the scene.
    Scene,
    /// `@group(2)` of a glint stage (`shade_glint.wgsl`): one glint material's field,
    /// parameters, DPF levels and split table.
    Glint,
    /// `@group(0)` of the queue closes (`queue_args.wgsl`).
    QueueArgs,
}

use BindingKind::{Storage, StorageReadOnly, Texture3d, Uniform};

impl Group {
    /// Every group.
    pub const ALL: [Group; 4] = [Group::Frame, Group::Scene, Group::Glint, Group::QueueArgs];

    /// Its number in the WGSL (`@group(n)`).
    pub const fn number(self) -> u32 {
        match self {
            Group::Frame | Group::QueueArgs => 0,
            Group::Scene => 1,
            Group::Glint => 2,
        }
    }

    /// Its label (layouts and bind groups).
    pub const fn label(self) -> &'static str {
        match self {
            Group::Frame => "frame",
            Group::Scene => "scene",
            Group::Glint => "glint",
            Group::QueueArgs => "queue args",
        }
    }

    /// Its bindings: (the WGSL global's name, what it holds), binding i at index i.
    pub const fn bindings(self) -> &'static [(&'static str, BindingKind)] {
        match self {
            Group::Frame => &[
                ("frame", Uniform),
                ("paths", Storage),
                ("info", Storage),
                ("counters", Storage),
                ("sizes", StorageReadOnly),
                ("queues", Storage),
                ("film", Storage),
                ("film_sq", Storage),
            ],
            Group::Scene => &[
                ("bvh_nodes", StorageReadOnly),
                ("bvh_primitives", StorageReadOnly),
                ("bvh_triangles", StorageReadOnly),
                ("vertices", StorageReadOnly),
                ("triangles", StorageReadOnly),
                ("materials", StorageReadOnly),
                ("textures", StorageReadOnly),
                ("lights", StorageReadOnly),
                ("tables", StorageReadOnly),
                ("triangle_light", StorageReadOnly),
                ("light_tree", StorageReadOnly),
            ],
            Group::Glint => &[
                ("field", Uniform),
                ("params", Uniform),
                ("level0", Texture3d),
                ("level1", Texture3d),
                ("split_table", StorageReadOnly),
            ],
            Group::QueueArgs => &[("counters", Storage), ("sizes", Storage), ("args", Storage)],
        }
    }

    /// Its layout.
    pub(crate) fn layout(self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let entries: Vec<wgpu::BindGroupLayoutEntry> = self
            .bindings()
            .iter()
            .zip(0..)
            .map(|((_, kind), binding)| kind.entry(binding))
            .collect();
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.label()),
            entries: &entries,
        })
    }
}

/// The groups of a stage over the path state and the scene, in group order: every stage but a
/// glint material's shading.
pub const STAGE: &[Group] = &[Group::Frame, Group::Scene];

/// The groups of a glint material's shading stage: its field and pyramid levels in group 2.
pub const GLINT_STAGE: &[Group] = &[Group::Frame, Group::Scene, Group::Glint];

/// Every pipeline file of the integrator but the shading stages, with the groups of its
/// pipeline layout, in group order: what these stages and the queue closes build their
/// pipeline layouts from. A shading stage's file and groups are its material class's
/// (`crate::materials::ShadeStage`).
pub const PIPELINES: &[(&str, &[Group])] = &[
    ("render/logic.wgsl", STAGE),
    ("render/generate.wgsl", STAGE),
    ("render/extend.wgsl", STAGE),
    ("render/connect.wgsl", STAGE),
    ("render/queue_args.wgsl", &[Group::QueueArgs]),
];

/// The groups of pipeline file `file`, in group order (`None`: not an integrator pipeline).
pub fn pipeline_groups(file: &str) -> Option<&'static [Group]> {
    PIPELINES.iter().find(|(f, _)| *f == file).map(|(_, g)| *g)
}

/// A bind group of `group` whose resources are named as the WGSL names the globals: each of
/// the group's bindings named once, in any order.
///
/// # Panics
///
/// When `named` misses a binding of the group, names one twice or names one the group does
/// not have: the lists are written in the code, and a wrong one is the code's error.
pub(crate) fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    group: Group,
    named: &[(&str, wgpu::BindingResource)],
) -> wgpu::BindGroup {
    let declared = group.bindings();
    for (name, _) in named {
        assert!(
            declared.iter().any(|(d, _)| d == name),
            "bind group {group:?} has no binding `{name}`; its bindings: {:?}",
            declared.iter().map(|(d, _)| *d).collect::<Vec<_>>()
        );
        assert!(
            named.iter().filter(|(n, _)| n == name).count() == 1,
            "bind group {group:?}: `{name}` is given twice"
        );
    }
    let entries: Vec<wgpu::BindGroupEntry> = declared
        .iter()
        .zip(0..)
        .map(|((name, _), binding)| {
            let (_, resource) = named
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("bind group {group:?}: no resource named `{name}`"));
            wgpu::BindGroupEntry {
                binding,
                resource: resource.clone(),
            }
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(group.label()),
        layout,
        entries: &entries,
    })
}

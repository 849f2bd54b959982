//! Adapter and device selection.
//!
//! Preference: a discrete GPU, then integrated, virtual, CPU (lavapipe / llvmpipe); Vulkan before
//! GL at equal rank. `FACET_BACKEND` = vulkan | gl | cpu and `FACET_ADAPTER` = a name substring
//! override it (`cpu` means: no GPU at all). The device gets the adapter's own limits, not
//! wgpu's defaults (storage bindings beyond 128 MiB where the adapter allows), and timestamp
//! queries where the adapter has them.

use crate::error::GpuError;
use std::sync::{Arc, Mutex};

/// What chose the adapter.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Restrict to these backends (`None`: Vulkan and GL).
    pub backends: Option<wgpu::Backends>,
    /// Only adapters whose name contains this (case-insensitive).
    pub adapter_name: Option<String>,
    /// Cap on the storage binding size requested (default: all the adapter allows).
    pub max_storage_binding: Option<u64>,
}

impl GpuOptions {
    /// From `FACET_BACKEND` and `FACET_ADAPTER`; `Err` when `FACET_BACKEND=cpu` or is unknown.
    pub fn from_env() -> Result<Self, GpuError> {
        let backends = match std::env::var("FACET_BACKEND")
            .ok()
            .as_deref()
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            None | Some("") | Some("auto") => None,
            Some("vulkan") => Some(wgpu::Backends::VULKAN),
            Some("gl") => Some(wgpu::Backends::GL),
            Some("cpu") => {
                return Err(GpuError::NoAdapter(
                    "FACET_BACKEND=cpu asks for no GPU".into(),
                ));
            }
            Some(other) => {
                return Err(GpuError::NoAdapter(format!(
                    "FACET_BACKEND={other}: use vulkan, gl or cpu"
                )));
            }
        };
        let adapter_name = std::env::var("FACET_ADAPTER")
            .ok()
            .filter(|s| !s.is_empty());
        Ok(GpuOptions {
            backends,
            adapter_name,
            max_storage_binding: None,
        })
    }
}

/// A chosen adapter with its device and queue. Domain code takes `&wgpu::Device` and
/// `&wgpu::Queue` from it; this struct owns nothing else.
pub struct Gpu {
    /// The chosen adapter.
    pub adapter: wgpu::Adapter,
    /// The device opened on it.
    pub device: wgpu::Device,
    /// The device's queue.
    pub queue: wgpu::Queue,
    /// The adapter's name, backend and driver.
    pub info: wgpu::AdapterInfo,
    /// Timestamp queries are available.
    pub timestamps: bool,
    lost: Arc<Mutex<Option<String>>>,
}

fn rank(info: &wgpu::AdapterInfo) -> (u32, u32) {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    let backend = if info.backend == wgpu::Backend::Vulkan {
        0
    } else {
        1
    };
    (kind, backend)
}

/// The best-ranked adapter allowed by `opts`.
fn best_adapter(opts: &GpuOptions) -> Result<wgpu::Adapter, GpuError> {
    let backends = opts
        .backends
        .unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::GL);
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = backends;
    let instance = wgpu::Instance::new(desc);
    let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
    if let Some(name) = &opts.adapter_name {
        let name = name.to_ascii_lowercase();
        adapters.retain(|a| a.get_info().name.to_ascii_lowercase().contains(&name));
    }
    adapters.sort_by_key(|a| rank(&a.get_info()));
    adapters.into_iter().next().ok_or_else(|| {
        GpuError::NoAdapter(match &opts.adapter_name {
            Some(n) => format!("none matches FACET_ADAPTER={n} on {backends:?}"),
            None => {
                format!("none found on {backends:?} (install mesa-vulkan-drivers for lavapipe)")
            }
        })
    })
}

impl Gpu {
    /// The best adapter under `FACET_BACKEND` / `FACET_ADAPTER`.
    pub fn new() -> Result<Self, GpuError> {
        Self::with_options(&GpuOptions::from_env()?)
    }

    /// The adapter [`Gpu::new`] would take, without opening a device on it (which costs tens of
    /// milliseconds on a software adapter that a caller may not want).
    pub fn best_adapter_info() -> Result<wgpu::AdapterInfo, GpuError> {
        Ok(best_adapter(&GpuOptions::from_env()?)?.get_info())
    }

    /// An adapter and device chosen by `opts`.
    pub fn with_options(opts: &GpuOptions) -> Result<Self, GpuError> {
        let adapter = best_adapter(opts)?;
        let info = adapter.get_info();
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let mut limits = adapter.limits();
        if let Some(cap) = opts.max_storage_binding {
            limits.max_storage_buffer_binding_size =
                limits.max_storage_buffer_binding_size.min(cap);
        }
        let desc = wgpu::DeviceDescriptor {
            label: Some("facet"),
            required_features: features,
            required_limits: limits,
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&desc)).map_err(|source| {
                GpuError::RequestDevice {
                    adapter: info.name.clone(),
                    source,
                }
            })?;
        let lost = Arc::new(Mutex::new(None));
        let flag = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            *flag.lock().unwrap() = Some(format!("{reason:?}: {message}"));
        });
        Ok(Gpu {
            adapter,
            device,
            queue,
            info,
            timestamps: !features.is_empty(),
            lost,
        })
    }

    /// Wraps a device made elsewhere (eframe's `egui_wgpu::RenderState`) so the renderer and
    /// the UI share one device and queue. Device loss is reported through [`Gpu::check_lost`];
    /// the device's own lost callback is taken over for that.
    pub fn from_parts(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        let info = adapter.get_info();
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let lost = Arc::new(Mutex::new(None));
        let flag = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            *flag.lock().unwrap() = Some(format!("{reason:?}: {message}"));
        });
        Gpu {
            adapter,
            device,
            queue,
            info,
            timestamps,
            lost,
        }
    }

    /// The device descriptor [`Gpu::new`] asks an adapter for: its own limits and timestamp
    /// queries where it has them. For code that creates the device itself (eframe).
    pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
        wgpu::DeviceDescriptor {
            label: Some("facet"),
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }
    }

    /// "name (backend, type)", as written into fit records.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// `Err(DeviceLost)` once the device has been lost.
    pub fn check_lost(&self) -> Result<(), GpuError> {
        match self.lost.lock().unwrap().clone() {
            Some(m) => Err(GpuError::DeviceLost(m)),
            None => Ok(()),
        }
    }

    /// Runs `f` inside out-of-memory and validation error scopes and turns what they caught
    /// into errors.
    pub fn scoped<T>(&self, f: impl FnOnce() -> T) -> Result<T, GpuError> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = f();
        let v = pollster::block_on(validation.pop());
        let o = pollster::block_on(oom.pop());
        if let Some(e) = o {
            return Err(GpuError::OutOfMemory(e.to_string()));
        }
        if let Some(e) = v {
            return Err(GpuError::Validation(e.to_string()));
        }
        self.check_lost()?;
        Ok(value)
    }
}

/// For tests: the GPU if there is one. Without one the test is skipped: `None`, after
/// [`report_skip`](crate::skip::report_skip) wrote `SKIPPED <test>: <why>` where a person sees
/// it (on the terminal past libtest's capture, and into the `FACET_SKIP_LOG` file when that is
/// set; `.ci/run` prints that file at the end). With `FACET_REQUIRE_GPU=1` (CI) it panics
/// instead. "No GPU" is any error choosing the adapter or creating the device, including
/// `FACET_BACKEND=cpu`.
pub fn gpu_for_tests(test: &str) -> Option<Gpu> {
    gpu_for_tests_with(test, |options| options)
}

/// [`gpu_for_tests`] with the options from the environment adjusted by `adjust` (a capped
/// storage binding size, say); skips and `FACET_REQUIRE_GPU=1` the same way.
pub fn gpu_for_tests_with(
    test: &str,
    adjust: impl FnOnce(GpuOptions) -> GpuOptions,
) -> Option<Gpu> {
    match GpuOptions::from_env().and_then(|options| Gpu::with_options(&adjust(options))) {
        Ok(g) => Some(g),
        Err(e) => {
            if std::env::var("FACET_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("{test}: FACET_REQUIRE_GPU=1 but {e}");
            }
            crate::skip::report_skip(test, &e.to_string());
            None
        }
    }
}

//! Errors a caller can act on: fall back to the CPU, report the shader, retry smaller.

/// What went wrong on the GPU, by what the caller can do about it.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter matched (none at all, `FACET_BACKEND=cpu`, or no `FACET_ADAPTER` match): run
    /// on the CPU instead. The text says which.
    #[error("no GPU adapter: {0}")]
    NoAdapter(String),
    /// The adapter was found but refused the device.
    #[error("{adapter}: requesting a device failed: {source}")]
    RequestDevice {
        /// The adapter's description.
        adapter: String,
        /// wgpu's reason.
        source: wgpu::RequestDeviceError,
    },
    /// A WGSL file that is missing, fails to expand its includes, or fails naga's validation.
    #[error("shader {name}: {message}")]
    Shader {
        /// The shader file, relative to `shaders/`.
        name: String,
        /// What is wrong (naga's report, with the path of the expanded source).
        message: String,
    },
    /// An out-of-memory error scope fired: retry smaller.
    #[error("GPU out of memory: {0}")]
    OutOfMemory(String),
    /// The device was lost; it cannot be used again.
    #[error("GPU device lost: {0}")]
    DeviceLost(String),
    /// A validation error scope fired (a bug or a limit the checks missed).
    #[error("GPU error: {0}")]
    Validation(String),
    /// Mapping a read-back buffer failed.
    #[error("reading a GPU buffer back failed: {0}")]
    Readback(String),
    /// A binding larger than the adapter allows, refused before it is created.
    #[error("{what} needs {needed} bytes in one binding; this adapter allows {limit}")]
    TooLarge {
        /// What the binding holds.
        what: String,
        /// Bytes it would need.
        needed: u64,
        /// The adapter's limit in bytes.
        limit: u64,
    },
}

//! Errors a caller can act on: fall back to the CPU, report the shader, retry smaller.

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter: {0}")]
    NoAdapter(String),
    #[error("{adapter}: requesting a device failed: {source}")]
    RequestDevice {
        adapter: String,
        source: wgpu::RequestDeviceError,
    },
    #[error("shader {name}: {message}")]
    Shader { name: String, message: String },
    #[error("GPU out of memory: {0}")]
    OutOfMemory(String),
    #[error("GPU device lost: {0}")]
    DeviceLost(String),
    #[error("GPU error: {0}")]
    Validation(String),
    #[error("reading a GPU buffer back failed: {0}")]
    Readback(String),
    #[error("{what} needs {needed} bytes in one binding; this adapter allows {limit}")]
    TooLarge {
        what: String,
        needed: u64,
        limit: u64,
    },
}

//! What the resources and the integrator agree on with the WGSL: the records the GPU reads
//! ([`gpu_types`], checked against naga by the tests), the closed sets of tags generated into
//! `shaders/render/tags.inc.wgsl` ([`tags`]), the bind groups ([`bindings`]), the queues
//! (`queues`), the device limits the buffers are planned by (`limits`) and the scene's `tables`
//! buffer as it is assembled (`tables`).

pub mod bindings;
pub mod gpu_types;
pub(crate) mod limits;
pub(crate) mod queues;
pub(crate) mod tables;
pub mod tags;

//! The sections of `facet bench`, one file each: each prints its table and returns its JSON.

pub mod coat;
pub mod dpf;
pub mod fit;
pub mod integrator;
pub mod lights;
pub mod measured;
pub mod noise;
pub mod shard;
pub mod trace;
pub mod viewer;

//! What a render writes: the film read back as an image ([`film`]: PNG tone mapped, EXR
//! linear), the tone map ([`tonemap`]), a shard's record in its EXR ([`shard`]) and the exact
//! merge of shards ([`merge`]).

pub mod film;
pub mod merge;
pub mod shard;
pub mod tonemap;

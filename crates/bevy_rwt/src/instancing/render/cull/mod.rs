//! Culling per instance on the GPU ([`InstanceCulling`](crate::InstanceCulling)).
//!
//! After queueing, each view gets one compute dispatch (`cull.wgsl`) over a record of each
//! chunk binned into any of its phases ([`CullRecord`](params::CullRecord)), the chunks' instances all in one
//! buffer ([`InstanceSlab`](super::slab::InstanceSlab)): each instance is tested against the view and, when it may be
//! seen, copied into the frame's pool of kept instances, and counted in its draw's indirect
//! arguments. The chunk's draws in that view then read their instances from the pool and
//! their count from the arguments ([`CulledDraw`](culler::CulledDraw)). The compute work is encoded at the start
//! of the frame's render graph ([`encode_cull`](frame::encode_cull)), before every view's passes, so each pass
//! of the view (prepasses, main pass, shadow map) reads what it wrote. A chunk without a
//! culled draw (culling off, the adapter unable, the pool full, or nothing culling could
//! drop: [`whole`]) is drawn directly, whole.
//!
//! A camera with Bevy's `OcclusionCulling` and `DepthPrepass`, and the cascades of a light
//! with `OcclusionCulling`, also cull what their depth pyramids hide, in two phases
//! ([`occlusion`]): what last frame's depth hid is tested again once this frame's early
//! depth is reduced, and drawn from the late prepass and late shadow passes on.

//! The modules, in the order a frame goes through them: [`views`] (how each view culls,
//! with its [`pyramids`]), [`entries`] (every chunk's meshes a view may thin, chosen by
//! [`whole`] and split by [`lods`]), [`layout`] (their records and ranges), [`frame`]
//! (written, recorded, encoded), [`occlusion`] (the late phase); [`culler`] holds the
//! pass and what the draws read, [`params`] what `cull.wgsl` reads; with feature
//! `testing`, `check` compares a frame with the CPU.

#[cfg(feature = "testing")]
mod check;
mod culler;
mod entries;
mod frame;
mod layout;
mod lods;
mod occlusion;
mod params;
mod pyramids;
#[cfg(test)]
mod tests;
mod views;
mod whole;

#[cfg(feature = "testing")]
pub(in crate::instancing) use check::{
    CullSnapshot, FrameCheck, check_culling, extract_culling_check,
};
#[cfg(feature = "testing")]
pub use check::{CullingCheck, CullingReport};
pub use culler::gpu_culling_supported;
pub(in crate::instancing) use culler::{InstanceCuller, init_culler};
pub(in crate::instancing) use frame::{cull_instances, encode_cull};
pub(in crate::instancing) use occlusion::cull_late;

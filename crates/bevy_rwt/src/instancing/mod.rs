//! Instanced classes: dense foliage (grass, flowers, pebbles) without an entity per instance.
//!
//! A class whose look is [`ClassLook::Instanced`](crate::ClassLook::Instanced) is packed,
//! in the chunk's generation task on the async compute pool, into one [`InstanceBuffer`] per
//! chunk: [`GpuInstance`]s of 24 bytes, positions relative to the chunk's corner so that
//! precision holds far from the origin. One entity per (chunk, class) carries it as an
//! [`InstancedChunk`] with an `Aabb` for frustum culling; the render plugin
//! ([`RwtInstancingPlugin`]) draws each with one instanced draw call.
//!
//! Each instance also stores the level-of-detail factor at which its point appears (its
//! rank over the local density). The vertex shader grows an instance in over a band of
//! that factor as the viewer approaches and shrinks it out as the viewer leaves, so a
//! layer with a [`Falloff`](rwt_core::streaming::Falloff) neither pops when chunks change
//! band nor at the streaming edge.

#[cfg(feature = "gltf")]
mod assets;
mod bend;
mod chunk;
mod far;
mod mesh;
mod pack;
mod plugin;
mod promote;
mod queue;
mod render;
mod settings;

#[cfg(feature = "gltf")]
pub use assets::ResolvedAssets;
pub use bend::{BEND_FIELD_TEXELS, BEND_RECOVERY, BEND_TEXEL, BendField, Bender};
pub use chunk::{
    GPU_BYTES_PER_INSTANCE, GpuInstance, ImpostorDraw, InstanceBuffer, InstancedChunk,
};
pub use mesh::InstancedMeshes;
pub(crate) use pack::{InstancedClasses, PackedClass};
pub use plugin::RwtInstancingPlugin;
pub use promote::PromotedInstance;
pub(crate) use queue::{InstancedQueue, UploadSources};
pub use render::gpu_culling_supported;
#[cfg(feature = "testing")]
pub use render::{CullingCheck, CullingReport};
pub use settings::{CascadeCasters, InstanceCulling, RwtFadeIn, RwtWind};

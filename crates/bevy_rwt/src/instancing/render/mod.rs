//! Render world: each [`InstancedChunk`](crate::instancing::InstancedChunk) is drawn with one
//! instanced draw of its class's mesh per view, from the shared buffer of every chunk's
//! instances, its uniform (corner, shading, fall-off, wind) and the frame's.
//!
//! One stage per module, each owning the types it makes; later stages read earlier ones,
//! never the reverse:
//!
//! - [`extract`]: a chunk's [`ExtractedChunk`](extract::ExtractedChunk), remade when it changed;
//! - [`prepare`]: the shared bindings and each chunk's [`GpuChunk`](prepare::GpuChunk), its
//!   instances placed in the [`slab`];
//! - [`pipelines`]: the instance layout and each chunk's specialized pipeline;
//! - queueing: [`main_pass`] (the opaque 3-D phase) and [`depth`] (prepasses and shadow
//!   maps, their cascades' casters chosen by [`receivers`]), both kept true frame by frame by
//!   [`retained`];
//! - [`cull`]: culling per instance on the GPU, after queueing;
//! - [`draw`]: the render commands, reading what culling kept (or the whole chunk).

mod cull;
mod depth;
mod draw;
mod extract;
#[cfg(test)]
mod extract_tests;
mod main_pass;
mod pipelines;
mod prepare;
mod receivers;
mod retained;
#[cfg(test)]
mod shader_check;
mod slab;
mod slices;
mod uniforms;

pub use cull::gpu_culling_supported;
#[cfg(feature = "testing")]
pub(super) use cull::{CullSnapshot, FrameCheck, check_culling, extract_culling_check};
#[cfg(feature = "testing")]
pub use cull::{CullingCheck, CullingReport};
pub(super) use cull::{cull_instances, cull_late, encode_cull, init_culler};
pub(super) use depth::{
    DrawInstancedDepth, InstancedDepthPipeline, init_depth_pipeline, queue_prepass, queue_shadows,
};
pub(super) use draw::{DrawInstancedChunk, LatePasses, begin_late_passes, end_late_passes};
pub(super) use main_pass::{InstancedPipeline, init_main_pipeline, queue_main};
pub(super) use pipelines::ReportedMeshes;
pub(super) use prepare::{MainViewer, embed_shader, init_bindings, prepare_chunks, prepare_frame};
pub(super) use receivers::{CascadeReceivers, find_receivers};
pub(super) use retained::Queued;
pub(super) use slab::InstanceSlab;

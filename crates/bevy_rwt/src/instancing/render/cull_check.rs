//! The check of culling per instance against the CPU (feature `testing`): on request, the
//! render world reads back a frame's indirect arguments and counts, for every culled draw,
//! the instances the same test keeps on the CPU ([`CullingCheck`]).

use super::cull::{ARGS_WORDS, CullUniform, InstanceCuller};
use crate::instancing::InstanceBuffer;
use bevy::prelude::*;
use bevy::render::extract_resource::ExtractResource;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use std::sync::{Arc, Mutex};

/// Asks the render world to check one frame's culling per instance against a brute-force
/// count on the CPU (the same test, the same view, every instance). Insert it, call
/// [`request`](Self::request), run frames until [`report`](Self::report) answers.
#[derive(Resource, Clone, Default)]
pub struct CullingCheck(Arc<Mutex<CheckState>>);

#[derive(Default)]
struct CheckState {
    requested: bool,
    report: Option<CullingReport>,
}

/// What a check found in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CullingReport {
    /// Culled draws (a chunk in a view).
    pub draws: usize,
    /// Instances of the chunks drawn, summed over the draws.
    pub instances: u64,
    /// Instances the GPU kept (read back from the indirect arguments).
    pub gpu_kept: u64,
    /// Instances the CPU keeps.
    pub cpu_kept: u64,
    /// Draws whose two counts differ.
    pub mismatched: usize,
}

impl CullingCheck {
    /// Checks the next frame that culls per instance (a report waiting is dropped).
    pub fn request(&self) {
        let mut state = self.0.lock().unwrap_or_else(|e| e.into_inner());
        state.requested = true;
        state.report = None;
    }

    /// The report, once the frame was checked.
    pub fn report(&self) -> Option<CullingReport> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).report
    }

    fn take_request(&self) -> bool {
        std::mem::take(&mut self.0.lock().unwrap_or_else(|e| e.into_inner()).requested)
    }

    fn answer(&self, report: CullingReport) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).report = Some(report);
    }
}

impl ExtractResource for CullingCheck {
    type Source = CullingCheck;

    fn extract_resource(source: &Self::Source) -> Self {
        source.clone()
    }
}

/// One culled draw as the check sees it: the dispatch's uniform and the chunk's instances.
pub(super) type Checked = (CullUniform, Arc<InstanceBuffer>);

/// After the frame's work is submitted: reads the arguments back when a check was asked
/// for and the frame culled per instance, and answers it.
pub(in crate::instancing) fn check_culling(
    check: Option<Res<CullingCheck>>,
    culler: Res<InstanceCuller>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
) {
    let Some(check) = check else { return };
    let (checked, Some(args)) = (culler.checked(), culler.args()) else {
        return;
    };
    if checked.is_empty() || !check.take_request() {
        return;
    }
    let size = checked.len() as u64 * u64::from(ARGS_WORDS) * 4;
    let staging = device.create_buffer(&BufferDescriptor {
        label: Some("rwt_cull_check"),
        size,
        usage: BufferUsages::MAP_READ | BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
        label: Some("rwt_cull_check"),
    });
    encoder.copy_buffer_to_buffer(args, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    let slice = staging.slice(..);
    slice.map_async(MapMode::Read, |_| {});
    if device.poll(PollType::wait_indefinitely()).is_err() {
        return;
    }
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&slice.get_mapped_range());
    let mut report = CullingReport::default();
    for (i, (uniform, buffer)) in checked.iter().enumerate() {
        let gpu = u64::from(words[i * ARGS_WORDS as usize + 1]);
        let cpu = buffer.instances.iter().filter(|g| uniform.keeps(g)).count() as u64;
        report.draws += 1;
        report.instances += buffer.instances.len() as u64;
        report.gpu_kept += gpu;
        report.cpu_kept += cpu;
        report.mismatched += usize::from(gpu != cpu);
    }
    check.answer(report);
}

//! How each view culls this frame, as the CPU sees it: its half-spaces, where its level of
//! detail is measured from, where a cascade's shadows are read, and how it occludes.

use super::pyramids::Occluding;
use crate::instancing::render::receivers::Receivers;
use bevy::prelude::*;

/// How one view culls (written for the GPU as its [`CullView`](super::params::CullView)).
#[derive(Clone, Copy)]
pub(super) struct ViewCulling {
    pub entity: Entity,
    pub planes: [Vec4; 6],
    pub eye: Vec3,
    pub shadow: bool,
    /// In a directional light's cascade, where its shadows are read.
    pub receivers: Option<Receivers>,
    pub occluding: Option<Occluding>,
}

//! The settings every instanced class shares: wind, fade-in, how chunks are culled, and
//! which instances shadow cascades draw. Resources of the main world, extracted to the
//! render world as they are.

use bevy::prelude::*;
use bevy::render::extract_resource::ExtractResource;

/// Wind for every instanced class: sway from a world-space noise field, coherent across
/// chunk borders.
#[derive(Resource, ExtractResource, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Resource, Clone, Debug, PartialEq)]
pub struct RwtWind {
    /// Direction on the ground (x, z); normalized by the shader.
    pub direction: Vec2,
    /// Strength: 0 is still air, 1 a stiff breeze.
    pub strength: f32,
    /// Spatial frequency of the gusts, cycles per world unit.
    pub frequency: f32,
    /// How fast the gusts travel, world units per second.
    pub speed: f32,
}

impl Default for RwtWind {
    fn default() -> Self {
        Self {
            direction: Vec2::new(1.0, 0.3),
            strength: 0.5,
            frequency: 0.05,
            speed: 4.0,
        }
    }
}

/// Whether instanced classes grow in and out with the level of detail (the default) or
/// appear and vanish at full size: turn it off to see the popping the fade hides.
#[derive(Resource, ExtractResource, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Resource, Clone, Debug, PartialEq)]
pub struct RwtFadeIn(pub bool);

impl Default for RwtFadeIn {
    fn default() -> Self {
        Self(true)
    }
}

/// How instanced chunks are culled.
///
/// Every chunk is first culled whole on the CPU, by its bounds against each view (cameras
/// and shadow views). With culling per instance, a compute pass then tests each instance of
/// the kept chunks against the view (its frustum, grown by the instance's reach and sway;
/// the level-of-detail fade, which shrinks far instances to nothing; the class's shadow
/// distance in shadow views) and writes the instances kept and the draw's arguments, and
/// each chunk is drawn indirectly: a chunk at the edge of the view draws only the instances
/// inside it.
#[derive(Resource, ExtractResource, Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Reflect)]
#[reflect(Resource, Clone, Debug, PartialEq, Default)]
pub enum InstanceCulling {
    /// Per instance on the GPU where the adapter runs compute shaders and indirect draws
    /// (not WebGL2-class adapters), per chunk otherwise.
    #[default]
    Auto,
    /// Per chunk on the CPU only: each kept chunk draws all its instances.
    PerChunk,
    /// Per instance on the GPU (per chunk where the adapter cannot).
    PerInstance,
}

/// Which instances a directional light's shadow cascades draw.
///
/// A cascade's shadow map covers a box around its slice of the camera's frustum, wider
/// than the slice and reaching behind the camera; each instanced chunk, and with culling per
/// instance each instance, is drawn into it only where its shadow may fall on what the
/// camera sees through that cascade.
#[derive(Resource, ExtractResource, Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Reflect)]
#[reflect(Resource, Clone, Debug, PartialEq, Default)]
pub enum CascadeCasters {
    /// Those whose shadow may fall in the camera's frustum, in the slice of view depth
    /// that reads the cascade (with a margin for filtering, the normal bias and diffuse
    /// transmission). Lights with soft shadows (`soft_shadow_size`) draw every instance.
    #[default]
    WhereRead,
    /// Every instance in the cascade's box, as Bevy draws meshes: for a shader that reads
    /// the cascades elsewhere (a reflection, the shadows of points outside the frustum).
    All,
}

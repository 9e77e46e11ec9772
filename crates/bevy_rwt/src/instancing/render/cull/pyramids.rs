//! The depth pyramids views occlude with: Bevy's `ViewDepthPyramid` of a camera with
//! `OcclusionCulling` and `DepthPrepass`, and of the cascades of a light with
//! `OcclusionCulling` under such a camera; a pyramid that hides nothing for the other views.

use bevy::core_pipeline::mip_generation::experimental::depth::ViewDepthPyramid;
use bevy::core_pipeline::prepass::DepthPrepass;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::occlusion_culling::OcclusionCullingSubviewEntities;
use bevy::render::render_resource::binding_types::texture_2d;
use bevy::render::render_resource::*;
use bevy::render::renderer::RenderDevice;
use bevy::render::view::ExtractedView;

/// What culling reads of a view to occlude: its pyramid, whether it has a depth prepass,
/// and (a camera) its cascades that occlude.
pub(super) type PyramidQuery = (
    Option<&'static ViewDepthPyramid>,
    Has<DepthPrepass>,
    Option<&'static OcclusionCullingSubviewEntities>,
);

/// A view as [`Pyramids::prepare`] reads it: its entity, itself, whether it is a shadow
/// view, and its [`PyramidQuery`].
pub(super) type ViewPyramid<'a> = (
    Entity,
    &'a ExtractedView,
    bool,
    (
        Option<&'a ViewDepthPyramid>,
        bool,
        Option<&'a OcclusionCullingSubviewEntities>,
    ),
);

/// How a view occludes this frame: its clip space from world space, and last frame's where
/// its pyramid still holds last frame's depth.
#[derive(Clone, Copy, Debug)]
pub(super) struct Occluding {
    pub current: Mat4,
    pub previous: Option<Mat4>,
}

/// One occluding view's pyramid as culling binds it.
struct Pyramid {
    texture: TextureViewId,
    /// The view's clip space from world space at the frame it was last culled.
    clip_from_world: Mat4,
    bind_group: BindGroup,
}

/// The pyramids views occlude with, and one that hides nothing for the other views.
pub(super) struct Pyramids {
    layout: BindGroupLayoutDescriptor,
    none_texture: TextureView,
    none: Option<BindGroup>,
    by_view: HashMap<Entity, Pyramid>,
}

impl Pyramids {
    pub fn new(device: &RenderDevice) -> Self {
        let layout = BindGroupLayoutDescriptor::new(
            "rwt_cull_pyramid",
            &BindGroupLayoutEntries::single(
                ShaderStages::COMPUTE,
                texture_2d(TextureSampleType::Float { filterable: false }),
            ),
        );
        // Zeroed: the farthest depth everywhere, which hides nothing.
        let texture = device.create_texture(&TextureDescriptor {
            label: Some("rwt_cull_no_pyramid"),
            size: Extent3d::default(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: TextureDimension::D2,
            format: TextureFormat::R32Float,
            usage: TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        Self {
            layout,
            none_texture: texture.create_view(&TextureViewDescriptor::default()),
            none: None,
            by_view: HashMap::default(),
        }
    }

    pub fn layout(&self) -> &BindGroupLayoutDescriptor {
        &self.layout
    }

    /// The bind group `view` culls with this frame.
    pub fn bind_group(&self, view: Entity) -> Option<&BindGroup> {
        self.by_view
            .get(&view)
            .map(|p| &p.bind_group)
            .or(self.none.as_ref())
    }

    /// Binds the pyramid of each view that occludes (a camera with a depth prepass, a
    /// cascade), and says how each occludes.
    pub fn prepare<'a>(
        &mut self,
        views: impl IntoIterator<Item = ViewPyramid<'a>>,
        device: &RenderDevice,
        cache: &PipelineCache,
    ) -> HashMap<Entity, Occluding> {
        let layout = cache.get_bind_group_layout(&self.layout);
        if self.none.is_none() {
            let entries = BindGroupEntries::single(&self.none_texture);
            self.none = Some(device.create_bind_group("rwt_cull_no_pyramid", &layout, &entries));
        }
        let views: Vec<ViewPyramid> = views.into_iter().collect();
        // A cascade's pyramid is reduced only under a camera whose own pyramid is: under
        // another, it holds nothing or an old frame's depth.
        let reduced: Vec<Entity> = views
            .iter()
            .filter(|(.., (pyramid, _, _))| pyramid.is_some())
            .flat_map(|(.., (_, _, cascades))| cascades.iter().flat_map(|c| c.0.iter().copied()))
            .collect();
        let mut occluding = HashMap::default();
        let mut by_view = HashMap::default();
        for (entity, view, shadow, (pyramid, depth_prepass, _)) in views {
            let occludes = if shadow {
                reduced.contains(&entity)
            } else {
                depth_prepass
            };
            let Some(pyramid) = pyramid.filter(|_| occludes) else {
                continue;
            };
            let current = view.clip_from_world.unwrap_or_else(|| {
                view.clip_from_view * view.world_from_view.to_matrix().inverse()
            });
            let texture = pyramid.all_mips.id();
            let (previous, bind_group) = match self.by_view.remove(&entity) {
                Some(p) if p.texture == texture => (Some(p.clip_from_world), p.bind_group),
                _ => {
                    let entries = BindGroupEntries::single(&pyramid.all_mips);
                    let bind_group =
                        device.create_bind_group("rwt_cull_pyramid", &layout, &entries);
                    (None, bind_group)
                }
            };
            occluding.insert(entity, Occluding { current, previous });
            let clip_from_world = current;
            by_view.insert(
                entity,
                Pyramid {
                    texture,
                    clip_from_world,
                    bind_group,
                },
            );
        }
        self.by_view = by_view;
        occluding
    }
}

//! A layer's densities and height source as thread-safe snapshots for generation tasks.
//! Each is made once and kept; repainting a map forgets only the snapshots that read it.

use crate::ground::SharedGround;
use crate::layers::too_large;
use crate::layers::{AssetFailure, AssetProblem, LayerAsset, merge_missing, missing_asset};
use crate::layers::{AssetStatus, HeightSource, LayerDensity, ScatterLayer, SharedDensity};
use bevy::prelude::*;
use rwt_core::density::Exclude;
use std::sync::Arc;

/// The snapshots of one layer.
#[derive(Default)]
pub(super) struct Resolved {
    /// One per class, `None` until made.
    classes: Vec<Option<SharedDensity>>,
    /// The exclusion mask, when the layer has one.
    exclusion: Option<SharedDensity>,
    /// The ground; for a layer on surfaces, set by [`Resolved::set_surfaces`].
    ground: Option<SharedGround>,
    /// Every class's density with the exclusion applied, once all are made.
    combined: Option<Vec<SharedDensity>>,
}

/// What generation tasks read: every class's density (exclusion applied) and the ground.
pub(super) struct Sources {
    pub densities: Vec<SharedDensity>,
    pub ground: SharedGround,
}

/// The snapshot of `density`, or why it cannot be made yet.
fn snapshot(
    density: &LayerDensity,
    images: &Assets<Image>,
    server: Option<&AssetServer>,
) -> Result<SharedDensity, AssetStatus> {
    if let Some(d) = density.resolve(images) {
        return Ok(d);
    }
    // Only an image density waits; any other resolves at once.
    Err(match density.image() {
        Some(image) => unreadable(image, images, server),
        None => AssetStatus::Waiting(Vec::new()),
    })
}

/// Why an image that a layer reads gives no snapshot: loading, failed, or not readable.
fn unreadable(
    image: &Handle<Image>,
    images: &Assets<Image>,
    server: Option<&AssetServer>,
) -> AssetStatus {
    if let Some(missing) = missing_asset(image, images.contains(image), server) {
        return missing;
    }
    let Some(i) = images.get(image) else {
        return AssetStatus::Waiting(vec![LayerAsset::of(image)]);
    };
    let why = if too_large(i) {
        AssetProblem::TooLarge {
            width: i.width(),
            height: i.height(),
            limit: rwt_core::density::MAX_IMAGE_PIXELS,
        }
    } else {
        AssetProblem::NotOnCpu {
            format: i.texture_descriptor.format,
        }
    };
    AssetStatus::Failed(vec![AssetFailure {
        asset: LayerAsset::of(image),
        why,
    }])
}

impl Resolved {
    /// Forgets the snapshots that read `image`; returns the ground regions they covered
    /// (`None` for a region: the whole plane).
    pub fn forget_image(
        &mut self,
        layer: &ScatterLayer,
        image: AssetId<Image>,
    ) -> Vec<Option<rwt_core::Rect>> {
        let mut covered = Vec::new();
        self.combined = None;
        let reads = |d: &LayerDensity| d.image().is_some_and(|h| h.id() == image);
        for (slot, class) in self.classes.iter_mut().zip(&layer.classes) {
            if reads(&class.density) {
                *slot = None;
                covered.push(class.density.image_rect());
            }
        }
        if let Some(mask) = layer.exclusion.as_ref().filter(|m| reads(m)) {
            self.exclusion = None;
            covered.push(mask.image_rect());
        }
        if let Some((handle, rect)) = layer.height.image()
            && handle.id() == image
        {
            self.ground = None;
            covered.push(rect);
        }
        covered
    }

    /// Makes what is missing; returns the task inputs, or why the layer must wait.
    pub fn sources(
        &mut self,
        layer: &ScatterLayer,
        images: &Assets<Image>,
        server: Option<&AssetServer>,
    ) -> Result<Sources, AssetStatus> {
        self.classes.resize(layer.classes.len(), None);
        let mut missing = Vec::new();
        for (slot, class) in self.classes.iter_mut().zip(&layer.classes) {
            if slot.is_none() {
                snapshot(&class.density, images, server)
                    .map(|d| *slot = Some(d))
                    .unwrap_or_else(|m| missing.push(m));
            }
        }
        if let Some(mask) = layer
            .exclusion
            .as_ref()
            .filter(|_| self.exclusion.is_none())
        {
            snapshot(mask, images, server)
                .map(|d| self.exclusion = Some(d))
                .unwrap_or_else(|m| missing.push(m));
        }
        if self.ground.is_none() {
            match (layer.height.resolve(images), layer.height.image()) {
                (Some(g), _) => self.ground = Some(g),
                (None, Some((image, _))) => missing.push(unreadable(image, images, server)),
                // The meshes of a layer on surfaces are still being gathered.
                (None, None) => missing.push(AssetStatus::Waiting(Vec::new())),
            }
        }
        if !missing.is_empty() {
            return Err(merge_missing(missing));
        }
        if self.combined.is_none() {
            self.combined = self.densities();
        }
        // With nothing missing, every snapshot is there.
        self.ready().ok_or(AssetStatus::Waiting(Vec::new()))
    }

    /// The task inputs as last made (`None` until every snapshot is there).
    pub fn ready(&self) -> Option<Sources> {
        Some(Sources {
            densities: self.combined.clone()?,
            ground: self.ground.clone()?,
        })
    }

    /// The ground snapshot, once made.
    pub fn ground(&self) -> Option<&SharedGround> {
        self.ground.as_ref()
    }

    /// Sets the ground of a layer on surfaces (its meshes were gathered or changed).
    pub fn set_surfaces(&mut self, layer: &ScatterLayer, ground: SharedGround) {
        if matches!(layer.height, HeightSource::Surfaces) {
            self.ground = Some(ground);
        }
    }

    /// Every class's density with the exclusion mask applied, once every class has its
    /// snapshot.
    fn densities(&self) -> Option<Vec<SharedDensity>> {
        let classes: Vec<SharedDensity> = self.classes.iter().cloned().collect::<Option<_>>()?;
        Some(match &self.exclusion {
            None => classes,
            Some(mask) => classes
                .into_iter()
                .map(|inner| {
                    Arc::new(Exclude {
                        inner,
                        mask: mask.clone(),
                        threshold: 0.5,
                    }) as SharedDensity
                })
                .collect(),
        })
    }
}

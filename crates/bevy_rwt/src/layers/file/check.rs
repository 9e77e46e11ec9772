//! The range checks of a parsed layer file.

use super::{
    DensityDescription, InvalidLayer, LAYER_FORMAT, LayerDescription, MAX_CLASSES,
    MaterialDescription, numbers,
};
use rwt_core::clumps::Clumps;
use rwt_core::streaming::StreamingConfig;

impl LayerDescription {
    /// Whether the values are in range.
    pub(super) fn check(&self) -> Result<(), InvalidLayer> {
        let d = self;
        if !(1..=LAYER_FORMAT).contains(&d.format) {
            return Err(InvalidLayer::Format {
                found: d.format,
                supported: LAYER_FORMAT,
            });
        }
        if d.classes.is_empty() {
            return Err(InvalidLayer::NoClasses);
        }
        if d.classes.len() > MAX_CLASSES {
            return Err(InvalidLayer::TooManyClasses {
                classes: d.classes.len(),
                limit: MAX_CLASSES,
            });
        }
        for (field, v) in [
            ("tile_size", Some(d.tile_size)),
            ("chunk_size", d.chunk_size),
            ("load_distance", d.load_distance),
            ("unload_distance", d.unload_distance),
        ] {
            if let Some(value) = v
                && !(value.is_finite() && value > 0.0)
            {
                return Err(InvalidLayer::NotPositive { field, value });
            }
        }
        let chunk = d
            .chunk_size
            .unwrap_or(StreamingConfig::default().chunk_size);
        let load = d
            .load_distance
            .unwrap_or(StreamingConfig::default().load_distance);
        if load / chunk > rwt_core::streaming::MAX_REACH_CHUNKS {
            return Err(InvalidLayer::TooFar {
                load_distance: load,
                chunk_size: chunk,
                limit: rwt_core::streaming::MAX_REACH_CHUNKS,
            });
        }
        if let (Some(load_distance), Some(unload_distance)) = (d.load_distance, d.unload_distance)
            && unload_distance < load_distance
        {
            return Err(InvalidLayer::UnloadBelowLoad {
                load_distance,
                unload_distance,
            });
        }
        let densities = d.classes.iter().map(|c| &c.density).chain(&d.exclusion);
        for density in densities {
            if let DensityDescription::Clumps(params) = density {
                Clumps::new(*params).map_err(InvalidLayer::Clumps)?;
            }
        }
        d.check_looks()?;
        for (i, c, lod) in d
            .classes
            .iter()
            .enumerate()
            .filter_map(|(i, c)| Some((i, c, c.lod.as_ref()?)))
        {
            if !(lod.distance.is_finite() && lod.distance > 0.0) {
                return Err(InvalidLayer::LodDistance {
                    class: i,
                    distance: lod.distance,
                });
            }
            let instanced = matches!(c.material, Some(MaterialDescription::Instanced(_)));
            if instanced != matches!(lod.material, MaterialDescription::Instanced(_)) {
                return Err(InvalidLayer::FarMaterial { class: i });
            }
        }
        numbers::check(d)
    }

    /// Whether each class has a mesh and a material, or an asset alone.
    fn check_looks(&self) -> Result<(), InvalidLayer> {
        for (i, c) in self.classes.iter().enumerate() {
            let drawn = c.mesh.is_some() && c.material.is_some();
            let asset_only = c.mesh.is_none() && c.material.is_none() && c.lod.is_none();
            if c.asset.as_ref().map_or(!drawn, |_| !asset_only) {
                return Err(InvalidLayer::ClassLook { class: i });
            }
        }
        Ok(())
    }
}

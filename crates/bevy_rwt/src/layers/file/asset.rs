//! An asset class in a layer file: `asset: "trees/oak.glb#Scene0"`, or with its options
//! `asset: (path: "trees/oak.glb", lods: [20.0, 60.0], collider: false, wind_response: 0.2)`.

use crate::look::InstancedShadows;
use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

/// The look of an asset class in a layer file (see [`AssetLook`](crate::look::asset::AssetLook),
/// whose defaults each field takes). Written as its path alone (`asset: "rocks/boulder.glb"`)
/// or as a struct naming the fields it changes.
///
/// The path's label picks the part of the file: none for the whole file, `#Scene0` for a
/// scene, any other label a node by its name (`"trees.glb#Oak"`).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct AssetDescription {
    /// Asset path of the glTF file, with its label.
    pub path: String,
    /// See [`AssetLods::distances`](crate::look::asset::AssetLods::distances).
    pub lods: Vec<f32>,
    /// See [`AssetLods::crossfade`](crate::look::asset::AssetLods::crossfade).
    pub crossfade: f32,
    /// Whether promoted instances get the file's collider.
    pub collider: bool,
    /// Strength of the hashed colour variation.
    pub color_variation: f32,
    /// How far the top sways in the wind.
    pub wind_response: f32,
    /// How far instances lean where a bender passed.
    pub bend_response: f32,
    /// Width of the fade-in band.
    pub fade_band: f32,
    /// Whether the class casts shadows: `Off`, `On` or `Within(30.0)`.
    pub shadows: InstancedShadows,
}

impl Default for AssetDescription {
    fn default() -> Self {
        Self {
            path: String::new(),
            lods: Vec::new(),
            crossfade: 0.1,
            collider: true,
            color_variation: 0.0,
            wind_response: 0.0,
            bend_response: 0.0,
            fade_band: 0.1,
            shadows: InstancedShadows::On,
        }
    }
}

/// Which part of a file an asset path's label names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AssetLabel<'a> {
    /// No label: the whole file.
    File,
    /// `#SceneN`.
    Scene(usize),
    /// Any other label: a node's name.
    Node(&'a str),
}

impl AssetDescription {
    /// The file's path, without its label.
    pub fn file(&self) -> &str {
        self.path
            .split_once('#')
            .map_or(&self.path, |(file, _)| file)
    }

    /// The part of the file the path's label names.
    pub fn label(&self) -> AssetLabel<'_> {
        match self.path.split_once('#') {
            None => AssetLabel::File,
            Some((_, label)) => match label
                .strip_prefix("Scene")
                .and_then(|i| i.parse::<usize>().ok())
            {
                Some(scene) => AssetLabel::Scene(scene),
                None => AssetLabel::Node(label),
            },
        }
    }
}

/// Reads either form: a string is the path with every other field at its default.
pub(super) fn either_form<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<Option<AssetDescription>, D::Error> {
    struct Form;
    impl<'de> Visitor<'de> for Form {
        type Value = Option<AssetDescription>;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an asset path, or (path: .., lods: [..], ..)")
        }

        fn visit_str<E: de::Error>(self, path: &str) -> Result<Self::Value, E> {
            Ok(Some(AssetDescription {
                path: path.to_string(),
                ..AssetDescription::default()
            }))
        }

        fn visit_map<M: MapAccess<'de>>(self, map: M) -> Result<Self::Value, M::Error> {
            AssetDescription::deserialize(de::value::MapAccessDeserializer::new(map)).map(Some)
        }

        fn visit_none<E: de::Error>(self) -> Result<Self::Value, E> {
            Ok(None)
        }

        fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_any(Form)
        }
    }
    d.deserialize_any(Form)
}

#[cfg(feature = "gltf")]
mod look {
    use super::{AssetDescription, AssetLabel};
    use crate::look::asset::{AssetLods, AssetLook, AssetRoot};
    use bevy::gltf::Gltf;
    use bevy::prelude::*;

    impl AssetDescription {
        /// The look it describes, of the file `gltf` (loaded from [`AssetDescription::file`]).
        pub fn to_look(&self, gltf: Handle<Gltf>) -> AssetLook {
            let root = match self.label() {
                AssetLabel::File => AssetRoot::File,
                AssetLabel::Scene(i) => AssetRoot::Scene(i),
                AssetLabel::Node(name) => AssetRoot::Node(name.to_string()),
            };
            AssetLook {
                gltf,
                root,
                color_variation: self.color_variation,
                wind_response: self.wind_response,
                bend_response: self.bend_response,
                fade_band: self.fade_band,
                shadows: self.shadows,
                lods: AssetLods {
                    distances: self.lods.clone(),
                    crossfade: self.crossfade,
                },
                collider: self.collider,
            }
        }

        /// The description of `look`, whose file loads from `file`.
        pub fn of(look: &AssetLook, file: &str) -> Self {
            let path = match &look.root {
                AssetRoot::File => file.to_string(),
                AssetRoot::Scene(i) => format!("{file}#Scene{i}"),
                AssetRoot::Node(name) => format!("{file}#{name}"),
            };
            Self {
                path,
                lods: look.lods.distances.clone(),
                crossfade: look.lods.crossfade,
                collider: look.collider,
                color_variation: look.color_variation,
                wind_response: look.wind_response,
                bend_response: look.bend_response,
                fade_band: look.fade_band,
                shadows: look.shadows,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_the_file_a_scene_or_a_node() {
        let at = |path: &str| AssetDescription {
            path: path.into(),
            ..Default::default()
        };
        assert_eq!(at("trees/oak.glb").label(), AssetLabel::File);
        assert_eq!(at("trees/oak.glb#Scene2").label(), AssetLabel::Scene(2));
        assert_eq!(at("trees/oak.glb#Oak").label(), AssetLabel::Node("Oak"));
        assert_eq!(
            at("trees/oak.glb#SceneX").label(),
            AssetLabel::Node("SceneX")
        );
        assert_eq!(at("trees/oak.glb#Scene0").file(), "trees/oak.glb");
    }
}

//! Footprints every peer shares: a building the server places clears the same ground for
//! every player. A [`NetFootprint`] names its layers (entities differ between peers) and
//! carries its placement; replicon replicates it, and every peer, the server too, gives its
//! entity the local [`Footprint`] and `Transform` that `bevy_rwt` streams with.

use crate::index::LayerIndex;
use bevy::prelude::*;
use bevy_replicon::prelude::*;
use bevy_rwt::RwtSystems;
use bevy_rwt::footprints::{Footprint, FootprintShape};
use bevy_rwt::layers::ScatterLayer;
use serde::{Deserialize, Serialize};

/// A footprint that every peer shares: spawn it on the server with replicon's
/// [`Replicated`]; every peer (the server too) then clears the ground under it, and the
/// ground comes back everywhere when the entity goes.
///
/// ```
/// use bevy::prelude::*;
/// use bevy_replicon::prelude::Replicated;
/// use bevy_rwt::footprints::Footprint;
/// use bevy_rwt_net::NetFootprint;
///
/// /// On the server: a cabin that clears trees and rocks (not the grass) for every player.
/// fn place_cabin(mut commands: Commands) {
///     let at = Transform::from_xyz(12.0, 0.0, -3.0).with_rotation(Quat::from_rotation_y(0.4));
///     let clearing = Footprint::rectangle(Vec2::new(3.0, 2.0)).with_margin(1.5);
///     commands.spawn((
///         NetFootprint::new(at, clearing).on_layers(["trees", "rocks"]),
///         Replicated,
///     ));
/// }
/// ```
///
/// The entity's `Transform` is the placement's on every peer (set it here, not on the
/// entity). A client drops the server's footprints when it disconnects (the server sends
/// them again when it joins).
#[derive(Component, Clone, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[reflect(Component, Clone, Debug, PartialEq)]
pub struct NetFootprint {
    /// Where it stands.
    pub translation: Vec3,
    /// Its turn.
    pub rotation: Quat,
    /// Its scale.
    pub scale: Vec3,
    /// The shape, in the entity's ground coordinates.
    pub shape: FootprintShape,
    /// Clearance around the shape, in world units.
    pub margin: f32,
    /// The layers it clears, by `Name` (`None`: every layer, unnamed ones too).
    pub layers: Option<Vec<String>>,
    /// The classes it clears, by index in each cleared layer (`None`: every class).
    pub classes: Option<Vec<u16>>,
}

impl NetFootprint {
    /// `footprint`'s shape, margin and classes, placed by `transform`, clearing every layer
    /// until [`NetFootprint::on_layers`] names some (the footprint's own layer entities are
    /// not carried: entities differ between peers).
    pub fn new(transform: Transform, footprint: Footprint) -> Self {
        let Footprint {
            shape,
            margin,
            classes,
            layers: _,
        } = footprint;
        Self {
            translation: transform.translation,
            rotation: transform.rotation,
            scale: transform.scale,
            shape,
            margin,
            layers: None,
            classes,
        }
    }

    /// Clears the layers of these names only.
    pub fn on_layers(mut self, names: impl IntoIterator<Item = impl Into<String>>) -> Self {
        self.layers = Some(names.into_iter().map(Into::into).collect());
        self
    }

    /// Its placement.
    pub fn transform(&self) -> Transform {
        Transform {
            translation: self.translation,
            rotation: self.rotation,
            scale: self.scale,
        }
    }

    /// The local footprint, its layers found by name in `index` (names this peer lacks
    /// clear nothing).
    fn footprint(&self, index: &LayerIndex) -> Footprint {
        let footprint = Footprint {
            shape: self.shape.clone(),
            margin: self.margin,
            layers: None,
            classes: self.classes.clone(),
        };
        match &self.layers {
            Some(names) => footprint.on_layers(names.iter().filter_map(|n| index.by_name(n))),
            None => footprint,
        }
    }
}

pub(crate) fn plugin(app: &mut App) {
    app.register_type::<NetFootprint>()
        .add_systems(Update, place.before(RwtSystems::Plan))
        .add_systems(OnExit(ClientState::Connected), drop_servers_footprints);
}

/// A named layer that appeared or was renamed.
type LayerNamed = (With<ScatterLayer>, Or<(Changed<Name>, Added<ScatterLayer>)>);

/// Gives each new or changed [`NetFootprint`] its local footprint and transform; all of them
/// again when the named layers change (a layer added, renamed or gone).
fn place(
    footprints: Query<(Entity, Ref<NetFootprint>)>,
    layers: Query<(Entity, &Name), With<ScatterLayer>>,
    named: Query<(), LayerNamed>,
    mut gone: RemovedComponents<ScatterLayer>,
    mut unnamed: RemovedComponents<Name>,
    mut commands: Commands,
) {
    let layers_changed = !named.is_empty() | (gone.read().count() + unnamed.read().count() > 0);
    let mut index = None;
    for (entity, net) in &footprints {
        if !(layers_changed || net.is_changed()) {
            continue;
        }
        let index = index.get_or_insert_with(|| LayerIndex::new(layers.iter()));
        commands
            .entity(entity)
            .insert((net.transform(), net.footprint(index)));
    }
}

/// The server's footprints leave with the connection: replicon keeps what it spawned on a
/// client after a disconnect, and a join spawns the footprints again.
fn drop_servers_footprints(
    footprints: Query<Entity, (With<NetFootprint>, With<Remote>)>,
    mut commands: Commands,
) {
    for entity in &footprints {
        commands.entity(entity).despawn();
    }
}

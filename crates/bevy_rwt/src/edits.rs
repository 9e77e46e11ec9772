//! Per-instance edits: remove one instance (a tree chopped, a flower picked), give it another
//! class of its layer (a tree becomes a stump), or restore it, for entity and instanced
//! classes alike.
//!
//! An edit is keyed by the instance's layer and [`PointId`], and applied where the layer's
//! points are generated: an edited instance stays edited when its chunk unloads and comes
//! back, when its level of detail changes, when a map is repainted or the layer's file
//! reloads. Sending an [`EditInstance`] touches only the chunk that holds the point: an
//! entity instance is despawned or swapped at once, an instanced chunk is generated again.
//! Each layer's edits are a [`ScatterEdits`] component on its entity, whose size follows
//! the edits, not the world; the brush's save writes them beside the painted maps.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::prelude::*;
//! use bevy_rwt::edits::{EditInstance, ScatterEdits};
//!
//! /// Chops every tree the player clicked this frame (found by picking, or by a collider on
//! /// the instance entity): the tree leaves and never comes back.
//! fn chop(
//!     clicked: Query<&ScatterEntity, With<Chopped>>,
//!     mut edits: MessageWriter<EditInstance>,
//! ) {
//!     for instance in &clicked {
//!         edits.write(EditInstance::remove(instance.layer, instance.id));
//!     }
//! }
//! # #[derive(Component)]
//! # struct Chopped;
//!
//! /// How many instances the player changed, for a HUD.
//! fn count(layers: Query<&ScatterEdits>) -> usize {
//!     layers.iter().map(|e| e.len()).sum()
//! }
//! # let mut app = App::new();
//! # app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugins::default()));
//! # app.add_systems(Update, (chop, count.map(drop)));
//! # app.finish();
//! # app.cleanup();
//! # app.update();
//! ```

use bevy::prelude::*;
pub use rwt_core::edits::{Edit, EditSet, EditStamp, EditsError};
use rwt_core::query::PointId;

/// What an [`EditInstance`] does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Reflect)]
#[reflect(Clone, Debug, PartialEq, Hash)]
pub enum InstanceEdit {
    /// The instance leaves (and stays away).
    Remove,
    /// The instance is shown as its densities make it again (an edit undone).
    Restore,
    /// The instance shows this class of its layer instead (a stump for a tree).
    Reclass(u16),
}

/// Edits one instance of a layer. Write it with a `MessageWriter<EditInstance>`; the plugin
/// applies it before planning, in [`crate::RwtSystems::Plan`].
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq, Hash, Reflect)]
#[reflect(Clone, Debug, PartialEq, Hash)]
pub struct EditInstance {
    /// The layer entity.
    pub layer: Entity,
    /// The instance's point.
    pub id: PointId,
    /// What to do.
    pub edit: InstanceEdit,
}

impl EditInstance {
    /// Removes point `id` of `layer`.
    pub fn remove(layer: Entity, id: PointId) -> Self {
        Self {
            layer,
            id,
            edit: InstanceEdit::Remove,
        }
    }

    /// Restores point `id` of `layer`.
    pub fn restore(layer: Entity, id: PointId) -> Self {
        Self {
            layer,
            id,
            edit: InstanceEdit::Restore,
        }
    }

    /// Shows point `id` of `layer` as `class` of the layer.
    pub fn reclass(layer: Entity, id: PointId, class: u16) -> Self {
        Self {
            layer,
            id,
            edit: InstanceEdit::Reclass(class),
        }
    }
}

/// Who applies the game's [`EditInstance`]s: this app (the default), or a remote authority
/// such as a multiplayer server (`bevy_rwt_net` makes a joined client's edits requests to
/// its server). Under [`EditAuthority::Remote`] the plugin applies only [`ConfirmedEdit`]s
/// and leaves the game's edits to whoever forwards them.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
#[reflect(Resource, Clone, Debug, Default, PartialEq)]
pub enum EditAuthority {
    /// The plugin applies the game's edits.
    #[default]
    Local,
    /// The game's edits are requests to another app; only confirmed ones apply.
    Remote,
}

/// An edit its authority confirmed (a multiplayer server's): applied, with an
/// [`EditOutcome`], whatever the [`EditAuthority`].
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConfirmedEdit(pub EditInstance);

/// What became of an [`EditInstance`] or a [`ConfirmedEdit`]: the plugin writes one for each it reads, in order,
/// in [`crate::RwtSystems::Plan`] (read it after that set). A game shows why a chop failed;
/// a server that replicates edits sends on the applied ones.
#[derive(Message, Clone, Debug, PartialEq)]
pub struct EditOutcome {
    /// The edit.
    pub edit: EditInstance,
    /// Whether it was applied, or why not.
    pub result: Result<(), EditError>,
}

/// Why an [`EditInstance`] was not applied (logged, and in its [`EditOutcome`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EditError {
    /// The entity has no [`crate::ScatterLayer`].
    #[error("entity {0} is not a scatter layer")]
    NoLayer(Entity),
    /// The layer's tiling has no such point (an identity from another layer or tile set).
    #[error("the layer has no point {0:?}")]
    NoSuchPoint(PointId),
    /// A reclass to a class the layer does not have.
    #[error("the layer has {classes} classes, no class {class}")]
    NoSuchClass {
        /// The class asked for.
        class: u16,
        /// The layer's classes.
        classes: usize,
    },
    /// The edit set refused it (more than `rwt_core::edits::MAX_EDITS` edits).
    #[error(transparent)]
    Refused(#[from] rwt_core::edits::EditsError),
}

/// The edits of a layer, on its entity (added with the [`crate::ScatterLayer`], kept when the
/// layer is replaced or its file reloads). Read it to list or count edits; change single
/// instances with [`EditInstance`]; insert a new `ScatterEdits` to replace them all (what a
/// load does): every chunk that the old or the new edits touch is generated again.
#[derive(Component, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Component, Clone, Debug, Default, PartialEq)]
pub struct ScatterEdits(EditSet);

impl ScatterEdits {
    /// A layer's edits from a set (e.g. read from a file with [`EditSet::from_bytes`]).
    pub fn new(set: EditSet) -> Self {
        Self(set)
    }

    /// The edits.
    pub fn edits(&self) -> &EditSet {
        &self.0
    }

    /// The edit of point `id`, if any.
    pub fn get(&self, id: &PointId) -> Option<Edit> {
        self.0.get(id)
    }

    /// Number of edited instances.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether no instance is edited.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Applies one edit to the set; a refused one changes nothing.
    pub(crate) fn apply(&mut self, id: PointId, edit: InstanceEdit) -> Result<(), EditError> {
        edit.apply_to(&mut self.0, id)
    }
}

impl InstanceEdit {
    /// Applies this edit of point `id` to `set` (a layer's, or one chunk's share of it).
    pub(crate) fn apply_to(self, set: &mut EditSet, id: PointId) -> Result<(), EditError> {
        match self {
            InstanceEdit::Remove => set.set(id, Edit::Remove)?,
            InstanceEdit::Reclass(class) => set.set(id, Edit::Reclass(class))?,
            InstanceEdit::Restore => set.restore(&id),
        };
        Ok(())
    }
}

//! Layers across the network: by name, numbered in name order.

use bevy::prelude::*;

/// The named layers in the order the network numbers them: by name, the first of equal
/// names.
#[derive(Default)]
pub(crate) struct LayerIndex(Vec<(String, Entity)>);

impl LayerIndex {
    pub(crate) fn new<'a>(layers: impl IntoIterator<Item = (Entity, &'a Name)>) -> Self {
        let mut named: Vec<_> = layers
            .into_iter()
            .map(|(e, n)| (n.as_str().to_owned(), e))
            .collect();
        named.sort_by(|a, b| a.0.cmp(&b.0));
        named.dedup_by(|a, b| a.0 == b.0);
        Self(named)
    }

    pub(crate) fn entity(&self, index: u16) -> Option<Entity> {
        self.0.get(index as usize).map(|(_, e)| *e)
    }

    pub(crate) fn position(&self, entity: Entity) -> Option<u16> {
        self.0
            .iter()
            .position(|(_, e)| *e == entity)
            .map(|i| i as u16)
    }

    pub(crate) fn by_name(&self, name: &str) -> Option<Entity> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, e)| *e)
    }

    pub(crate) fn names(&self) -> impl Iterator<Item = &str> {
        self.0.iter().map(|(n, _)| n.as_str())
    }

    pub(crate) fn entities(&self) -> impl Iterator<Item = Entity> + '_ {
        self.0.iter().map(|(_, e)| *e)
    }
}

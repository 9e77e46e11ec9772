//! Names for assets made in code, so that layer files can use them and layers built in code
//! can be written as layer files.

use crate::layers::{HeightFn, HeightSource};
use crate::look::InstanceInserter;
use bevy::prelude::*;
use std::collections::HashMap;
use std::sync::{Arc, PoisonError, RwLock};

/// Meshes, materials, height functions and promotion inserters a game gives names: a layer file says
/// `mesh: Named("spruce")`, `material: Named("bark")` or `ground: Named("terrain")`, and
/// [`super::LayerDescription::describe`] writes these names for the handles it meets.
///
/// The layer file loader reads the names when it loads a file, so register them before
/// loading the files that use them (a file naming something unregistered fails to load, with
/// the name in its error). Clones share one registry.
///
/// ```
/// # use bevy::prelude::*;
/// # use bevy_rwt::layers::file::NamedAssets;
/// # use bevy_rwt::layers::HeightSource;
/// # use std::sync::Arc;
/// let names = NamedAssets::default();
/// let spruce: Handle<Mesh> = Handle::default();
/// names.insert_mesh("spruce", spruce.clone());
/// let ground = HeightSource::Function(Arc::new(|p: Vec2| (p.x * 0.01).sin()));
/// names.insert_height("terrain", &ground);
/// assert_eq!(names.mesh_name(&spruce).as_deref(), Some("spruce"));
/// assert_eq!(names.height_name(&ground).as_deref(), Some("terrain"));
/// ```
#[derive(Resource, Clone, Default, Debug)]
pub struct NamedAssets(Arc<RwLock<Registry>>);

#[derive(Default)]
struct Registry {
    meshes: HashMap<String, Handle<Mesh>>,
    materials: HashMap<String, Handle<StandardMaterial>>,
    heights: HashMap<String, HeightFn>,
    inserters: HashMap<String, InstanceInserter>,
}

impl std::fmt::Debug for Registry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names = |m: Vec<&String>| {
            let mut m: Vec<_> = m.into_iter().cloned().collect();
            m.sort();
            m
        };
        f.debug_struct("Registry")
            .field("meshes", &names(self.meshes.keys().collect()))
            .field("materials", &names(self.materials.keys().collect()))
            .field("heights", &names(self.heights.keys().collect()))
            .field("inserters", &names(self.inserters.keys().collect()))
            .finish()
    }
}

impl NamedAssets {
    fn read<T>(&self, f: impl FnOnce(&Registry) -> T) -> T {
        f(&self.0.read().unwrap_or_else(PoisonError::into_inner))
    }

    fn write(&self, f: impl FnOnce(&mut Registry)) {
        f(&mut self.0.write().unwrap_or_else(PoisonError::into_inner));
    }

    /// Names a mesh (replacing what had the name).
    pub fn insert_mesh(&self, name: impl Into<String>, mesh: Handle<Mesh>) {
        self.write(|r| _ = r.meshes.insert(name.into(), mesh));
    }

    /// Names a material (replacing what had the name).
    pub fn insert_material(&self, name: impl Into<String>, material: Handle<StandardMaterial>) {
        self.write(|r| _ = r.materials.insert(name.into(), material));
    }

    /// Names a [`HeightSource::Function`] (other sources are described without names):
    /// layers whose height is a clone of `height` are written with this name.
    pub fn insert_height(&self, name: impl Into<String>, height: &HeightSource) {
        if let HeightSource::Function(f) = height {
            self.write(|r| _ = r.heights.insert(name.into(), f.clone()));
        }
    }

    /// Names what promoted instances get (a [`crate::Promotion`]'s inserter): promotions
    /// inserting this very function are written with this name.
    pub fn insert_inserter(&self, name: impl Into<String>, inserter: &InstanceInserter) {
        self.write(|r| _ = r.inserters.insert(name.into(), inserter.clone()));
    }

    /// The inserter of this name.
    pub fn inserter(&self, name: &str) -> Option<InstanceInserter> {
        self.read(|r| r.inserters.get(name).cloned())
    }

    /// The name of an inserter registered as this very function.
    pub fn inserter_name(&self, inserter: &InstanceInserter) -> Option<String> {
        self.read(|r| first_name(&r.inserters, |i| Arc::ptr_eq(i, inserter)))
    }

    /// The mesh of this name.
    pub fn mesh(&self, name: &str) -> Option<Handle<Mesh>> {
        self.read(|r| r.meshes.get(name).cloned())
    }

    /// The material of this name.
    pub fn material(&self, name: &str) -> Option<Handle<StandardMaterial>> {
        self.read(|r| r.materials.get(name).cloned())
    }

    /// The height source of this name.
    pub fn height(&self, name: &str) -> Option<HeightSource> {
        self.read(|r| r.heights.get(name).cloned().map(HeightSource::Function))
    }

    /// The name of a mesh (the first in name order when it has several).
    pub fn mesh_name(&self, mesh: &Handle<Mesh>) -> Option<String> {
        self.read(|r| first_name(&r.meshes, |h| h.id() == mesh.id()))
    }

    /// The name of a material (the first in name order when it has several).
    pub fn material_name(&self, material: &Handle<StandardMaterial>) -> Option<String> {
        self.read(|r| first_name(&r.materials, |h| h.id() == material.id()))
    }

    /// The name of a height function: one registered as this very function (not an equal
    /// one, which cannot be told apart).
    pub fn height_name(&self, height: &HeightSource) -> Option<String> {
        let HeightSource::Function(f) = height else {
            return None;
        };
        self.read(|r| first_name(&r.heights, |h| Arc::ptr_eq(h, f)))
    }
}

fn first_name<T>(map: &HashMap<String, T>, is: impl Fn(&T) -> bool) -> Option<String> {
    map.iter()
        .filter(|(_, v)| is(v))
        .map(|(k, _)| k)
        .min()
        .cloned()
}

//! glTF binaries (`.glb`) written from code, for tests, benchmarks and examples that need an
//! asset file without downloading one: named nodes with transforms and children, meshes of
//! several primitives, and materials with what the instanced path draws (base colour and
//! its texture, normal map, metallic and roughness, emissive, alpha mode and cut-off,
//! double-sided). Images are PNG bytes embedded in the binary chunk.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::testing::glb::{Glb, GlbMaterial, GlbNode, GlbPrimitive};
//!
//! let mut file = Glb::default();
//! let red = file.add_material(GlbMaterial::colored([0.8, 0.1, 0.1, 1.0]));
//! let cube = GlbPrimitive::from_mesh(&Cuboid::default().mesh().build(), red).unwrap();
//! let mesh = file.add_mesh(vec![cube]);
//! let root = file.add_node(GlbNode::named("box").with_mesh(mesh));
//! file.add_root(root);
//! let bytes = file.to_bytes();
//! assert_eq!(&bytes[..4], b"glTF");
//! ```

use bevy::mesh::{Indices, VertexAttributeValues};
use bevy::prelude::*;
use serde_json::{Value, json};

/// How a material's alpha is used.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum GlbAlpha {
    /// Alpha ignored.
    #[default]
    Opaque,
    /// Cut out below the cut-off.
    Mask(f32),
    /// Blended.
    Blend,
}

/// A material: glTF's metallic-roughness model. Textures are indices into [`Glb::images`].
#[derive(Clone, Debug, PartialEq)]
pub struct GlbMaterial {
    /// The material's name.
    pub name: String,
    /// Base colour factor (linear RGBA).
    pub base_color: [f32; 4],
    /// Base colour texture (sRGB), multiplied by the factor.
    pub base_color_texture: Option<usize>,
    /// Normal map (tangent space).
    pub normal_texture: Option<usize>,
    /// Metallic factor.
    pub metallic: f32,
    /// Roughness factor.
    pub roughness: f32,
    /// Metallic (blue) and roughness (green) texture.
    pub metallic_roughness_texture: Option<usize>,
    /// Emissive factor (linear RGB).
    pub emissive: [f32; 3],
    /// Occlusion texture (red).
    pub occlusion_texture: Option<usize>,
    /// Alpha mode.
    pub alpha: GlbAlpha,
    /// Whether back faces are drawn.
    pub double_sided: bool,
}

impl GlbMaterial {
    /// A rough, non-metallic, opaque material of one colour.
    pub fn colored(base_color: [f32; 4]) -> Self {
        Self {
            name: String::new(),
            base_color,
            base_color_texture: None,
            normal_texture: None,
            metallic: 0.0,
            roughness: 0.9,
            metallic_roughness_texture: None,
            emissive: [0.0; 3],
            occlusion_texture: None,
            alpha: GlbAlpha::Opaque,
            double_sided: false,
        }
    }

    fn to_json(&self) -> Value {
        let texture = |index: Option<usize>| index.map(|i| json!({ "index": i }));
        let mut pbr = json!({
            "baseColorFactor": self.base_color,
            "metallicFactor": self.metallic,
            "roughnessFactor": self.roughness,
        });
        if let Some(t) = texture(self.base_color_texture) {
            pbr["baseColorTexture"] = t;
        }
        if let Some(t) = texture(self.metallic_roughness_texture) {
            pbr["metallicRoughnessTexture"] = t;
        }
        let mut out = json!({
            "name": self.name,
            "pbrMetallicRoughness": pbr,
            "emissiveFactor": self.emissive,
            "doubleSided": self.double_sided,
        });
        if let Some(t) = texture(self.normal_texture) {
            out["normalTexture"] = t;
        }
        if let Some(t) = texture(self.occlusion_texture) {
            out["occlusionTexture"] = t;
        }
        match self.alpha {
            GlbAlpha::Opaque => {}
            GlbAlpha::Mask(cutoff) => {
                out["alphaMode"] = json!("MASK");
                out["alphaCutoff"] = json!(cutoff);
            }
            GlbAlpha::Blend => out["alphaMode"] = json!("BLEND"),
        }
        out
    }
}

/// A triangle list with its material (an index into [`Glb::materials`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GlbPrimitive {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Vertex normals.
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates (`TEXCOORD_0`), if any.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Tangents (xyz and handedness), if any.
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Triangle indices.
    pub indices: Vec<u32>,
    /// The material.
    pub material: usize,
}

impl GlbPrimitive {
    /// A Bevy triangle mesh's positions, normals, first UVs, tangents and indices, or `None`
    /// where it has no positions or normals of three floats.
    pub fn from_mesh(mesh: &Mesh, material: usize) -> Option<Self> {
        let vec3 = |id| match mesh.attribute(id) {
            Some(VertexAttributeValues::Float32x3(v)) => Some(v.clone()),
            _ => None,
        };
        let positions = vec3(Mesh::ATTRIBUTE_POSITION)?;
        let normals = vec3(Mesh::ATTRIBUTE_NORMAL)?;
        let uvs = match mesh.attribute(Mesh::ATTRIBUTE_UV_0) {
            Some(VertexAttributeValues::Float32x2(v)) => Some(v.clone()),
            _ => None,
        };
        let tangents = match mesh.attribute(Mesh::ATTRIBUTE_TANGENT) {
            Some(VertexAttributeValues::Float32x4(v)) => Some(v.clone()),
            _ => None,
        };
        let indices = match mesh.indices() {
            Some(Indices::U16(i)) => i.iter().map(|&i| u32::from(i)).collect(),
            Some(Indices::U32(i)) => i.clone(),
            None => (0..positions.len() as u32).collect(),
        };
        Some(Self {
            positions,
            normals,
            uvs,
            tangents,
            indices,
            material,
        })
    }
}

/// A node: a name, a transform relative to its parent, a mesh (an index into
/// [`Glb::meshes`]) and children (indices into [`Glb::nodes`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GlbNode {
    /// The node's name.
    pub name: String,
    /// Its transform relative to its parent.
    pub transform: Transform,
    /// Its mesh.
    pub mesh: Option<usize>,
    /// Its children.
    pub children: Vec<usize>,
    /// `MSFT_lod`: the nodes of its lower levels (none: no extension).
    pub lods: Vec<usize>,
    /// `MSFT_screencoverage` in its extras (none when empty).
    pub coverage: Vec<f32>,
}

impl GlbNode {
    /// A node called `name`, at the parent's origin.
    pub fn named(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            ..default()
        }
    }

    /// This node, drawing `mesh`.
    pub fn with_mesh(mut self, mesh: usize) -> Self {
        self.mesh = Some(mesh);
        self
    }

    /// This node, placed by `transform`.
    pub fn with_transform(mut self, transform: Transform) -> Self {
        self.transform = transform;
        self
    }

    /// This node, with `children`.
    pub fn with_children(mut self, children: impl IntoIterator<Item = usize>) -> Self {
        self.children.extend(children);
        self
    }

    /// This node, naming its lower levels with `MSFT_lod` and hinting their screen
    /// coverage (`MSFT_screencoverage`, none when empty).
    pub fn with_msft_lod(mut self, levels: Vec<usize>, coverage: Vec<f32>) -> Self {
        self.lods = levels;
        self.coverage = coverage;
        self
    }
}

/// A glTF file being written: one scene of [`Glb::roots`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Glb {
    /// Every node.
    pub nodes: Vec<GlbNode>,
    /// The scene's root nodes.
    pub roots: Vec<usize>,
    /// Every mesh: its primitives.
    pub meshes: Vec<Vec<GlbPrimitive>>,
    /// Every material.
    pub materials: Vec<GlbMaterial>,
    /// Every image, as PNG bytes.
    pub images: Vec<Vec<u8>>,
}

impl Glb {
    /// Adds a node; returns its index.
    pub fn add_node(&mut self, node: GlbNode) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// Makes node `node` a root of the scene.
    pub fn add_root(&mut self, node: usize) {
        self.roots.push(node);
    }

    /// Adds a mesh of `primitives`; returns its index.
    pub fn add_mesh(&mut self, primitives: Vec<GlbPrimitive>) -> usize {
        self.meshes.push(primitives);
        self.meshes.len() - 1
    }

    /// Adds a material; returns its index.
    pub fn add_material(&mut self, material: GlbMaterial) -> usize {
        self.materials.push(material);
        self.materials.len() - 1
    }

    /// Adds an image (PNG bytes); returns its index.
    pub fn add_image(&mut self, png: Vec<u8>) -> usize {
        self.images.push(png);
        self.images.len() - 1
    }

    /// The file's bytes: a header, the JSON chunk and the binary chunk.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bin = Binary::default();
        let meshes: Vec<Value> = self
            .meshes
            .iter()
            .map(|primitives| {
                let primitives: Vec<Value> = primitives.iter().map(|p| bin.primitive(p)).collect();
                json!({ "primitives": primitives })
            })
            .collect();
        let images: Vec<Value> = self
            .images
            .iter()
            .map(|png| json!({ "bufferView": bin.view(png, None), "mimeType": "image/png" }))
            .collect();
        let textures: Vec<Value> = (0..self.images.len())
            .map(|i| json!({ "source": i, "sampler": 0 }))
            .collect();
        let nodes: Vec<Value> = self.nodes.iter().map(node_json).collect();
        let mut root = json!({
            "asset": { "version": "2.0", "generator": "bevy_rwt::testing::glb" },
            "scene": 0,
            "scenes": [{ "nodes": self.roots }],
            "nodes": nodes,
            "meshes": meshes,
            "materials": self.materials.iter().map(GlbMaterial::to_json).collect::<Vec<_>>(),
            "accessors": bin.accessors,
            "bufferViews": bin.views,
            "buffers": [{ "byteLength": bin.bytes.len() }],
        });
        if !images.is_empty() {
            root["images"] = json!(images);
            root["textures"] = json!(textures);
            // Linear filtering, mipmaps, repeat.
            root["samplers"] = json!([{ "magFilter": 9729, "minFilter": 9987 }]);
        }
        if self.nodes.iter().any(|n| !n.lods.is_empty()) {
            root["extensionsUsed"] = json!(["MSFT_lod"]);
        }
        // glTF's arrays are present only when not empty.
        if let Value::Object(fields) = &mut root {
            fields.retain(|_, v| v.as_array().is_none_or(|a| !a.is_empty()));
        }
        let json = serde_json::to_vec(&root).unwrap_or_default();
        container(json, bin.bytes)
    }
}

fn node_json(node: &GlbNode) -> Value {
    let t = node.transform;
    let mut out = json!({
        "name": node.name,
        "translation": t.translation.to_array(),
        "rotation": t.rotation.to_array(),
        "scale": t.scale.to_array(),
    });
    if let Some(mesh) = node.mesh {
        out["mesh"] = json!(mesh);
    }
    if !node.children.is_empty() {
        out["children"] = json!(node.children);
    }
    if !node.lods.is_empty() {
        out["extensions"] = json!({ "MSFT_lod": { "ids": node.lods } });
    }
    if !node.coverage.is_empty() {
        out["extras"] = json!({ "MSFT_screencoverage": node.coverage });
    }
    out
}

/// The binary chunk and the views and accessors that point into it.
#[derive(Default)]
struct Binary {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

/// glTF's buffer view targets and component types.
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

impl Binary {
    /// A view of `data`, aligned to 4 bytes; returns its index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": data.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.views.push(view);
        self.views.len() - 1
    }

    /// An accessor of `count` elements of `kind` over a new view of `data`.
    fn accessor(&mut self, data: &[u8], kind: &str, component: u32, count: usize) -> usize {
        let target = match component {
            UNSIGNED_INT => ELEMENT_ARRAY_BUFFER,
            _ => ARRAY_BUFFER,
        };
        let view = self.view(data, Some(target));
        self.accessors.push(json!({
            "bufferView": view, "componentType": component, "count": count, "type": kind,
        }));
        self.accessors.len() - 1
    }

    fn floats<const N: usize>(&mut self, values: &[[f32; N]], kind: &str) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        self.accessor(&bytes, kind, FLOAT, values.len())
    }

    fn primitive(&mut self, p: &GlbPrimitive) -> Value {
        let position = self.floats(&p.positions, "VEC3");
        // Positions need their bounds.
        let (lo, hi) = p.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), q| (lo.min(Vec3::from(*q)), hi.max(Vec3::from(*q))),
        );
        self.accessors[position]["min"] = json!(lo.to_array());
        self.accessors[position]["max"] = json!(hi.to_array());
        let mut attributes = json!({
            "POSITION": position,
            "NORMAL": self.floats(&p.normals, "VEC3"),
        });
        if let Some(uvs) = &p.uvs {
            attributes["TEXCOORD_0"] = json!(self.floats(uvs, "VEC2"));
        }
        if let Some(tangents) = &p.tangents {
            attributes["TANGENT"] = json!(self.floats(tangents, "VEC4"));
        }
        let indices: Vec<u8> = p.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.accessor(&indices, "SCALAR", UNSIGNED_INT, p.indices.len());
        json!({ "attributes": attributes, "indices": indices, "material": p.material })
    }
}

/// The binary glTF container: a header, the JSON chunk (padded with spaces) and the binary
/// chunk.
fn container(mut json: Vec<u8>, bin: Vec<u8>) -> Vec<u8> {
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-level tree: a root with a trunk (bark) and a masked, double-sided crown with a
    /// texture.
    fn tree() -> Glb {
        let mut file = Glb::default();
        let bark = file.add_material(GlbMaterial {
            name: "bark".into(),
            ..GlbMaterial::colored([0.3, 0.2, 0.1, 1.0])
        });
        let png = file.add_image(vec![0x89, b'P', b'N', b'G']);
        let leaves = file.add_material(GlbMaterial {
            name: "leaves".into(),
            base_color_texture: Some(png),
            alpha: GlbAlpha::Mask(0.4),
            double_sided: true,
            ..GlbMaterial::colored([0.2, 0.6, 0.1, 1.0])
        });
        let cuboid = Cuboid::default().mesh().build();
        let trunk = GlbPrimitive::from_mesh(&cuboid, bark).unwrap();
        let crown = GlbPrimitive::from_mesh(&Sphere::new(1.0).mesh().build(), leaves).unwrap();
        let mesh = file.add_mesh(vec![trunk, crown]);
        let lod0 = file.add_node(
            GlbNode::named("tree_LOD0")
                .with_mesh(mesh)
                .with_transform(Transform::from_xyz(0.0, 1.0, 0.0)),
        );
        let root = file.add_node(GlbNode::named("tree").with_children([lod0]));
        file.add_root(root);
        file
    }

    #[test]
    fn a_written_file_reads_back_with_its_nodes_primitives_and_materials() {
        let file = tree();
        let read = gltf::Gltf::from_slice(&file.to_bytes()).expect("a valid glTF binary");
        let names: Vec<_> = read
            .nodes()
            .map(|n| n.name().unwrap_or("").to_string())
            .collect();
        assert_eq!(names, ["tree_LOD0", "tree"]);
        let root = read.scenes().next().unwrap().nodes().next().unwrap();
        assert_eq!(root.name(), Some("tree"));
        let child = root.children().next().unwrap();
        let (translation, _, _) = child.transform().decomposed();
        assert_eq!(translation, [0.0, 1.0, 0.0]);
        let mesh = child.mesh().unwrap();
        assert_eq!(mesh.primitives().count(), 2);
        let leaves = mesh.primitives().nth(1).unwrap().material();
        assert_eq!(leaves.name(), Some("leaves"));
        assert_eq!(leaves.alpha_mode(), gltf::material::AlphaMode::Mask);
        assert_eq!(leaves.alpha_cutoff(), Some(0.4));
        assert!(leaves.double_sided());
        let texture = leaves
            .pbr_metallic_roughness()
            .base_color_texture()
            .unwrap();
        assert_eq!(texture.texture().source().index(), 0);
        let cube = &file.meshes[0][0];
        let positions = mesh
            .primitives()
            .next()
            .unwrap()
            .get(&gltf::Semantic::Positions);
        assert_eq!(positions.unwrap().count(), cube.positions.len());
        let blob = read.blob.as_ref().unwrap();
        assert_eq!(blob.len() % 4, 0);
    }

    #[test]
    fn the_container_is_aligned_and_sized() {
        let bytes = tree().to_bytes();
        assert_eq!(&bytes[..4], b"glTF");
        let total = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
        assert_eq!(total, bytes.len());
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        assert_eq!(json_len % 4, 0);
        assert_eq!(&bytes[16..20], b"JSON");
    }
}

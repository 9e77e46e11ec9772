//! The showcase's asset pack: glTF files the examples write themselves (nothing is
//! downloaded), as a game's artist would ship them, for rwt to scatter as asset classes.
//! Three trees (bark with a normal map, alpha-masked leaf cards, two levels of detail, a
//! `UCX_` hull), a bush, a fern, a rock (normal-mapped, two levels) and meadow flowers
//! (three colours in one file, a root node each).

mod cards;
pub mod flowers;
pub mod plants;
pub mod textures;
pub mod trees;

use crate::generated::write_asset;

/// The pack's files under the asset folder, by what they hold.
pub struct Pack {
    /// The trees: spruce, oak, birch.
    pub trees: [&'static str; 3],
    /// A bush.
    pub bush: &'static str,
    /// A fern.
    pub fern: &'static str,
    /// A boulder.
    pub rock: &'static str,
    /// Flowers, a root node per colour (see [`flowers::FLOWERS`]).
    pub flowers: &'static str,
}

/// Where the pack is written.
pub const PACK: Pack = Pack {
    trees: [
        "generated/pack/spruce.glb",
        "generated/pack/oak.glb",
        "generated/pack/birch.glb",
    ],
    bush: "generated/pack/bush.glb",
    fern: "generated/pack/fern.glb",
    rock: "generated/pack/rock.glb",
    flowers: "generated/pack/flowers.glb",
};

/// Writes the pack where the asset server reads it, at [`PACK`]'s paths (each file only
/// when it changed).
pub fn write_pack() {
    let species = [trees::spruce(), trees::oak(), trees::birch()];
    for (tree, path) in species.iter().zip(PACK.trees) {
        write_asset(path, &trees::tree(tree).to_bytes());
    }
    write_asset(PACK.bush, &plants::bush().to_bytes());
    write_asset(PACK.fern, &plants::fern().to_bytes());
    write_asset(PACK.rock, &plants::rock().to_bytes());
    write_asset(PACK.flowers, &flowers::flowers().to_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_rwt::testing::glb::{Glb, GlbAlpha};

    /// The vertices of the mesh of the node named `name`.
    fn vertices(file: &Glb, name: &str) -> usize {
        let node = file.nodes.iter().find(|n| n.name == name).expect(name);
        let mesh = node.mesh.expect("a mesh");
        file.meshes[mesh].iter().map(|p| p.positions.len()).sum()
    }

    #[test]
    fn trees_have_two_levels_that_thin_and_a_hull_round_the_trunk() {
        for (i, spec) in [trees::spruce(), trees::oak(), trees::birch()]
            .iter()
            .enumerate()
        {
            let file = trees::tree(spec);
            let name = spec.name;
            let (near, far) = (
                vertices(&file, &format!("{name}_LOD0")),
                vertices(&file, &format!("{name}_LOD1")),
            );
            assert!(far * 3 < near, "{name}: {near} then {far} vertices");
            let hull = file
                .nodes
                .iter()
                .find(|n| n.name == format!("UCX_{name}"))
                .and_then(|n| n.mesh)
                .expect("a hull");
            let widest = file.meshes[hull][0]
                .positions
                .iter()
                .map(|p| glam::Vec2::new(p[0], p[2]).length())
                .fold(0.0f32, f32::max);
            assert!(
                (widest - trees::hull_radius(i)).abs() < 1e-4,
                "{name}: {widest}"
            );
            // Bark with a normal map, leaves cut out.
            assert!(file.materials[0].normal_texture.is_some());
            assert_eq!(file.materials[1].alpha, GlbAlpha::Mask(0.5));
        }
    }

    #[test]
    fn normal_maps_hold_unit_normals_facing_out_of_the_surface() {
        for maps in [textures::bark(1, [0.5; 3], [0.1; 3]), textures::rock(2)] {
            let image = image::load_from_memory(&maps.normal).unwrap().to_rgb8();
            for p in image.pixels().step_by(97) {
                let n = glam::Vec3::from_array(p.0.map(|c| c as f32 / 255.0 * 2.0 - 1.0));
                assert!((n.length() - 1.0).abs() < 0.02 && n.z > 0.2, "{n}");
            }
            let albedo = image::load_from_memory(&maps.albedo).unwrap().to_rgb8();
            assert_eq!(albedo.dimensions(), image.dimensions());
        }
    }

    #[test]
    fn flowers_are_a_root_each_with_a_lighter_far_level_in_their_own_colours() {
        let file = flowers::flowers();
        let image = image::load_from_memory(&file.images[0]).unwrap().to_rgb8();
        let roots: Vec<&str> = file
            .roots
            .iter()
            .map(|r| file.nodes[*r].name.as_str())
            .collect();
        assert_eq!(roots, ["red", "yellow", "blue"]);
        for (name, petal, _) in flowers::FLOWERS {
            let near = vertices(&file, &format!("{name}_LOD0"));
            let far = vertices(&file, &format!("{name}_LOD1"));
            assert!(far * 3 < near * 2, "{name}: {near} then {far} vertices");
            // The petals' texture coordinates land on the flower's own petal colour.
            let node = file.nodes.iter().find(|n| n.name == format!("{name}_LOD0"));
            let primitive = &file.meshes[node.unwrap().mesh.unwrap()][0];
            let top = (0..primitive.positions.len())
                .max_by(|a, b| primitive.positions[*a][1].total_cmp(&primitive.positions[*b][1]))
                .unwrap();
            let petal_uv = primitive.uvs.as_ref().unwrap()[top + 1];
            let (w, h) = image.dimensions();
            let texel = image.get_pixel(
                (petal_uv[0] * w as f32) as u32,
                (petal_uv[1] * h as f32) as u32,
            );
            assert_eq!(texel.0, petal, "{name}");
        }
    }

    #[test]
    fn leaf_clusters_are_cut_out_cards() {
        let png = textures::leaf_cluster(textures::Leaves {
            count: 12,
            size: (0.3, 0.12),
            colours: ([0.3, 0.5, 0.1], [0.2, 0.3, 0.1]),
            seed: 1,
        });
        let image = image::load_from_memory(&png).unwrap().to_rgba8();
        let opaque = image.pixels().filter(|p| p.0[3] == 255).count();
        let clear = image.pixels().filter(|p| p.0[3] == 0).count();
        let total = image.pixels().count();
        // Only fully opaque or fully clear texels: a mask, with room between the leaves.
        assert_eq!(opaque + clear, total);
        assert!(
            opaque > total / 5 && clear > total / 4,
            "{opaque} of {total}"
        );
    }
}

//! The showcase's asset pack: glTF files the examples write themselves (nothing is
//! downloaded), as a game's artist would ship them, for rwt to scatter as asset classes.
//! Three trees (bark with a normal map, alpha-masked leaf cards, two levels of detail, a
//! `UCX_` hull), a bush, a fern and a rock (normal-mapped, two levels).

mod cards;
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
};

/// Writes the pack where the asset server reads it (each file only when it changed).
pub fn write_pack() -> &'static Pack {
    let species = [trees::spruce(), trees::oak(), trees::birch()];
    for (tree, path) in species.iter().zip(PACK.trees) {
        write_asset(path, &trees::tree(tree).to_bytes());
    }
    write_asset(PACK.bush, &plants::bush().to_bytes());
    write_asset(PACK.fern, &plants::fern().to_bytes());
    write_asset(PACK.rock, &plants::rock().to_bytes());
    &PACK
}

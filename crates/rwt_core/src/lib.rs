//! # rwt_core: recursive Wang tiles for real-time blue noise
//!
//! An implementation of *Recursive Wang Tiles for Real-Time Blue Noise* (Kopf, Cohen-Or,
//! Deussen, Lischinski, SIGGRAPH 2006), engine-agnostic (glam only).
//!
//! The work splits in two:
//!
//! - **Construction**, offline and deterministic from a seed ([`construction::build`]):
//!   progressive source tiles ([`source_tile`]), Wang tiles merged along Voronoi seams
//!   ([`seam`]), subdivision rules ([`subdivision`]), relaxation to the exact subset property
//!   ([`relaxation`]) and progressive rankings with spacing guaranteed across tile borders
//!   ([`progressive`]). The result is a [`tileset::TileSet`]; one is shipped and embedded.
//! - **Use**, at run time: [`tiling::Tiling`] places tiles anywhere in O(1) by hashing edge
//!   colours, and the tile set's rankings give points at any density.
//!
//! ```
//! use rwt_core::tileset::TileSet;
//! use rwt_core::tiling::Tiling;
//!
//! let set = TileSet::embedded();
//! assert_eq!(set.tiles.len(), 16); // complete set of 2 colours: 2^4 tiles
//! let tiling = Tiling::new(&set, 42);
//! // Neighbouring tiles always agree on their shared edge, anywhere in the plane.
//! let (a, b) = (tiling.base_tile(1_000_000, -7), tiling.base_tile(1_000_001, -7));
//! assert_eq!(set.tiles[a as usize].edges.east, set.tiles[b as usize].edges.west);
//! ```
//!
//! Loading a tile set validates it and reports problems as [`tileset::TileSetError`]:
//!
//! ```
//! use rwt_core::tileset::{TileSet, TileSetError};
//! assert!(matches!(TileSet::from_ron_bytes(b"(format: 1"), Err(TileSetError::Parse(_))));
//! ```

pub mod analysis;
pub mod check;
pub mod construction;
pub mod density;
pub mod geometry;
pub mod progressive;
pub mod query;
pub mod relaxation;
pub mod rng;
pub mod seam;
pub mod source_tile;
pub mod subdivision;
pub mod tileset;
pub mod tiling;
pub mod wang;

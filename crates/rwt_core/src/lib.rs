//! # rwt_core: recursive Wang tiles for real-time blue noise
//!
//! An implementation of *Recursive Wang Tiles for Real-Time Blue Noise* (Kopf, Cohen-Or,
//! Deussen, Lischinski, SIGGRAPH 2006), engine-agnostic (glam only).
//!
//! The work splits in two:
//!
//! - **Construction**, offline and deterministic from a seed (`construction::build`, with
//!   the `build` feature): progressive source tiles, Wang tiles merged along Voronoi seams,
//!   subdivision rules, relaxation to the exact subset property and progressive rankings
//!   with spacing guaranteed across tile borders. The result is a [`TileSet`]; one is
//!   shipped and embedded ([`TileSet::embedded`]). Games that only query need none of the
//!   builder, and do not compile its dependencies (spade, rayon).
//! - **Use**, at run time: [`Tiling`] places tiles anywhere in O(1) by hashing edge
//!   colours, and a [`Sampler`] turns the tile set's rankings into points at any density.
//!
//! | paper section | module |
//! |---|---|
//! | 3, 5.2 recursive tiling, queries | [`tiling`], [`query`] |
//! | 4 progressive source tiles, seams, rankings | `construction` (feature `build`) |
//! | 5.1 subdivision rules, 5.2 relaxation | `construction` (feature `build`) |
//! | 6.1 densities | [`density`] |
//! | 6.3 classes | [`Sampler::query_classes`] |
//! | figures' measurements | [`analysis`] |
//! | streaming and level of detail around viewers | [`streaming`] |
//!
//! ```
//! use rwt_core::{TileSet, Tiling};
//!
//! let set = TileSet::embedded();
//! assert_eq!(set.tiles.len(), 16); // complete set of 2 colours: 2^4 tiles
//! let tiling = Tiling::new(&set, 42);
//! // Neighbouring tiles always agree on their shared edge, anywhere in the plane.
//! let (a, b) = (tiling.base_tile(1_000_000, -7), tiling.base_tile(1_000_001, -7));
//! assert_eq!(set.tiles[a as usize].edges.east, set.tiles[b as usize].edges.west);
//! ```
//!
//! ## Queries
//!
//! A [`Sampler`] produces the points of any rectangle for any [`Density`] (points per unit
//! area). Each point has a stable [`PointId`], and the point set only
//! grows when the density grows, so chunked, streamed or zoomed views never see a point move:
//!
//! ```
//! use glam::DVec2;
//! use rwt_core::{Constant, NoiseDensity, NoiseParams, Rect, Sampler, TileSet};
//!
//! let set = TileSet::embedded();
//! let sampler = Sampler::new(&set, 7).with_tile_size(4.0); // base tiles 4 units wide
//! let rect = Rect::new(DVec2::ZERO, DVec2::new(8.0, 8.0)).unwrap();
//! let mut sparse = Vec::new();
//! sampler.query(rect, &Constant(20.0), &mut sparse).unwrap();
//! assert!((sparse.len() as f64 - 20.0 * 64.0).abs() < 40.0);
//!
//! // Raising the density only adds points; the old ones keep their place.
//! let mut dense = Vec::new();
//! sampler.query(rect, &Constant(50.0), &mut dense).unwrap();
//! assert!(sparse.iter().all(|p| dense.iter().any(|q| q.id == p.id && q.position == p.position)));
//!
//! // Classes share one point set; rotations are hashed from the identity.
//! let classes = [Constant(10.0), Constant(30.0)];
//! let mut n = [0; 2];
//! sampler.query_classes(rect, &classes, |p| n[p.class as usize] += 1).unwrap();
//! assert!(n[1] > 2 * n[0]);
//! let yaw = dense[0].id.rotation(7);
//! assert!((0.0..std::f64::consts::TAU).contains(&yaw));
//!
//! // Densities compose: fBm noise, painted images, closures, sums, masks, fall-off.
//! let noise = NoiseDensity::new(NoiseParams { frequency: 0.1, scale: 10.0, ..Default::default() });
//! let mut patchy = Vec::new();
//! sampler.query(rect, &noise, &mut patchy).unwrap();
//! assert!(patchy.len() < 10 * 64);
//! ```
//!
//! Bad input is a typed error, never a panic; loading a tile set validates it:
//!
//! ```
//! use rwt_core::{TileSet, TileSetError};
//! assert!(matches!(TileSet::from_ron_bytes(b"(format: 1"), Err(TileSetError::Parse(_))));
//! ```

pub mod analysis;
pub mod bench;
pub mod clumps;
#[cfg(feature = "build")]
pub mod construction;
#[cfg(feature = "build")]
pub mod dart_throwing;
pub mod density;
pub mod edits;
pub mod files;
mod geometry;
pub mod query;
pub mod rng;
pub mod stipple;
pub mod streaming;
pub mod tileset;
pub mod tiling;
pub mod wang;

pub use clumps::{ClumpKernel, ClumpParams, Clumps};
pub use density::{
    Constant, Density, DistanceFalloff, Exclude, FnDensity, ImageDensity, LocalModel, Mask,
    NoiseDensity, NoiseParams, Placement, Product, Scale, Sum, SumOf,
};
pub use query::{Lattice, Point, PointId, QueryError, Rect, Sampler};
pub use tileset::{TileSet, TileSetError};
pub use tiling::Tiling;

/// The README's examples, compiled and run as doctests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

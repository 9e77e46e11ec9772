//! rwt_core
pub mod analysis;
pub mod check;
pub mod construction;
pub mod geometry;
pub mod progressive;
pub mod relaxation;
pub mod rng;
pub mod seam;
pub mod source_tile;
pub mod subdivision;
pub mod tileset;
pub mod tiling;
pub mod wang;

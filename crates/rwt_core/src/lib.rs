//! rwt_core
pub mod geometry;
pub mod progressive;
pub mod rng;
pub mod seam;
pub mod source_tile;
pub mod subdivision;
pub mod tileset;
pub mod wang;

//! Point set analysis (paper section 6 and the figures' measurements): the normalized
//! minimum distance, nearest-neighbour statistics, averaged periodograms, the reference
//! point sets every figure is shown beside, and whole-tile-set checks.

pub mod check;
pub mod reference;
mod spectrum;
mod statistics;
mod windows;
pub mod zoneplate;

pub use crate::geometry::hex_spacing;
pub use spectrum::Spectrum;
pub use statistics::{min_distance, nearest_neighbour_distances, rho};
pub use windows::{MAX_WINDOW_POINTS, WindowAnalysis, WindowError, WindowGrid};

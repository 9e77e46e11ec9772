//! Tiles prepared for queries: points grouped by the cells of the subdivision.

use crate::tileset::{Tile, TileSet, fixed_to_unit};

/// A point of a tile's cell list: its rank in the list it comes from, its index in the tile
/// it belongs to, and its position in that tile.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellPoint {
    pub rank: u32,
    pub index: u16,
    pub frac: [f64; 2],
}

/// A tile prepared for queries: its points grouped by the `n x n` cells of its subdivision,
/// each group in rank order, so that a query bounds the density per cell and only touches
/// the cells it needs.
#[derive(Clone, Debug)]
pub(crate) struct PreparedTile {
    /// Base points by the cell they lie in (`rank` = base rank, `frac` in this tile).
    pub base_cells: Vec<Vec<CellPoint>>,
    /// Subdivision points of rank `N..n^2 N` by child cell (`index` and `frac` in the child).
    pub sub_cells: Vec<Vec<CellPoint>>,
    pub children: Vec<u16>,
    /// The tile's own points by index, in the tile (what [`super::Sampler::locate`] reads).
    pub points: Vec<[f64; 2]>,
}

impl PreparedTile {
    pub fn new(set: &TileSet, tile: &Tile) -> Self {
        Self {
            base_cells: base_cells(set, tile),
            sub_cells: sub_cells(set, tile),
            children: tile.children.clone(),
            points: tile
                .points
                .iter()
                .map(|p| [fixed_to_unit(p[0]), fixed_to_unit(p[1])])
                .collect(),
        }
    }
}

/// The tile's own points by the subdivision cell they lie in.
fn base_cells(set: &TileSet, tile: &Tile) -> Vec<Vec<CellPoint>> {
    let n = set.subdivision as usize;
    let mut cells = vec![Vec::new(); n * n];
    for (k, p) in tile.points.iter().enumerate() {
        let frac = [fixed_to_unit(p[0]), fixed_to_unit(p[1])];
        let cell = ((frac[1] * n as f64) as usize).min(n - 1) * n
            + ((frac[0] * n as f64) as usize).min(n - 1);
        cells[cell].push(CellPoint {
            rank: k as u32,
            index: k as u16,
            frac,
        });
    }
    cells
}

/// The subdivision ranking past the base points, by the child cell each point lies in.
fn sub_cells(set: &TileSet, tile: &Tile) -> Vec<Vec<CellPoint>> {
    let n = set.subdivision as usize;
    let mut cells = vec![Vec::new(); n * n];
    let skip = set.points_per_tile as usize;
    for (r, &e) in tile.subdivision.iter().enumerate().skip(skip) {
        let (cell, index) = ((e >> 16) as usize, (e & 0xffff) as u16);
        let q = set.tiles[tile.children[cell] as usize].points[index as usize];
        cells[cell].push(CellPoint {
            rank: r as u32,
            index,
            frac: [fixed_to_unit(q[0]), fixed_to_unit(q[1])],
        });
    }
    cells
}

//! Subdivision rules (paper section 5.1, figure 6).
//!
//! Every edge colour is replaced on subdivision by a unique sequence of `n` colours, so the
//! children along a shared parent edge match whichever tiles meet there. The `n x n`
//! interior is found by stochastic repair: start from random children, then repeatedly pick
//! a cell and replace its tile by one that violates no more constraints, until nothing is
//! violated. With our complete set the search always succeeds (any interior colouring names
//! existing tiles); for other sets it restarts with new sequences when it stalls.

use crate::rng::Rng;
use crate::wang::EdgeColors;

/// Subdivision rules for a tile set.
#[derive(Clone, Debug, PartialEq)]
pub struct Rules {
    /// `n`-colour sequence for each horizontal edge colour (west to east).
    pub horizontal: Vec<Vec<u8>>,
    /// `n`-colour sequence for each vertical edge colour (south to north).
    pub vertical: Vec<Vec<u8>>,
    /// For every tile, its `n * n` children, row-major from the south-west.
    pub children: Vec<Vec<u16>>,
}

/// Why no rules were found.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RulesError {
    /// Fewer possible sequences than colours: `K^n < K`.
    #[error("{colors} colours cannot have unique sequences of length {n}")]
    TooFewSequences {
        /// Colours.
        colors: u8,
        /// Sequence length.
        n: usize,
    },
    /// The repair search did not converge after every restart.
    #[error("no valid subdivision found after {0} restarts")]
    NoSolution(usize),
}

fn unique_sequences(k: u8, n: usize, rng: &mut Rng) -> Vec<Vec<u8>> {
    let mut seqs: Vec<Vec<u8>> = Vec::with_capacity(k as usize);
    while seqs.len() < k as usize {
        let s: Vec<u8> = (0..n).map(|_| rng.below(k as usize) as u8).collect();
        // A constant sequence would repeat one colour along a whole edge: avoid when possible.
        let constant = s.iter().all(|&c| c == s[0]) && k > 1;
        if !seqs.contains(&s) && !constant {
            seqs.push(s);
        }
    }
    seqs
}

fn violations(
    tiles: &[EdgeColors],
    grid: &[u16],
    n: usize,
    a: usize,
    b: usize,
    candidate: u16,
    border: &Border,
) -> usize {
    let t = &tiles[candidate as usize];
    let at = |a: usize, b: usize| &tiles[grid[b * n + a] as usize];
    let mut v = 0;
    v += usize::from(if a == 0 {
        t.west != border.west[b]
    } else {
        t.west != at(a - 1, b).east
    });
    v += usize::from(if a + 1 == n {
        t.east != border.east[b]
    } else {
        t.east != at(a + 1, b).west
    });
    v += usize::from(if b == 0 {
        t.south != border.south[a]
    } else {
        t.south != at(a, b - 1).north
    });
    v += usize::from(if b + 1 == n {
        t.north != border.north[a]
    } else {
        t.north != at(a, b + 1).south
    });
    v
}

struct Border<'a> {
    north: &'a [u8],
    east: &'a [u8],
    south: &'a [u8],
    west: &'a [u8],
}

/// Finds subdivision rules for `tiles` with `k` colours and factor `n`.
pub fn find_rules(tiles: &[EdgeColors], k: u8, n: usize, seed: u64) -> Result<Rules, RulesError> {
    if (k as f64).powi(n as i32) < k as f64 * 2.0 && k > 1 {
        return Err(RulesError::TooFewSequences { colors: k, n });
    }
    const RESTARTS: usize = 64;
    let mut rng = Rng::new(seed, 0x5d1);
    for _ in 0..RESTARTS {
        let horizontal = unique_sequences(k, n, &mut rng);
        let vertical = unique_sequences(k, n, &mut rng);
        let mut children = Vec::with_capacity(tiles.len());
        for t in tiles {
            let border = Border {
                north: &horizontal[t.north as usize],
                south: &horizontal[t.south as usize],
                east: &vertical[t.east as usize],
                west: &vertical[t.west as usize],
            };
            match repair(tiles, n, &border, &mut rng) {
                Some(grid) => children.push(grid),
                None => break,
            }
        }
        if children.len() == tiles.len() {
            return Ok(Rules {
                horizontal,
                vertical,
                children,
            });
        }
    }
    Err(RulesError::NoSolution(RESTARTS))
}

fn repair(tiles: &[EdgeColors], n: usize, border: &Border, rng: &mut Rng) -> Option<Vec<u16>> {
    let mut grid: Vec<u16> = (0..n * n).map(|_| rng.below(tiles.len()) as u16).collect();
    let max_steps = 2_000 * n * n;
    let total = |grid: &[u16]| -> usize {
        (0..n * n)
            .map(|i| violations(tiles, grid, n, i % n, i / n, grid[i], border))
            .sum()
    };
    let mut best: Vec<u16> = Vec::with_capacity(tiles.len());
    for _ in 0..max_steps {
        if total(&grid) == 0 {
            return Some(grid);
        }
        let cell = rng.below(n * n);
        let (a, b) = (cell % n, cell / n);
        let current = violations(tiles, &grid, n, a, b, grid[cell], border);
        best.clear();
        for c in 0..tiles.len() as u16 {
            if violations(tiles, &grid, n, a, b, c, border) <= current {
                best.push(c);
            }
        }
        grid[cell] = best[rng.below(best.len())];
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wang::complete_set_size;

    #[test]
    fn complete_sets_get_valid_rules() {
        for (k, n) in [(2u8, 2usize), (2, 4), (3, 2)] {
            let tiles: Vec<_> = (0..complete_set_size(k))
                .map(|i| EdgeColors::from_complete_index(i, k))
                .collect();
            let rules = find_rules(&tiles, k, n, 11).unwrap();
            for (t, grid) in rules.children.iter().enumerate() {
                let border = Border {
                    north: &rules.horizontal[tiles[t].north as usize],
                    south: &rules.horizontal[tiles[t].south as usize],
                    east: &rules.vertical[tiles[t].east as usize],
                    west: &rules.vertical[tiles[t].west as usize],
                };
                for i in 0..n * n {
                    assert_eq!(
                        violations(&tiles, grid, n, i % n, i / n, grid[i], &border),
                        0
                    );
                }
            }
            for s in [&rules.horizontal, &rules.vertical] {
                assert_eq!(s.len(), k as usize);
                assert!(s.iter().enumerate().all(|(i, a)| !s[i + 1..].contains(a)));
            }
        }
    }
}

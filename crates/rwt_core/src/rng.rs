//! Deterministic random numbers and integer hashes.
//!
//! Everything rwt produces must be bit-identical on every platform for the same seed, so the
//! generator and hashes here are plain integer arithmetic (no platform `libm`, no external
//! RNG whose stream could change between versions).

/// SplitMix64 finaliser: a fast, well-mixed 64-bit hash of one word.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hashes a sequence of words into one, order-sensitive.
#[inline]
pub fn hash_words(seed: u64, words: &[u64]) -> u64 {
    let mut h = mix64(seed ^ 0x9e37_79b9_7f4a_7c15);
    for &w in words {
        h = mix64(h ^ w.wrapping_mul(0x2545_f491_4f6c_dd1d));
    }
    h
}

/// 64-bit FNV-1a of `bytes`: the same on every platform and build, for names and
/// fingerprints of data (not for hashing points: see [`hash_words`]).
///
/// ```
/// assert_eq!(rwt_core::rng::fnv1a(b""), 0xcbf2_9ce4_8422_2325);
/// assert_eq!(rwt_core::rng::fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
/// ```
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Maps a hash to a float uniformly distributed in `[0, 1)` (53 random bits).
#[inline]
pub fn unit_f64(h: u64) -> f64 {
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A small deterministic generator (SplitMix64 stream). Not cryptographic.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// Creates a generator from a seed and a stream label, so that independent stages that
    /// share a seed never share a stream.
    pub fn new(seed: u64, stream: u64) -> Self {
        Self {
            state: hash_words(seed, &[stream]),
        }
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(self.state)
    }

    /// Uniform float in `[0, 1)`.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        unit_f64(self.next_u64())
    }

    /// Uniform integer in `0..n` (`n > 0`), without modulo bias worth caring about for the
    /// small `n` used here (Lemire's multiply-shift).
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }

    /// Fisher-Yates shuffle.
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = self.below(i + 1);
            items.swap(i, j);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..8)
            .map({
                let mut r = Rng::new(7, 1);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..8)
            .map({
                let mut r = Rng::new(7, 1);
                move |_| r.next_u64()
            })
            .collect();
        let c: Vec<u64> = (0..8)
            .map({
                let mut r = Rng::new(7, 2);
                move |_| r.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn below_stays_in_range_and_covers_it() {
        let mut r = Rng::new(1, 0);
        let mut seen = [0usize; 5];
        for _ in 0..10_000 {
            seen[r.below(5)] += 1;
        }
        assert!(seen.iter().all(|&s| s > 1_800 && s < 2_200), "{seen:?}");
    }

    #[test]
    fn unit_is_in_unit_interval() {
        for h in [0, 1, u64::MAX, 0x8000_0000_0000_0000] {
            let u = unit_f64(h);
            assert!((0.0..1.0).contains(&u));
        }
    }
}

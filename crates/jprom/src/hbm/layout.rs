//! Layout of the HBM unknowns: `z = [z_0; z_1c; z_1s; ...; z_Hc; z_Hs]`, with `n_h` entries
//! per part of harmonic `h` (`n_h` may differ between harmonics in reduced models).

use serde::{Deserialize, Serialize};

/// Sizes and offsets of the unknowns of each harmonic.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct HarmonicLayout {
    /// Highest harmonic `H`.
    pub harmonics: usize,
    /// `n_h` for `h = 0..=H`.
    pub sizes: Vec<usize>,
}

impl HarmonicLayout {
    /// The same `n` unknowns for every harmonic.
    pub fn uniform(harmonics: usize, n: usize) -> Self {
        HarmonicLayout { harmonics, sizes: vec![n; harmonics + 1] }
    }
    /// Per-harmonic sizes (`sizes.len() == H + 1`).
    pub fn new(sizes: Vec<usize>) -> Self {
        assert!(!sizes.is_empty());
        HarmonicLayout { harmonics: sizes.len() - 1, sizes }
    }
    /// `n_h`.
    pub fn size(&self, h: usize) -> usize {
        self.sizes[h]
    }
    /// Total number of unknowns `n_0 + 2 sum_{h>=1} n_h`.
    pub fn total(&self) -> usize {
        self.sizes[0] + 2 * self.sizes[1..].iter().sum::<usize>()
    }
    /// Offset of `z_0` (always 0).
    pub fn static_offset(&self) -> usize {
        0
    }
    /// Offset of `z_hc`, `h >= 1`.
    pub fn cos_offset(&self, h: usize) -> usize {
        assert!(h >= 1 && h <= self.harmonics);
        self.sizes[0] + 2 * self.sizes[1..h].iter().sum::<usize>()
    }
    /// Offset of `z_hs`, `h >= 1`.
    pub fn sin_offset(&self, h: usize) -> usize {
        self.cos_offset(h) + self.sizes[h]
    }
    /// Offset and length of coefficient `k` (`0`, `2h - 1` cos, `2h` sin).
    pub fn coeff_range(&self, k: usize) -> (usize, usize) {
        if k == 0 {
            (0, self.sizes[0])
        } else {
            let h = (k + 1) / 2;
            let off = if k % 2 == 1 { self.cos_offset(h) } else { self.sin_offset(h) };
            (off, self.sizes[h])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_tile_the_vector() {
        let l = HarmonicLayout::new(vec![4, 3, 2]);
        assert_eq!(l.total(), 4 + 6 + 4);
        let mut covered = vec![0; l.total()];
        for k in 0..5 {
            let (o, n) = l.coeff_range(k);
            for c in &mut covered[o..o + n] {
                *c += 1;
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
        assert_eq!(l.cos_offset(2), 10);
        assert_eq!(l.sin_offset(2), 12);
    }
}

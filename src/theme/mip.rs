//! Mip levels of a class-index map. Indices cannot be blended like colours (Vyatkin et al. 2018,
//! §V): a texel of level l keeps the class that wholly covers its 2^l × 2^l footprint of level 0;
//! where no class does, it keeps the class that covers most of the footprint (ties → the
//! smaller index), so details smaller than the texel are dropped and no level ever holds a
//! class absent from the texels it covers. A lone one-texel island vanishes at level 1, where
//! it covers a quarter texel. The texture lookup then filters within the chosen theme only.
//!
//! Each level is computed from level 0 (not from the level below, whose majorities would
//! compound), W·H work per level.

use super::index_map::IndexMap;
use rayon::prelude::*;

/// Level 0 (the map) and its coarser levels down to 1×1.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IndexMips {
    pub levels: Vec<IndexMap>,
}

impl IndexMips {
    /// All levels of `map` (level l is ⌈W/2^l⌉ × ⌈H/2^l⌉).
    pub fn build(map: IndexMap) -> IndexMips {
        let mut levels = vec![];
        let mut l = 1;
        loop {
            let s = 1usize << l;
            if s / 2 >= map.width.max(map.height) {
                break;
            }
            levels.push(level(&map, l));
            l += 1;
        }
        levels.insert(0, map);
        IndexMips { levels }
    }

    /// Texels of level `l` whose footprint holds more than one class (kept by majority).
    pub fn mixed(&self, l: usize) -> usize {
        if l == 0 {
            return 0;
        }
        let base = &self.levels[0];
        let m = &self.levels[l];
        let s = 1usize << l;
        (0..m.height)
            .into_par_iter()
            .map(|r| {
                (0..m.width)
                    .filter(|&c| {
                        let first = base.at(c * s, r * s);
                        footprint(base, c, r, s).any(|v| v != first)
                    })
                    .count()
            })
            .sum()
    }

    /// Bytes of all levels at one byte per texel.
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|m| m.data.len()).sum()
    }
}

/// The level-0 classes under texel (c, r) of a level with footprint s×s (clipped to the map).
fn footprint(base: &IndexMap, c: usize, r: usize, s: usize) -> impl Iterator<Item = u8> + '_ {
    let (x1, y1) = (
        ((c + 1) * s).min(base.width),
        ((r + 1) * s).min(base.height),
    );
    (r * s..y1).flat_map(move |y| (c * s..x1).map(move |x| base.at(x, y)))
}

fn level(base: &IndexMap, l: usize) -> IndexMap {
    let s = 1usize << l;
    let (w, h) = (base.width.div_ceil(s), base.height.div_ceil(s));
    let mut data = vec![0u8; w * h];
    data.par_chunks_mut(w).enumerate().for_each(|(r, out)| {
        let mut counts: Vec<(u8, usize)> = Vec::with_capacity(8);
        for (c, o) in out.iter_mut().enumerate() {
            counts.clear();
            for v in footprint(base, c, r, s) {
                match counts.iter_mut().find(|(k, _)| *k == v) {
                    Some(e) => e.1 += 1,
                    None => counts.push((v, 1)),
                }
            }
            // Most texels; ties → the smaller index.
            *o = counts
                .iter()
                .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
                .map(|e| e.0)
                .unwrap_or(0);
        }
    });
    IndexMap {
        width: w,
        height: h,
        data,
    }
}

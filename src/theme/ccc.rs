//! Colour Cell Compression of a class-index map (Campbell et al. 1986, cited by Vyatkin et
//! al. 2018 for "up to six times"): per 4×4 block two classes and a 16-bit mask choosing between
//! them, one 32-bit word per 16 texels — 2 bits per texel instead of 8, random access in one fetch.
//!
//! Plain CCC is lossy where three or more classes meet in a block (the extra classes take the
//! block's most frequent one). Index maps are made of large contiguous regions, so such blocks
//! are rare; relume stores them whole in an exception table instead, which makes the code
//! lossless at a measured cost ([`Ccc::bytes`]; docs/themes.md has the numbers): a word whose
//! first class is 255 (never a class) holds in its upper 24 bits the slot of the block's 16
//! raw bytes. Decoding is then one fetch, or two in an exception block (`theme.wgsl`'s
//! `class_at` is the twin of [`Ccc::at`]).
//!
//! Word layout: bits 0–7 class a, 8–15 class b, 16–31 mask (bit k set → texel k of the block,
//! row-major, is b). Texels past the map's edge in a border block copy the block's first texel.

use super::index_map::IndexMap;

/// The reserved class byte that marks an exception block.
pub const EXCEPTION: u8 = 255;

/// A compressed index map.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ccc {
    pub width: usize,
    pub height: usize,
    /// One word per 4×4 block, row-major over ⌈W/4⌉ × ⌈H/4⌉ blocks.
    pub words: Vec<u32>,
    /// The raw texels of blocks with more than two classes (empty when lossy).
    pub exceptions: Vec<[u8; 16]>,
    /// Texels whose class changed (0 with exceptions).
    pub lossy_texels: usize,
}

fn block_texels(map: &IndexMap, bx: usize, by: usize) -> [u8; 16] {
    let first = map.at(bx * 4, by * 4);
    std::array::from_fn(|k| {
        let (x, y) = (bx * 4 + k % 4, by * 4 + k / 4);
        if x < map.width && y < map.height {
            map.at(x, y)
        } else {
            first
        }
    })
}

impl Ccc {
    /// Compress `map` (classes must be < 255). `exceptions`: keep blocks with more than two
    /// classes whole (lossless) instead of reducing them to their two most frequent classes.
    pub fn encode(map: &IndexMap, exceptions: bool) -> Ccc {
        let (bw, bh) = (map.width.div_ceil(4), map.height.div_ceil(4));
        let mut words = Vec::with_capacity(bw * bh);
        let mut table = Vec::new();
        let mut lossy = 0;
        for by in 0..bh {
            for bx in 0..bw {
                let t = block_texels(map, bx, by);
                let mut counts: Vec<(u8, usize)> = Vec::with_capacity(4);
                for &v in &t {
                    match counts.iter_mut().find(|(k, _)| *k == v) {
                        Some(e) => e.1 += 1,
                        None => counts.push((v, 1)),
                    }
                }
                if counts.len() > 2 && exceptions {
                    words.push(EXCEPTION as u32 | (table.len() as u32) << 8);
                    table.push(t);
                    continue;
                }
                // Most frequent first; ties → smaller index.
                counts.sort_by(|x, y| y.1.cmp(&x.1).then(x.0.cmp(&y.0)));
                let a = counts[0].0;
                let b = counts.get(1).map_or(a, |e| e.0);
                let mut mask = 0u32;
                for (k, &v) in t.iter().enumerate() {
                    if v == b && b != a {
                        mask |= 1 << k;
                    } else if v != a {
                        let (x, y) = (bx * 4 + k % 4, by * 4 + k / 4);
                        if x < map.width && y < map.height {
                            lossy += 1;
                        }
                    }
                }
                words.push(a as u32 | (b as u32) << 8 | mask << 16);
            }
        }
        Ccc {
            width: map.width,
            height: map.height,
            words,
            exceptions: table,
            lossy_texels: lossy,
        }
    }

    /// The class at texel (col, row).
    pub fn at(&self, col: usize, row: usize) -> u8 {
        let bw = self.width.div_ceil(4);
        let w = self.words[(row / 4) * bw + col / 4];
        let k = (row % 4) * 4 + col % 4;
        if (w & 0xff) as u8 == EXCEPTION {
            return self.exceptions[(w >> 8) as usize][k];
        }
        if (w >> (16 + k)) & 1 == 1 {
            (w >> 8) as u8
        } else {
            w as u8
        }
    }

    /// The whole map back.
    pub fn decode(&self) -> IndexMap {
        let data = (0..self.height)
            .flat_map(|r| (0..self.width).map(move |c| (c, r)))
            .map(|(c, r)| self.at(c, r))
            .collect();
        IndexMap {
            width: self.width,
            height: self.height,
            data,
        }
    }

    /// Bytes: 4 per block plus 16 per exception block.
    pub fn bytes(&self) -> usize {
        self.words.len() * 4 + self.exceptions.len() * 16
    }
}

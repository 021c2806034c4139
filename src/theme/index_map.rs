//! The class-index map (the "service buffer" of pointers to themes and border kinds of
//! Vyatkin et al. 2018), made one of three ways:
//! - by rules over a height map ([`from_rules`]): height, slope and aspect per texel, the first
//!   matching rule wins (water below a level, sand, forest, rock, snow);
//! - from an image ([`from_keys`]): each pixel's colour (grey or RGB) names a class;
//! - by rasterising polygons ([`rasterize`]): even-odd fill of each polygon's rings at texel
//!   centres, later polygons over earlier ones, over a background class.
//!
//! Texel (column j, row i) covers [j, j+1) × [i, i+1) and is decided at its centre (README
//! "Conventions"); row 0 is the north edge.

use crate::heightmap::HeightMap;
use serde::{Deserialize, Serialize};

/// A W×H map of class indices (row-major, row 0 = north).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IndexMap {
    pub width: usize,
    pub height: usize,
    pub data: Vec<u8>,
}

impl IndexMap {
    /// A map filled with `class`.
    pub fn filled(width: usize, height: usize, class: u8) -> Self {
        IndexMap {
            width,
            height,
            data: vec![class; width * height],
        }
    }

    pub fn at(&self, col: usize, row: usize) -> u8 {
        self.data[row * self.width + col]
    }

    /// Texels per class (256 entries).
    pub fn histogram(&self) -> Vec<usize> {
        let mut h = vec![0usize; 256];
        for &c in &self.data {
            h[c as usize] += 1;
        }
        h
    }
}

/// An inclusive range `[min, max]`; an open side is ±∞.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Range {
    #[serde(default = "neg_inf")]
    pub min: f64,
    #[serde(default = "pos_inf")]
    pub max: f64,
}

fn neg_inf() -> f64 {
    f64::NEG_INFINITY
}
fn pos_inf() -> f64 {
    f64::INFINITY
}

impl Range {
    fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// A rule: texels whose height (metres), slope (degrees from horizontal) and aspect (degrees
/// clockwise from north of the downhill direction; a range may wrap, e.g. 300..60) all fall in
/// the given ranges get `class`. A missing range matches everything.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    pub class: u8,
    pub height: Option<Range>,
    pub slope: Option<Range>,
    pub aspect: Option<Range>,
}

/// Slope (degrees) and aspect (degrees clockwise from north, downhill; 0 on flat ground) at a
/// texel from central differences (one-sided at the border), in metres.
pub fn slope_aspect(map: &HeightMap, col: usize, row: usize) -> (f64, f64) {
    let (dzdx, dzdy) = map.gradient(col, row);
    let slope = dzdx.hypot(dzdy).atan().to_degrees();
    let aspect = if dzdx == 0.0 && dzdy == 0.0 {
        0.0
    } else {
        (-dzdx).atan2(-dzdy).to_degrees().rem_euclid(360.0)
    };
    (slope, aspect)
}

fn aspect_matches(r: &Range, a: f64) -> bool {
    if r.min <= r.max {
        r.contains(a)
    } else {
        a >= r.min || a <= r.max
    }
}

/// The class map of `map` by `rules` (first match wins; none matches → `otherwise`).
pub fn from_rules(map: &HeightMap, rules: &[Rule], otherwise: u8) -> IndexMap {
    use rayon::prelude::*;
    let w = map.width;
    let mut data = vec![otherwise; w * map.height];
    data.par_chunks_mut(w).enumerate().for_each(|(row, out)| {
        for (col, o) in out.iter_mut().enumerate() {
            let z = map.at(col, row) as f64;
            let (slope, aspect) = slope_aspect(map, col, row);
            let hit = rules.iter().find(|r| {
                r.height.is_none_or(|h| h.contains(z))
                    && r.slope.is_none_or(|s| s.contains(slope))
                    && r.aspect.is_none_or(|a| aspect_matches(&a, aspect))
            });
            if let Some(r) = hit {
                *o = r.class;
            }
        }
    });
    IndexMap {
        width: w,
        height: map.height,
        data,
    }
}

/// The class map of an RGB image by colour keys; Err((col, row, colour)) names the first pixel
/// whose colour has no key.
pub fn from_keys(
    width: usize,
    height: usize,
    pixels: &[[u8; 3]],
    keys: &[([u8; 3], u8)],
) -> Result<IndexMap, (usize, usize, [u8; 3])> {
    let mut data = Vec::with_capacity(pixels.len());
    for (i, p) in pixels.iter().enumerate() {
        match keys.iter().find(|(k, _)| k == p) {
            Some(&(_, class)) => data.push(class),
            None => return Err((i % width, i / width, *p)),
        }
    }
    Ok(IndexMap {
        width,
        height,
        data,
    })
}

/// A polygon with holes in index-map texel coordinates (x east, y south; (0, 0) = the map's
/// north-west corner): the first ring is the outline, the others holes (even-odd fill, so
/// orientation does not matter).
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    pub class: u8,
    pub rings: Vec<Vec<[f64; 2]>>,
}

/// Rasterise `polygons` in order over `background`: a texel takes the class of the last
/// polygon containing its centre.
pub fn rasterize(width: usize, height: usize, background: u8, polygons: &[Polygon]) -> IndexMap {
    let mut map = IndexMap::filled(width, height, background);
    let mut xs: Vec<f64> = Vec::new();
    for poly in polygons {
        for row in 0..height {
            let y = row as f64 + 0.5;
            xs.clear();
            for ring in &poly.rings {
                let n = ring.len();
                for i in 0..n {
                    let (a, b) = (ring[i], ring[(i + 1) % n]);
                    // Half-open in y so a vertex on the scanline counts once.
                    if (a[1] <= y) != (b[1] <= y) {
                        xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
                    }
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                // Texel centres col + 0.5 in [x0, x1).
                let c0 = (pair[0] - 0.5).ceil().max(0.0) as usize;
                let c1 = ((pair[1] - 0.5).ceil().max(0.0) as usize).min(width);
                for col in c0..c1 {
                    map.data[row * width + col] = poly.class;
                }
            }
        }
    }
    map
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rasterised_square_with_hole_matches_point_in_polygon() {
        let outer = vec![[2.0, 2.0], [14.0, 2.0], [14.0, 14.0], [2.0, 14.0]];
        let hole = vec![[6.0, 6.0], [10.0, 6.0], [10.0, 10.0], [6.0, 10.0]];
        let poly = Polygon {
            class: 3,
            rings: vec![outer, hole],
        };
        let m = rasterize(16, 16, 1, &[poly]);
        for row in 0..16 {
            for col in 0..16 {
                let (x, y) = (col as f64 + 0.5, row as f64 + 0.5);
                let inside_outer = (2.0..14.0).contains(&x) && (2.0..14.0).contains(&y);
                let inside_hole = (6.0..10.0).contains(&x) && (6.0..10.0).contains(&y);
                let want = if inside_outer && !inside_hole { 3 } else { 1 };
                assert_eq!(m.at(col, row), want, "texel {col},{row}");
            }
        }
    }

    #[test]
    fn aspect_of_a_slope_falling_east_is_90() {
        let map = HeightMap {
            width: 3,
            height: 3,
            heights: (0..9).map(|i| -((i % 3) as f32)).collect(),
            cell_size: [1.0, 1.0],
            height_scale: 1.0,
        };
        let (slope, aspect) = slope_aspect(&map, 1, 1);
        assert!((slope - 45.0).abs() < 1e-9 && (aspect - 90.0).abs() < 1e-9);
    }
}

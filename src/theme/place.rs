//! Where polygon vertices land on the index map: from the coordinates a theme file gives them
//! in ([`Coordinates`]) to index-map texels (x east, y south, (0, 0) the north-west corner).
//!
//! `LonLat` and `Map` vertices go through the georeference of the height map the index map
//! covers: to the height map's texel space (column, row; texel centres at +0.5, as
//! [`GeoReference::model_xy`]), then scaled by (index size)/(height-map size), as the player
//! maps a height-map texel to the index map. Only the vertices are converted: an edge is the
//! straight line between them in the height map's grid, as `gdal_rasterize` draws a reprojected
//! polygon (RFC 7946 calls an edge straight in longitude/latitude; the two differ by the edge's
//! curvature in the grid, see docs/themes.md).

use super::spec::Coordinates;
use crate::heightmap::georef::{Crs, GeoReference};

/// How to turn one theme-file vertex into index texels (see [`Placement::texel`]).
#[derive(Clone, Debug)]
pub struct Placement<'a> {
    coordinates: Coordinates,
    /// The index map's size.
    index: [f64; 2],
    /// The height map's georeference and size (for `LonLat` and `Map`).
    grid: Option<(&'a GeoReference, [usize; 2])>,
}

impl<'a> Placement<'a> {
    /// The placement of `coordinates` on an index map of `index` (width, height) texels.
    /// `grid` is the height map's georeference (None when it has none) and its size; it is read
    /// only for `LonLat` and `Map`, which fail without a georeference that inverts (a tiepoint
    /// and pixel scale, or an invertible transformation), and `LonLat` also on a CRS relume
    /// cannot convert longitude and latitude into. Err says why, in words that follow the name
    /// of the height map ("… has no georeference").
    pub fn new(
        coordinates: Coordinates,
        index: (usize, usize),
        grid: (Option<&'a GeoReference>, [usize; 2]),
    ) -> Result<Self, String> {
        let mut placement = Placement {
            coordinates,
            index: [index.0 as f64, index.1 as f64],
            grid: None,
        };
        if !coordinates.georeferenced() {
            return Ok(placement);
        }
        let (Some(georef), size) = grid else {
            return Err(
                "has no georeference (no GeoTIFF georeference tags: PNG, JPEG, EXR and \
                        raw height maps never have one)"
                    .into(),
            );
        };
        let corner = georef.model_xy(0.0, 0.0);
        if corner
            .and_then(|[x, y]| georef.texel_of_model(x, y))
            .is_none()
        {
            return Err(
                "has a georeference without a usable tiepoint and pixel scale or an \
                        invertible transformation matrix"
                    .into(),
            );
        }
        if coordinates == Coordinates::LonLat && !georef.reads_lat_lon() {
            let crs = match georef.crs() {
                Crs::Other { epsg: Some(code) } => format!("EPSG:{code}"),
                Crs::Other { epsg: None } => "a CRS named by no EPSG code".into(),
                _ => "geographic in an angular unit other than degrees".into(),
            };
            return Err(format!(
                "is in {crs}, and relume converts longitude/latitude only into a geographic CRS \
                 in degrees or UTM (EPSG 326zz/327zz, NAD83 269zz): give the polygons in `Map` \
                 coordinates (the height map's own CRS), or reproject the height map \
                 (gdalwarp -t_srs EPSG:326zz)"
            ));
        }
        placement.grid = Some((georef, size));
        Ok(placement)
    }

    /// Vertex `p` in index texels. Err names the problem with `p` (a latitude beyond ±90°, or a
    /// position no finite texel corresponds to). A vertex outside the map is fine: the
    /// rasteriser clips the polygon to the map.
    pub fn texel(&self, p: [f64; 2]) -> Result<[f64; 2], String> {
        let [x, y] = p;
        let (georef, size) = match (self.coordinates, self.grid) {
            (Coordinates::Texels, _) => return Ok(p),
            (Coordinates::Unit, _) => return Ok([x * self.index[0], y * self.index[1]]),
            (_, Some(grid)) => grid,
            (_, None) => unreachable!("Placement::new keeps the grid of georeferenced coordinates"),
        };
        let texel = match self.coordinates {
            Coordinates::LonLat => {
                if !(x.is_finite() && (-90.0..=90.0).contains(&y)) {
                    return Err(format!(
                        "position [{x}, {y}] is not [longitude, latitude] in degrees (the \
                         latitude must be within ±90°; coordinates in the height map's own CRS \
                         are `coordinates: Map`)"
                    ));
                }
                georef.texel_of_lat_lon(y, x, size)
            }
            _ => georef.texel_of_model(x, y),
        };
        let scale = [
            self.index[0] / size[0] as f64,
            self.index[1] / size[1] as f64,
        ];
        match texel {
            Some([c, r]) if (c * scale[0]).is_finite() && (r * scale[1]).is_finite() => {
                Ok([c * scale[0], r * scale[1]])
            }
            _ => Err(format!(
                "position [{x}, {y}] falls on no finite point of the height map's grid"
            )),
        }
    }
}

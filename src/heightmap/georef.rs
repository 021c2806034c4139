//! GeoTIFF georeference: read a height map's GeoTIFF tags, interpret the CRSs relume understands
//! (lat/lon, UTM), and write single-band GeoTIFFs (shadow masks, lit fractions, horizon maps...)
//! carrying the input's tags unchanged ([`super::geotiff_write`], re-exported here: compression
//! by choice, horizontal predictor for compressed u8, none for f32; little-endian strips, BigTIFF
//! past 2 GiB of samples). Texel (column j, row i) covers
//! [j, j+1) × [i, i+1) in texel space, its centre at +0.5; row 0 is the file's first (north).

use super::utm::{self, WGS84_A, WGS84_E2};
use crate::error::{Error, Result}; // the same path in relume and in the scratch stand-in
use std::io::{Read, Seek};
use std::path::Path;
use tiff::decoder::{ifd::Value, Decoder};

pub use super::geotiff_common::TiffCompression;
pub use super::geotiff_stack::write_geotiff_stack_f32;
pub use super::geotiff_write::{
    write_geotiff_f32, write_geotiff_f32_with, write_geotiff_u8, write_geotiff_u8_with,
};
use tiff::tags::Tag;
use tiff::TiffResult;

/// What a GeoTIFF says about where its grid lies: the raw GeoTIFF tags, kept so that an output
/// can carry them unchanged. Empty fields mean the tag is absent.
#[derive(Clone, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct GeoReference {
    /// ModelTiepointTag (33922): (I, J, K, X, Y, Z) per tiepoint.
    pub tiepoints: Vec<f64>,
    /// ModelPixelScaleTag (33550): (ScaleX, ScaleY, ScaleZ).
    pub pixel_scale: Vec<f64>,
    /// ModelTransformationTag (34264): a row-major 4×4 matrix (16 values).
    pub transformation: Vec<f64>,
    /// GeoKeyDirectoryTag (34735): header (version, revision, minor, count) + 4 shorts per key.
    pub geo_keys: Vec<u16>,
    /// GeoDoubleParamsTag (34736).
    pub geo_doubles: Vec<f64>,
    /// GeoAsciiParamsTag (34737), without its terminating NUL.
    pub geo_ascii: String,
}

/// The coordinate reference system, as far as relume needs to understand it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Crs {
    /// Latitude/longitude in degrees, any datum (treated as WGS 84).
    Geographic,
    /// UTM on WGS 84 (EPSG 326zz north, 327zz south) or NAD83 (26901–26923, taken as WGS 84).
    Utm { zone: u8, north: bool },
    /// Anything else, with its EPSG code when the file names one.
    Other { epsg: Option<u16> },
}

impl GeoReference {
    /// Reads the georeference tags from an opened decoder (None when the file has none of them).
    /// A tag of the wrong type (not DOUBLE, SHORT, ASCII as the spec says) counts as absent.
    pub fn read<R: Read + Seek>(dec: &mut Decoder<R>) -> Option<GeoReference> {
        let g = GeoReference {
            tiepoints: tag(dec, Tag::ModelTiepointTag, Value::into_f64_vec),
            pixel_scale: tag(dec, Tag::ModelPixelScaleTag, Value::into_f64_vec),
            transformation: tag(dec, Tag::ModelTransformationTag, Value::into_f64_vec),
            geo_keys: tag(dec, Tag::GeoKeyDirectoryTag, Value::into_u16_vec),
            geo_doubles: tag(dec, Tag::GeoDoubleParamsTag, Value::into_f64_vec),
            geo_ascii: tag(dec, Tag::GeoAsciiParamsTag, Value::into_string),
        };
        (g != GeoReference::default()).then_some(g)
    }

    /// The georeference of the grid box-downsampled by `factor` (texel (i, j) of the result
    /// covers texels (f·i .. f·i + f) of the source): pixel scale and matrix columns times f,
    /// the tiepoint's raster coordinates divided by f.
    pub fn downsampled(&self, factor: usize) -> GeoReference {
        let f = factor as f64;
        let mut g = self.clone();
        for t in g.tiepoints.chunks_exact_mut(6) {
            t[0] /= f;
            t[1] /= f;
        }
        for v in g.pixel_scale.iter_mut().take(2) {
            *v *= f;
        }
        if g.transformation.len() == 16 {
            for r in 0..4 {
                g.transformation[4 * r] *= f;
                g.transformation[4 * r + 1] *= f;
            }
        }
        g
    }

    /// The true bearing (degrees clockwise from north) of the grid's "up" (toward row 0) at
    /// texel-space point (col, row): 0 for a geographic grid, the meridian convergence for UTM.
    /// From the latitude and longitude of the point and of the point one texel up, on the WGS 84
    /// ellipsoid's local radii (meridional M, prime vertical N). None when `lat_lon` is None.
    pub fn grid_north_bearing(&self, col: f64, row: f64) -> Option<f64> {
        let [la0, lo0] = self.lat_lon(col, row)?;
        let [la1, lo1] = self.lat_lon(col, row - 1.0)?;
        let phi = la0.to_radians();
        let w = (1.0 - WGS84_E2 * phi.sin().powi(2)).sqrt();
        let (m, n) = (WGS84_A * (1.0 - WGS84_E2) / w.powi(3), WGS84_A / w);
        let north = (la1 - la0).to_radians() * m;
        let east = (lo1 - lo0).to_radians() * n * phi.cos();
        Some(east.atan2(north).to_degrees())
    }

    /// A SHORT GeoKey stored in the directory itself (TIFFTagLocation 0).
    fn key(&self, id: u16) -> Option<u16> {
        let n = *self.geo_keys.get(3)? as usize;
        let mut keys = self.geo_keys.get(4..)?.chunks_exact(4).take(n);
        Some(keys.find(|k| k[0] == id && k[1] == 0 && k[2] == 1)?[3])
    }

    /// Parses the GeoKey directory: GTModelTypeGeoKey (1024), GeographicTypeGeoKey (2048),
    /// ProjectedCSTypeGeoKey (3072).
    pub fn crs(&self) -> Crs {
        match (self.key(1024), self.key(3072)) {
            (Some(2), _) => Crs::Geographic,
            (Some(1) | None, Some(code)) => match code {
                32601..=32660 | 32701..=32760 | 26901..=26923 => {
                    let (zone, north) = ((code % 100) as u8, code / 100 != 327);
                    Crs::Utm { zone, north }
                }
                32767 => Crs::Other { epsg: None }, // user-defined
                _ => Crs::Other { epsg: Some(code) },
            },
            (None, None) if self.key(2048).is_some() => Crs::Geographic,
            _ => Crs::Other { epsg: None },
        }
    }

    /// Model (map) coordinates of texel-space point (x = column, y = row; texel centres at +0.5):
    /// by the transformation matrix, else the one tiepoint and pixel scale (Y = Ty − (J − Tj)·Sy).
    /// RasterPixelIsPoint (GTRasterTypeGeoKey 1025 = 2) puts raster (0, 0) at the first texel's
    /// centre as GDAL does, PixelIsArea at its corner. None without the matrix or one tiepoint.
    pub fn model_xy(&self, col: f64, row: f64) -> Option<[f64; 2]> {
        let half = if self.key(1025) == Some(2) { 0.5 } else { 0.0 };
        let (i, j) = (col - half, row - half);
        let (t, s, m) = (&self.tiepoints, &self.pixel_scale, &self.transformation);
        let p = if m.len() == 16 {
            [m[0] * i + m[1] * j + m[3], m[4] * i + m[5] * j + m[7]]
        } else if t.len() == 6 && s.len() >= 2 {
            [t[3] + (i - t[0]) * s[0], t[4] - (j - t[1]) * s[1]]
        } else {
            return None;
        };
        p.iter().all(|v| v.is_finite()).then_some(p)
    }

    /// The texel-space point (column, row; texel centres at +0.5) of model (map) coordinates
    /// (x, y): the inverse of [`GeoReference::model_xy`], with the same raster-type convention
    /// (PixelIsPoint adds the half texel back). None without the matrix or one tiepoint, or when
    /// the affine map is singular.
    pub fn texel_of_model(&self, x: f64, y: f64) -> Option<[f64; 2]> {
        let half = if self.key(1025) == Some(2) { 0.5 } else { 0.0 };
        let (t, s, m) = (&self.tiepoints, &self.pixel_scale, &self.transformation);
        let [i, j] = if m.len() == 16 {
            // [x − m3, y − m7] = [[m0, m1], [m4, m5]]·[i, j], solved by Cramer's rule.
            let (dx, dy, det) = (x - m[3], y - m[7], m[0] * m[5] - m[1] * m[4]);
            [(m[5] * dx - m[1] * dy) / det, (m[0] * dy - m[4] * dx) / det]
        } else if t.len() == 6 && s.len() >= 2 {
            [t[0] + (x - t[3]) / s[0], t[1] + (t[4] - y) / s[1]]
        } else {
            return None;
        };
        let p = [i + half, j + half];
        p.iter().all(|v| v.is_finite()).then_some(p)
    }

    /// Whether [`GeoReference::lat_lon`] and [`GeoReference::texel_of_lat_lon`] understand the
    /// CRS: geographic in degrees (GeogAngularUnitsGeoKey 2054 absent or 9102), or UTM.
    pub fn reads_lat_lon(&self) -> bool {
        match self.crs() {
            Crs::Geographic => matches!(self.key(2054), None | Some(9102)),
            Crs::Utm { zone, .. } => (1..=60).contains(&zone),
            Crs::Other { .. } => false,
        }
    }

    /// Latitude and longitude (degrees) of texel-space point, for Geographic and UTM CRSs; None
    /// for Other. UTM by [`utm::inverse`] (Krüger's series to 6th order in n, a few nm).
    pub fn lat_lon(&self, col: f64, row: f64) -> Option<[f64; 2]> {
        let [x, y] = self.model_xy(col, row)?;
        match self.crs() {
            _ if !self.reads_lat_lon() => None,
            Crs::Utm { zone, north } => Some(utm::inverse(zone, north, x, y)),
            _ => Some([y, x]),
        }
    }

    /// The texel-space point of latitude and longitude (degrees, taken as WGS 84): forward UTM
    /// ([`utm::forward`], in the grid's zone) or the degrees themselves, then
    /// [`GeoReference::texel_of_model`]. On a geographic grid of `size` (width, height) the
    /// longitude is moved by whole turns to within 180° of the grid centre's, so that a 0..360°
    /// grid reads −170° as 190°. None when [`GeoReference::reads_lat_lon`] is false.
    pub fn texel_of_lat_lon(&self, lat: f64, lon: f64, size: [usize; 2]) -> Option<[f64; 2]> {
        match self.crs() {
            _ if !self.reads_lat_lon() => None,
            Crs::Utm { zone, north } => {
                let [x, y] = utm::forward(zone, north, lat, lon);
                self.texel_of_model(x, y)
            }
            _ => {
                let [cx, _] = self.model_xy(size[0] as f64 / 2.0, size[1] as f64 / 2.0)?;
                let turns = if (lon - cx).abs() <= 180.0 {
                    0.0
                } else {
                    ((lon - cx) / 360.0).round()
                };
                self.texel_of_model(lon - 360.0 * turns, lat)
            }
        }
    }

    /// Metres per texel (x, y): for a projected CRS the pixel scale (grid metres; ProjLinearUnits
    /// 3076 metre, foot or US survey foot), or the matrix's column lengths; for Geographic the
    /// degrees at the map's centre latitude times the WGS 84 radii of curvature (prime vertical
    /// N·cos φ across, meridional M along). None if unknown.
    pub fn cell_size_m(&self, width: usize, height: usize) -> Option<[f64; 2]> {
        let (s, m) = (&self.pixel_scale, &self.transformation);
        let [sx, sy] = if m.len() == 16 {
            [m[0].hypot(m[4]), m[1].hypot(m[5])]
        } else if s.len() >= 2 {
            [s[0].abs(), s[1].abs()]
        } else {
            return None;
        };
        let metres = match self.crs() {
            Crs::Geographic => {
                let [lat, _] = self.lat_lon(width as f64 / 2.0, height as f64 / 2.0)?;
                let w = (1.0 - WGS84_E2 * lat.to_radians().sin().powi(2)).sqrt();
                let (n, m) = (WGS84_A / w, WGS84_A * (1.0 - WGS84_E2) / (w * w * w));
                [
                    sx.to_radians() * n * lat.to_radians().cos(),
                    sy.to_radians() * m,
                ]
            }
            _ if self.key(1024) == Some(1) || self.key(3072).is_some() => {
                let unit = match self.key(3076) {
                    None | Some(9001) => 1.0,
                    Some(9002) => 0.3048,
                    Some(9003) => 1200.0 / 3937.0,
                    Some(_) => return None,
                };
                [sx * unit, sy * unit]
            }
            _ => return None,
        };
        let valid = metres.iter().all(|v| v.is_finite() && *v > 0.0);
        valid.then_some(metres)
    }
}

/// Tag `t` converted by `f`; the default when absent or of another type.
fn tag<R: Read + Seek, T: Default>(d: &mut Decoder<R>, t: Tag, f: fn(Value) -> TiffResult<T>) -> T {
    let value = d.find_tag(t).ok().flatten();
    value.and_then(|v| f(v).ok()).unwrap_or_default()
}

/// Opens `path` and returns its georeference (None when it has no GeoTIFF tags).
pub fn read_georeference(path: &Path) -> Result<Option<GeoReference>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, "cannot read GeoTIFF", e))?;
    // tiff 0.10 panics on some malformed tags (see readers.rs).
    crate::error::contain_panic(path, "TIFF decoder", || {
        let mut dec = Decoder::new(std::io::BufReader::new(file))?;
        Ok(GeoReference::read(&mut dec))
    })?
    .map_err(|e| match e {
        tiff::TiffError::IoError(io) => Error::io(path, "cannot read GeoTIFF", io),
        tiff::TiffError::UnsupportedError(u) => Error::unsupported(path, format!("TIFF: {u}")),
        other => Error::input(path, format!("cannot decode TIFF: {other}")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use std::process::Command;
    use tiff::decoder::DecodingResult;

    fn srtm() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dem/srtm_bigtujunga_30m.tif")
    }

    fn assert_close(got: [f64; 2], want: [f64; 2], tol: f64) {
        let err = (got[0] - want[0]).abs().max((got[1] - want[1]).abs());
        assert!(err <= tol, "{got:?} vs {want:?}: off by {err:e}");
    }

    #[test]
    fn reads_the_srtm_georeference() {
        let g = read_georeference(&srtm()).unwrap().unwrap();
        let (zone, north) = (11, true);
        assert_eq!(g.crs(), Crs::Utm { zone, north });
        // gdalinfo: Origin = (376313.655454263498541,3807917.827628375496715)
        let origin = [376313.6554542635, 3807917.8276283755]; // the same doubles
        assert_close(g.model_xy(0.0, 0.0).unwrap(), origin, 1e-9);
        // The centre (598.5, 321.5) is at (394268.6554542635, 3798272.8276283755);
        // echo "394268.6554542635 3798272.8276283755" |
        //   gdaltransform -s_srs EPSG:32611 -t_srs EPSG:4326  →  -118.149228674882 34.3203341674028
        let centre = g.lat_lon(598.5, 321.5).unwrap();
        assert_close(centre, [34.3203341674028, -118.149228674882], 1e-7);
        assert_eq!(g.cell_size_m(1197, 643), Some([30.0, 30.0]));
    }

    #[test]
    fn inverse_utm_matches_proj() {
        // EPSG, easting, northing, then the output of
        // gdaltransform -s_srs EPSG:<code> -t_srs EPSG:4326 <<< 'E N' (EPSG:4269 for 26910):
        // longitude, latitude. CM: the zone's central meridian.
        const CASES: &str = "
            32633 667294.821 6655205.484 17.9999999980688 60.0000000033275  3° E of CM
            32633 166034.098 55341.388 11.9999999976065 0.499999998051396   3° W of CM
            32756 334416.394 6251925.360 151.210000000046 -33.8600000031783 south
            32719 285015.763 4457055.981 -72.0000000038913 -50.000000003056 south, 3° W
            32723 684623.673 7466421.401 -43.200000002618 -22.899999997054  south
            32601 548449.870 8882626.945 -174.500000013106 80.0000000005773
            32611 223887.835 3799495.923 -120.000000002354 34.2999999976827 3° W
            32611 500000 0 -117 0
            32760 500000 10000000 177 0                                     south, equator
            26910 500000 4982950.400 -123 44.9999999990381                  NAD83";
        for line in CASES.lines().filter(|l| !l.trim().is_empty()) {
            let mut v = [0f64; 5];
            for (i, t) in line.split_whitespace().take(5).enumerate() {
                v[i] = t.parse().unwrap();
            }
            let g = GeoReference {
                tiepoints: vec![0.0, 0.0, 0.0, v[1], v[2], 0.0],
                pixel_scale: vec![1.0, 1.0, 0.0],
                geo_keys: vec![1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, v[0] as u16],
                ..Default::default()
            };
            assert_close(g.lat_lon(0.0, 0.0).unwrap(), [v[4], v[3]], 1e-7);
        }
    }

    #[test]
    fn geographic_cell_size_and_pixel_is_point() {
        // 1″ cells, 3600×3600 texels, centre at 45° N 10.5° E.
        let mut g = GeoReference {
            tiepoints: vec![0.0, 0.0, 0.0, 10.0, 45.5, 0.0],
            pixel_scale: vec![1.0 / 3600.0, 1.0 / 3600.0, 0.0],
            geo_keys: vec![1, 1, 0, 3, 1024, 0, 1, 2, 1025, 0, 1, 1, 2048, 0, 1, 4326],
            ..Default::default()
        };
        assert_eq!(g.crs(), Crs::Geographic);
        // Distances from (45, 10.5) to ±0.5″ in latitude and +0.5″ in longitude, by
        // gdaltransform -s_srs EPSG:4326 -t_srs "+proj=aeqd +lat_0=45 +lon_0=10.5 +datum=WGS84":
        // 15.4349692745737 + 15.4349688965449 north-south, 2 × 10.9509493186394 east-west.
        let size = g.cell_size_m(3600, 3600).unwrap();
        assert_close(size, [21.9018986372788, 30.8699381711186], 1e-6);
        assert_close(g.lat_lon(1800.0, 1800.0).unwrap(), [45.0, 10.5], 1e-12);
        g.geo_keys[11] = 2; // RasterPixelIsPoint: raster (0, 0) is the first texel's centre
        assert_close(g.lat_lon(0.5, 0.5).unwrap(), [45.5, 10.0], 1e-12);
    }

    /// Whether `cmd` runs; if not, fails under CI=true or RELUME_REQUIRE_ALL=1, else prints SKIP.
    fn have(cmd: &str, install: &str) -> bool {
        let mut words = cmd.split(' ');
        let out = Command::new(words.next().unwrap()).args(words).output();
        if out.is_ok_and(|o| o.status.success()) {
            return true;
        }
        let off = |v: String| matches!(&*v.to_lowercase(), "" | "0" | "false");
        let on = |k: &str| std::env::var(k).map(off) == Ok(false);
        let strict = on("CI") || on("RELUME_REQUIRE_ALL"); // as tests/common's require_all
        assert!(!strict, "missing `{cmd}` (CI requires it): {install}");
        eprintln!("SKIP: missing `{cmd}` ({install}; CI fails instead of skipping)");
        false
    }

    fn run(cmd: &mut Command) -> String {
        let o = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{cmd:?}: {err}");
        String::from_utf8(o.stdout).unwrap()
    }

    /// Writes the SRTM heights + 0.25 as f32, texel (0, 0) set to the no-data value −9999.
    fn write_sample(dir: &Path) -> (PathBuf, GeoReference, Vec<f32>) {
        let mut dec = Decoder::new(std::fs::File::open(srtm()).unwrap()).unwrap();
        let g = GeoReference::read(&mut dec).unwrap();
        let DecodingResult::I16(h) = dec.read_image().unwrap() else {
            panic!("the SRTM sample is int16")
        };
        let mut values: Vec<f32> = h.iter().map(|&v| v as f32 + 0.25).collect();
        values[0] = -9999.0;
        let out = dir.join("lit.tif");
        write_geotiff_f32(&out, 1197, 643, &values, Some(&g), Some(-9999.0)).unwrap();
        (out, g, values)
    }

    #[test]
    fn round_trip_keeps_values_and_tags() {
        let dir = tempfile::tempdir().unwrap();
        let (out, g, values) = write_sample(dir.path());
        let mut dec = Decoder::new(std::fs::File::open(&out).unwrap()).unwrap();
        assert_eq!(GeoReference::read(&mut dec).as_ref(), Some(&g));
        assert_eq!(dec.get_tag_ascii_string(Tag::GdalNodata).unwrap(), "-9999");
        assert_eq!(dec.dimensions().unwrap(), (1197, 643));
        let DecodingResult::F32(back) = dec.read_image().unwrap() else {
            panic!("not float32")
        };
        assert_eq!(back, values);
    }

    #[test]
    fn gdal_and_rasterio_read_the_written_geotiff() {
        let dir = tempfile::tempdir().unwrap();
        let (out, g, values) = write_sample(dir.path());
        let value = values[300 * 1197 + 700] as f64; // column 700, row 300
        if have("gdalinfo --version", "apt-get install gdal-bin") {
            let info = |p: &Path| -> serde_json::Value {
                serde_json::from_str(&run(Command::new("gdalinfo").arg("-json").arg(p))).unwrap()
            };
            let (got, input) = (info(&out), info(&srtm()));
            assert_eq!(got["size"], serde_json::json!([1197, 643]));
            let wkt = got["coordinateSystem"]["wkt"].as_str().unwrap();
            assert!(wkt.contains("UTM zone 11N"), "{wkt}");
            assert_eq!(got["geoTransform"], input["geoTransform"]);
            assert_eq!(got["bands"][0]["noDataValue"].as_f64(), Some(-9999.0));
            assert_eq!(got["bands"][0]["type"], "Float32");
            let mut at = Command::new("gdallocationinfo");
            let v = run(at.arg("-valonly").arg(&out).args(["700", "300"]));
            assert_eq!(v.trim().parse::<f64>().unwrap(), value);
        }
        if have("python3 -c __import__('rasterio')", "pip install rasterio") {
            let script = "import sys, json, rasterio\n\
                with rasterio.open(sys.argv[1]) as s:\n    \
                print(json.dumps([s.crs.to_epsg(), list(s.transform)[:6], s.nodata, \
                float(s.read(1)[300, 700])]))";
            let text = run(Command::new("python3").args(["-c", script]).arg(&out));
            let j: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!(j[0], 32611);
            // serde_json's float parsing may be an ulp off: compare within a micrometre.
            let t: Vec<f64> = (0..6).map(|i| j[1][i].as_f64().unwrap()).collect();
            let want = [30.0, 0.0, g.tiepoints[3], 0.0, -30.0, g.tiepoints[4]];
            let off = t.iter().zip(want).map(|(a, b)| (a - b).abs());
            assert!(off.fold(0.0, f64::max) < 1e-6, "{t:?}");
            assert_eq!((j[2].as_f64(), j[3].as_f64()), (Some(-9999.0), Some(value)));
        }
    }

    #[test]
    fn writes_are_atomic() {
        let dir = tempfile::tempdir().unwrap();
        let entries = || std::fs::read_dir(dir.path()).unwrap().count();
        // A missing directory: an error naming the path, nothing left behind.
        let missing = dir.path().join("no/such/dir/out.tif");
        let err = write_geotiff_u8(&missing, 1, 1, &[0], None, None).unwrap_err();
        let named = err.to_string().contains(&*missing.to_string_lossy());
        assert!(named && matches!(err, Error::Io { .. }), "{err}");
        assert_eq!(entries(), 0);
        // A failed write leaves the existing file as it was; a good one replaces it.
        let out = dir.path().join("mask.tif");
        std::fs::write(&out, b"old").unwrap();
        assert!(write_geotiff_u8(&out, 2, 2, &[0; 3], None, None).is_err());
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
        write_geotiff_u8(&out, 2, 2, &[0, 255, 128, 0], None, Some(128)).unwrap();
        let mut dec = Decoder::new(std::fs::File::open(&out).unwrap()).unwrap();
        assert_eq!(GeoReference::read(&mut dec), None);
        assert_eq!(dec.get_tag_ascii_string(Tag::GdalNodata).unwrap(), "128");
        let DecodingResult::U8(back) = dec.read_image().unwrap() else {
            panic!("not u8")
        };
        assert_eq!((back, entries()), (vec![0, 255, 128, 0], 1));
        // Fully written, then the rename fails (the target is a non-empty directory): the
        // temporary is removed and the directory kept.
        let busy = dir.path().join("busy.tif");
        std::fs::create_dir_all(busy.join("inside")).unwrap();
        let err = write_geotiff_f32(&busy, 1, 1, &[1.0], None, None).unwrap_err();
        assert!(err.to_string().contains("busy.tif"), "{err}");
        assert!(busy.join("inside").is_dir());
        assert_eq!(entries(), 2);
    }
}

//! Terrain commands with geography: the sun from a date and place (SPA at a UTM GeoTIFF's
//! centre, turned by the meridian convergence), and GeoTIFF outputs that keep the input's
//! georeference and no-data (read back by rasterio).

use crate::common;

use common::{bake, data, expect_code, python, require_python};
use relume::error::exit;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `--date` on the UTM GeoTIFF: the sun comes from SPA at the map's centre, turned by the
/// meridian convergence, and the mask equals the one from the angles it reports.
#[test]
fn shadow_from_a_date_on_a_utm_geotiff() {
    let dir = tempfile::tempdir().unwrap();
    let srtm = data("scenes/dem/srtm_bigtujunga_30m.tif");
    let (a, b) = (dir.path().join("date.png"), dir.path().join("angles.png"));
    let o = bake(
        dir.path(),
        &[
            "shadow",
            s(&srtm),
            "--date",
            "2026-06-21T14:30:00Z",
            "--out",
            s(&a),
            "--json",
        ],
    );
    expect_code(&o, 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let sun = &v["sun"];
    let (lat, lon) = (
        sun["latitude"].as_f64().unwrap(),
        sun["longitude"].as_f64().unwrap(),
    );
    // The centre of the grid (gdaltransform of its UTM centre: 34.3203 N, 118.1492 W).
    assert!(
        (lat - 34.3203).abs() < 1e-3 && (lon + 118.1492).abs() < 1e-3,
        "{sun}"
    );
    // Meridian convergence on the sphere, tan γ = tan(λ − λ₀)·sin φ (zone 11: λ₀ = −117°); the
    // ellipsoid changes it by less than 1e-3° here.
    let gamma = ((lon + 117.0).to_radians().tan() * lat.to_radians().sin())
        .atan()
        .to_degrees();
    let up = sun["grid_north_bearing"].as_f64().unwrap();
    assert!((up - gamma).abs() < 1e-3, "{up} vs {gamma}");
    let (az, el) = (
        v["sun_azimuth"].as_f64().unwrap(),
        v["sun_elevation"].as_f64().unwrap(),
    );
    assert!((az - (sun["true_azimuth"].as_f64().unwrap() - up)).abs() < 1e-9);
    // A June morning in California: the sun is in the east-northeast, 20° up.
    assert!(
        (60.0..90.0).contains(&az) && (15.0..25.0).contains(&el),
        "{az} {el}"
    );
    let o = bake(
        dir.path(),
        &[
            "shadow",
            s(&srtm),
            "--sun-azimuth",
            &az.to_string(),
            "--sun-elevation",
            &el.to_string(),
            "--out",
            s(&b),
            "-q",
        ],
    );
    expect_code(&o, 0);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // A map without georeference needs a place; a date without a zone is refused.
    let jpg = data("scenes/dem/puget_sound_4k.jpg");
    let o = bake(
        dir.path(),
        &[
            "shadow",
            s(&jpg),
            "--date",
            "2026-06-21T14:30Z",
            "--out",
            s(&a),
        ],
    );
    assert!(expect_code(&o, exit::INPUT).contains("--lat and --lon"));
    let o = bake(
        dir.path(),
        &[
            "shadow",
            s(&srtm),
            "--date",
            "2026-06-21T14:30",
            "--out",
            s(&a),
        ],
    );
    assert!(expect_code(&o, exit::INPUT).contains("time zone"));
}

/// GeoTIFF outputs keep the input's georeference, read by GDAL (rasterio); no-data texels of
/// the input are no-data (128) in the mask and are not counted as lit or shadowed.
#[test]
fn geotiff_masks_keep_the_georeference_and_the_nodata() {
    use relume::heightmap::georef::{read_georeference, write_geotiff_f32};
    let dir = tempfile::tempdir().unwrap();
    let srtm = data("scenes/dem/srtm_bigtujunga_30m.tif");
    let (map, _) = relume::heightmap::load_heightmap(&srtm, &Default::default()).unwrap();
    let geo = read_georeference(&srtm).unwrap().unwrap();
    // A copy of the DEM with a 20×10 hole of no-data (−9999).
    let mut h = map.heights.clone();
    for r in 100..110 {
        for c in 200..220 {
            h[r * map.width + c] = -9999.0;
        }
    }
    let holed = dir.path().join("holed.tif");
    write_geotiff_f32(&holed, map.width, map.height, &h, Some(&geo), Some(-9999.0)).unwrap();
    let ron = dir.path().join("holed.ron");
    std::fs::write(
        &ron,
        "Pipeline(input: HeightMap(path: \"holed.tif\", nodata: FillMin), output: \"o\", stages: [MinmaxMipmap()])",
    )
    .unwrap();
    let (tif, png) = (dir.path().join("mask.tif"), dir.path().join("mask.png"));
    let args = ["--sun-azimuth", "135", "--sun-elevation", "10"];
    let o = bake(
        dir.path(),
        &[&["shadow", s(&ron), "--out", s(&tif), "--json"][..], &args].concat(),
    );
    expect_code(&o, 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["nodata_texels"], 200);
    expect_code(
        &bake(
            dir.path(),
            &[&["shadow", s(&ron), "--out", s(&png), "-q"][..], &args].concat(),
        ),
        0,
    );
    if !require_python(&["rasterio", "PIL", "numpy"]) {
        return;
    }
    let out = python(
        "import sys, rasterio, numpy as np\n\
         from PIL import Image\n\
         src, tif, png = sys.argv[1:4]\n\
         with rasterio.open(src) as a, rasterio.open(tif) as b:\n\
         \x20   assert a.crs == b.crs and a.crs.to_epsg() == 32611, (a.crs, b.crs)\n\
         \x20   assert a.transform == b.transform, (a.transform, b.transform)\n\
         \x20   assert b.nodata == 128 and b.dtypes[0] == 'uint8'\n\
         \x20   m = b.read(1)\n\
         p = np.array(Image.open(png))\n\
         hole = np.zeros(m.shape, bool); hole[100:110, 200:220] = True\n\
         assert (m[hole] == 128).all()\n\
         assert (m[~hole] == p[~hole]).all() and set(np.unique(m[~hole])) <= {0, 255}\n\
         print((m[~hole] == 0).sum() / (~hole).sum())",
        &[s(&srtm), s(&tif), s(&png)],
    );
    let frac: f64 = out.trim().parse().unwrap();
    let reported = v["shadowed_fraction"].as_f64().unwrap();
    assert!((frac - reported).abs() < 1e-12, "{frac} vs {reported}");
}

/// `--compress none|lzw|deflate|deflate-small|zstd`: rasterio (GDAL) reads every plane of every
/// choice with the compression it names and the same values as the uncompressed file, and the
/// shadow mask (u8, horizontal differencing) likewise. `--stack`: one GeoTIFF whose bands are
/// the planes (same values, georeference and no-data), described by their azimuths.
#[test]
fn every_geotiff_compression_reads_back_the_same_values_in_gdal() {
    if !require_python(&["rasterio", "numpy"]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let srtm = data("scenes/dem/srtm_bigtujunga_30m.tif");
    let choices = ["none", "lzw", "deflate", "deflate-small", "zstd"];
    for c in choices {
        let out = dir.path().join(c);
        let o = bake(
            dir.path(),
            &[
                "-q",
                "horizon",
                s(&srtm),
                "--directions",
                "4",
                "--compress",
                c,
                "--out",
                s(&out),
                "--stack",
                s(&dir.path().join(format!("stack-{c}.tif"))),
            ],
        );
        expect_code(&o, 0);
        let mask = dir.path().join(format!("mask-{c}.tif"));
        let o = bake(
            dir.path(),
            &[
                "-q",
                "shadow",
                s(&srtm),
                "--sun-azimuth",
                "300",
                "--sun-elevation",
                "10",
                "--compress",
                c,
                "--out",
                s(&mask),
            ],
        );
        expect_code(&o, 0);
    }
    let script = r#"
import glob, json, os, sys
import numpy as np, rasterio
d = sys.argv[1]
def read(p):
    with rasterio.open(p) as s:
        return (s.compression.value if s.compression else 'NONE'), s.read(1)
out = {}
for c in ['none', 'lzw', 'deflate', 'deflate-small', 'zstd']:
    planes = sorted(glob.glob(os.path.join(d, c, 'horizon_*.tif')))
    names = [os.path.basename(p) for p in planes]
    got = [read(p) for p in planes] + [read(os.path.join(d, 'mask-%s.tif' % c))]
    out[c] = {'names': names, 'compression': sorted({g[0] for g in got}),
              'values': [g[1] for g in got]}
    with rasterio.open(os.path.join(d, 'stack-%s.tif' % c)) as st, rasterio.open(planes[0]) as p0:
        bands = st.read()
        out[c]['stack'] = {
            'count': st.count, 'interleave': st.interleaving.value,
            'compression': st.compression.value if st.compression else 'NONE',
            'descriptions': list(st.descriptions), 'nodata': st.nodata,
            'same_georef': st.crs == p0.crs and st.transform == p0.transform,
            'same_values': all(np.array_equal(bands[k], out[c]['values'][k], equal_nan=True)
                               for k in range(len(planes))),
        }
ref = out['none']['values']
print(json.dumps({c: {'names': v['names'], 'compression': v['compression'], 'stack': v['stack'],
                      'same': all(np.array_equal(a, b, equal_nan=True) for a, b in zip(v['values'], ref))}
                  for c, v in out.items()}))
"#;
    let j: serde_json::Value = serde_json::from_str(&python(script, &[s(dir.path())])).unwrap();
    eprintln!("{j}");
    let want = [
        ("none", "NONE"),
        ("lzw", "LZW"),
        ("deflate", "DEFLATE"),
        ("deflate-small", "DEFLATE"),
        ("zstd", "ZSTD"),
    ];
    for (c, method) in want {
        assert_eq!(j[c]["names"].as_array().unwrap().len(), 4, "{c}: {j}");
        assert_eq!(j[c]["names"], j["none"]["names"], "{c}");
        assert_eq!(j[c]["compression"], serde_json::json!([method]), "{c}: {j}");
        assert_eq!(
            j[c]["same"], true,
            "{c}: values differ from the uncompressed file"
        );
        let st = &j[c]["stack"];
        assert_eq!(st["count"], 4, "{c}: {st}");
        assert_eq!(st["interleave"], "BAND", "{c}: {st}");
        assert_eq!(st["compression"], method, "{c}: {st}");
        assert_eq!(st["nodata"], -9999.0, "{c}: {st}");
        assert_eq!(st["same_georef"], true, "{c}: {st}");
        assert_eq!(st["same_values"], true, "{c}: {st}");
        // horizon_AAA.AAA.tif ↔ "azimuth A.AAA deg".
        for (name, d) in j[c]["names"]
            .as_array()
            .unwrap()
            .iter()
            .zip(st["descriptions"].as_array().unwrap())
        {
            let az: f64 = name.as_str().unwrap()[8..15].parse().unwrap();
            assert_eq!(d.as_str().unwrap(), format!("azimuth {az:.3} deg"), "{c}");
        }
    }
}

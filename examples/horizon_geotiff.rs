//! Horizon maps of a GeoTIFF and what they give a GIS analyst: the sky-view factor and the
//! shadow of a sun, straight from the library.
//!
//! ```sh
//! cargo run --release --example horizon_geotiff                # scenes/dem/srtm_bigtujunga_30m.tif
//! cargo run --release --example horizon_geotiff -- DEM.tif 64 # 64 azimuths
//! ```
//!
//! The height map is read with its georeference (cell size from the GeoTIFF), the horizon angle
//! toward each of N azimuths is computed for every texel on curved ground (`terrain::horizon`),
//! and the map answers any sun in O(1) per texel.

use relume::heightmap::{load_heightmap, HeightMapOptions};
use relume::terrain::horizon::map::{HorizonMap, HorizonSettings};
use relume::terrain::Sun;
use std::path::PathBuf;

fn main() -> relume::error::Result<()> {
    let mut args = std::env::args().skip(1);
    let dem = PathBuf::from(
        args.next()
            .unwrap_or("scenes/dem/srtm_bigtujunga_30m.tif".into()),
    );
    let directions: usize = args.next().and_then(|d| d.parse().ok()).unwrap_or(32);

    let (map, _info) = load_heightmap(&dem, &HeightMapOptions::default())?;
    println!(
        "{}: {} x {} texels of {:.1} x {:.1} m",
        dem.display(),
        map.width,
        map.height,
        map.cell_size[0],
        map.cell_size[1]
    );
    let settings = HorizonSettings {
        directions,
        planet_radius: Some(6_371_000.0),
    };
    let horizons = HorizonMap::build(&map, &settings);

    let sky = horizons.sky_view();
    let mean = sky.iter().map(|&v| v as f64).sum::<f64>() / sky.len() as f64;
    let least = sky.iter().copied().fold(f32::INFINITY, f32::min);
    println!("sky-view factor over {directions} azimuths: mean {mean:.3}, least {least:.3}");

    for elevation_deg in [5.0, 15.0, 30.0] {
        let sun = Sun {
            azimuth_deg: 225.0,
            elevation_deg,
        };
        let shadowed = horizons.shadow_mask(&sun);
        let share = shadowed.iter().filter(|&&s| s).count() as f64 / shadowed.len() as f64;
        println!(
            "sun 225°/{elevation_deg:>2}°: {:.1} % in shadow",
            100.0 * share
        );
    }
    Ok(())
}

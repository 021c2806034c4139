//! `relume-bake theme THEMES.ron --size N --out ALBEDO.png [--frame K]`: compose a theme set's
//! albedo at any resolution. Thin: load, check, call the library, write atomically.

use crate::ui::Ui;
use clap::Args;
use relume::baked::images::{check_extension, write_png_rgba};
use relume::load::themes::{load_themes, GivenHeightMap};
use relume::render::tonemap::linear_to_srgb8;
use relume::theme::compose::compose;
use relume::{Error, Result};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

const THEME_HELP: &str = "\
Theme sets are RON (themes/*.ron); the format is in docs/themes.md. The index map comes from
height/slope/aspect rules over a height map, from a key image, or from polygons (GeoJSON or
inline; in texels, the unit square, longitude/latitude or the height map's CRS). The albedo is
written in sRGB; --frame K moves the fractal borders as frame K of the animation does in the
player.";

#[derive(Args)]
#[command(after_help = THEME_HELP)]
pub struct ThemeArgs {
    /// Theme set (.ron)
    pub themes: PathBuf,
    /// Width of the albedo in pixels (the height follows the index map's aspect), 1..=16384
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub size: u32,
    /// Albedo image to write (.png, sRGB)
    #[arg(long, value_name = "ALBEDO.png")]
    pub out: PathBuf,
    /// Animation frame (the border noise shifted K times)
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub frame: u32,
    /// Height map (or height-map pipeline) in place of the one the theme file names: the one a
    /// `Rules` map classifies, whose georeference places `LonLat`/`Map` polygons
    #[arg(long, value_name = "FILE")]
    pub heightmap: Option<PathBuf>,
}

pub fn run(a: &ThemeArgs, ui: &Ui, json_out: bool) -> Result<i32> {
    check_extension(&a.out, &["png"])?;
    let map = match &a.heightmap {
        Some(p) => Some(relume::load::heightmap_input_with_info(p, None, None)?),
        None => None,
    };
    let name = a.heightmap.as_ref().map(|p| format!("`{}`", p.display()));
    let given = map.as_ref().map(|(map, info)| GivenHeightMap {
        map,
        georef: info.georef.as_ref(),
        name: name.as_deref().unwrap_or_default(),
    });
    let t0 = Instant::now();
    let set = load_themes(&a.themes, given)?;
    let load_s = t0.elapsed().as_secs_f64();
    let base = &set.index.levels[0];
    let width = a.size as usize;
    let height = ((width as f64 * base.height as f64 / base.width as f64).round() as usize).max(1);
    if (width as u64) * (height as u64) > 1 << 28 {
        return Err(Error::knob(format!(
            "a {width}x{height} albedo is over 2^28 pixels; choose a smaller --size"
        )));
    }
    let t1 = Instant::now();
    let rgb = compose(&set, width, height, a.frame);
    let compose_s = t1.elapsed().as_secs_f64();
    let mut img = image::RgbaImage::new(width as u32, height as u32);
    for (p, c) in img.pixels_mut().zip(&rgb) {
        let [r, g, b] = c.map(linear_to_srgb8);
        *p = image::Rgba([r, g, b, 255]);
    }
    write_png_rgba(&a.out, &img)?;
    let memory = set.memory();
    let hist = base.histogram();
    let total = (base.width * base.height) as f64;
    let coverage: serde_json::Map<String, serde_json::Value> = set
        .classes
        .iter()
        .enumerate()
        .filter(|(i, _)| hist[*i] > 0)
        .map(|(i, c)| {
            let name = set.themes[c.theme as usize].clone();
            (format!("{i}:{name}"), json!(hist[i] as f64 / total))
        })
        .collect();
    if json_out {
        let j = json!({
            "out": a.out, "width": width, "height": height, "frame": a.frame,
            "index_map": [base.width, base.height], "classes": set.classes.len(),
            "coverage": coverage, "memory": memory,
            "seconds": {"load": load_s, "compose": compose_s},
        });
        println!("{j}");
    } else {
        ui.note(&format!(
            "wrote {} ({width}x{height}, frame {}) from a {}x{} index map of {} themes in {:.2} s\n\
             memory: {} B (index {} B CCC of {} B raw, textures {} B, noise {} B) against a global \
             RGB8 texture of {} B at the index map's resolution, {} B (BC1 {} B) at the themes' detail",
            a.out.display(),
            a.frame,
            base.width,
            base.height,
            set.themes.len(),
            load_s + compose_s,
            memory.total,
            memory.index_ccc,
            memory.index_raw,
            memory.textures,
            memory.noise,
            memory.global_rgb8_index_res,
            memory.global_rgb8_theme_res,
            memory.global_bc1_theme_res,
        ));
    }
    Ok(0)
}

//! The Crytek Sponza (262,267 triangles, alpha-masked leaves, plants and chains) baked by
//! `pipelines/crytek-sponza.ron` through the real binary, drawn by the player and exported to
//! glTF with its textures and masks. The masks' effect on light is tested on small scenes
//! (tests/radiosity/alpha.rs, tests/gpu/textures.rs); here the real file goes end to end.

use crate::common::{bake, data, text};
use crate::sponza::{export_textured_glb, player_median_luma};

#[test]
fn the_crytek_sponza_bakes_plays_and_exports_with_its_masks() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("crytek");
    let o = bake(
        tmp.path(),
        &[
            "-q",
            "run",
            data("pipelines/crytek-sponza.ron").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", text(&o));

    // A headless frame among the columns: neither black nor washed out (median luma 25/255
    // measured at 960×540 with this view, by Pillow: half the view is the shaded colonnade).
    let median = player_median_luma(tmp.path(), &out, "-6,2.5,0,2,0.5,3.5,60", "3");
    assert!((10..=200).contains(&median), "median luma {median}");

    // The glTF export: every textured material with its image, and the three masks of the MTL
    // (`map_d`: thorns, vase plants, chains) as alphaMode MASK.
    let (report, r) = export_textured_glb(tmp.path(), &out);
    assert_eq!(report["textured_materials"], 24, "{report}");
    assert_eq!(report["masks_left_out"], 0, "{report}");
    if let Some(r) = r {
        let mtl = std::fs::read_to_string(data("../shared/data/scenes/crytek-sponza/sponza.mtl"))
            .unwrap();
        let map_d = mtl
            .lines()
            .filter(|l| l.trim_start().starts_with("map_d "))
            .count();
        assert_eq!(r["masks"].as_u64().unwrap() as usize, map_d, "{r}");
    }
}

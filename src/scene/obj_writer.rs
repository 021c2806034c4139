//! Wavefront OBJ + MTL text of a [`Scene`]: what `relume-bake generate-scene` writes, so that
//! Blender, Mitsuba and the other tools of a studio open the bundled scenes as relume does.
//!
//! Positions print in Rust's shortest round-trip form of f32, so loading the file back gives
//! bit-identical coordinates (tested). One `o` per scene object (triangles grouped by object,
//! in object order), `usemtl` whenever the material changes; `Kd` is the albedo, `Ke` the
//! emitted radiance, as the OBJ loader reads them. Punctual lights have no OBJ form and are
//! not written.

use super::Scene;
use std::fmt::Write;

/// The OBJ text (referring to `mtl_name` by `mtllib`) and the MTL text of `scene`. `header`
/// lines become `#` comments at the top of both.
pub fn to_obj(scene: &Scene, mtl_name: &str, header: &str) -> (String, String) {
    let comment = |out: &mut String| {
        for line in header.lines() {
            let _ = writeln!(out, "# {line}");
        }
    };
    let mut obj = String::new();
    comment(&mut obj);
    let _ = writeln!(obj, "mtllib {mtl_name}");
    for p in &scene.positions {
        let _ = writeln!(obj, "v {} {} {}", p[0], p[1], p[2]);
    }
    let mut by_object: Vec<Vec<usize>> = vec![Vec::new(); scene.objects.len()];
    for (t, &o) in scene.triangle_object.iter().enumerate() {
        by_object[o as usize].push(t);
    }
    for (o, tris) in by_object.iter().enumerate() {
        if tris.is_empty() {
            continue;
        }
        let _ = writeln!(obj, "o {}", scene.objects[o]);
        let mut current = None;
        for &t in tris {
            let m = scene.triangle_material[t];
            if current != Some(m) {
                let _ = writeln!(obj, "usemtl {}", scene.materials[m as usize].name);
                current = Some(m);
            }
            let [a, b, c] = scene.triangles[t];
            let _ = writeln!(obj, "f {} {} {}", a + 1, b + 1, c + 1);
        }
    }
    let mut mtl = String::new();
    comment(&mut mtl);
    for m in &scene.materials {
        let [r, g, b] = m.albedo;
        let [er, eg, eb] = m.emission;
        let _ = writeln!(
            mtl,
            "newmtl {}\nKd {r} {g} {b}\nKe {er} {eg} {eb}\n",
            m.name
        );
    }
    (obj, mtl)
}

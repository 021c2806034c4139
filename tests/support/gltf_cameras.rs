//! A glTF scene with cameras, for the loader's and the player's tests.

/// The gltf-room scene with a perspective camera node (under the scaled "group" node, turned 90°
/// about y) and an orthographic one, written beside a copy of its buffer and texture.
pub fn room_with_cameras(dir: &std::path::Path) -> std::path::PathBuf {
    let src = crate::common::data("scenes/gltf-room");
    for f in ["room.bin", "checker.png"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let mut j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(src.join("room.gltf")).unwrap()).unwrap();
    j["cameras"] = serde_json::json!([
        {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}},
        {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.01}}
    ]);
    let nodes = j["nodes"].as_array_mut().unwrap();
    let q = std::f64::consts::FRAC_1_SQRT_2;
    nodes.push(serde_json::json!({
        "name": "view", "camera": 0, "translation": [0.5, 0.25, 1.0], "rotation": [0, q, 0, q]
    }));
    nodes.push(serde_json::json!({"name": "plan", "camera": 1}));
    let (view, plan) = (nodes.len() - 2, nodes.len() - 1);
    nodes[1]["children"]
        .as_array_mut()
        .unwrap()
        .push(view.into());
    j["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(plan.into());
    let path = dir.join("room.gltf");
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    path
}

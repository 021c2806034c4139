//! The player's first view (`render::first_view`): the framing from the front where it sees
//! into the scene, else a viewpoint inside, checked on scenes whose answer is known by
//! construction and on the bundled rooms and the Dabrovic Sponza.

use crate::common::data;
use glam::{DVec3, Vec3};
use relume::render::first_view::{first_view, ViewKind};
use relume::scene::builder::{Face, SceneBuilder};
use relume::scene::generate::{generate, Generated};
use relume::scene::{load_scene, Scene, SceneOptions};

fn inside(eye: Vec3, lo: Vec3, hi: Vec3) -> bool {
    eye.cmpgt(lo).all() && eye.cmplt(hi).all()
}

#[test]
fn a_closed_room_is_seen_from_inside_looking_along_its_length() {
    // A 10 × 3 × 4 room, walls facing in: the framing from −z meets the back of the near wall.
    let mut b = SceneBuilder::new();
    let m = b.material("wall", [0.7; 3], [0.0; 3]);
    let (lo, hi) = (DVec3::ZERO, DVec3::new(10.0, 3.0, 4.0));
    b.box_inside("room", lo, hi, m);
    let scene = b.build();
    let (cam, kind) = first_view(&scene);
    assert_eq!(kind, ViewKind::Inside);
    assert!(inside(cam.eye, lo.as_vec3(), hi.as_vec3()), "{:?}", cam.eye);
    // The longest free horizontal direction is along x (10 m against 4 m).
    let d = (cam.target - cam.eye).normalize();
    assert!(d.x.abs() > 0.9, "looks along {d}");
}

#[test]
fn open_boxes_and_solid_objects_keep_the_framing() {
    // The Cornell box: its open side faces the framing camera.
    let (cornell, _) = load_scene(
        &data("scenes/cornell-box/cornell_box.obj"),
        SceneOptions::default(),
    )
    .unwrap();
    assert_eq!(first_view(&cornell).1, ViewKind::Framing);
    // A solid block: no point sees its faces from inside, so nothing better than the framing.
    let mut b = SceneBuilder::new();
    let m = b.material("stone", [0.5; 3], [0.0; 3]);
    b.cuboid(
        "block",
        DVec3::ZERO,
        [DVec3::X, DVec3::Y * 2.0, DVec3::Z],
        m,
        &[] as &[Face],
    );
    let (cam, kind) = first_view(&b.build());
    assert_eq!(kind, ViewKind::Framing);
    assert!(cam.eye.z < 0.0);
    // No triangles at all: the framing of the empty bounds, no panic.
    assert_eq!(first_view(&Scene::default()).1, ViewKind::Framing);
}

#[test]
fn the_bundled_rooms_open_inside_their_walls() {
    for which in [
        Generated::FurnishedRoom,
        Generated::DoorAjar,
        Generated::DoorSealed,
    ] {
        let scene = generate(which);
        let (lo, hi) = scene.bounds();
        let (cam, kind) = first_view(&scene);
        assert_eq!(kind, ViewKind::Inside, "{}", which.name());
        assert!(inside(cam.eye, lo, hi), "{}: {:?}", which.name(), cam.eye);
    }
}

#[test]
fn the_dabrovic_sponza_opens_in_its_atrium() {
    let path = data("../shared/data/scenes/sponza/sponza.obj");
    let (scene, _) = load_scene(&path, SceneOptions::default()).unwrap();
    let (cam, kind) = first_view(&scene);
    assert_eq!(kind, ViewKind::Inside);
    // The atrium: above the floor (y ≈ 0) and between the galleries (|z| < 4 m of the
    // building's 15.6 m depth, z in −7.8..7.8). Measured: eye (−1.44, 5.99, −0.65).
    let (lo, hi) = scene.bounds();
    assert!(inside(cam.eye, lo, hi), "{:?}", cam.eye);
    assert!(cam.eye.y > 0.5 && cam.eye.z.abs() < 4.0, "{:?}", cam.eye);
}

//! Indoor scenes that relume makes itself, of the size and kind where radiosity is hard: a
//! furnished room of ≥ 50,000 triangles next to a lit room, and two rooms joined by a door
//! that stands ajar (light enters the dark room only through the gap) or is closed (no light may
//! enter at all). `relume-bake generate-scene NAME --out FILE.obj` writes them; the bundled
//! copies in `scenes/generated/` are that output, byte for byte (tested).
//!
//! Units are metres, y up. Object names start with the room they stand in ("dark.table"), so
//! that tests and studies can select a room's objects by prefix.

mod furniture;
mod rooms;

use crate::scene::builder::SceneBuilder;
use crate::scene::Scene;
use glam::DVec3;
use rooms::{Doorway, Room, RoomRow, ShellMaterials};
use serde::{Deserialize, Serialize};

/// The scenes `generate` makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Generated {
    /// A living room (table, chairs, sofa, bookshelf, picture, a vase and a statue of
    /// revolution: 70,628 triangles) beside a brightly lit studio, joined by an open doorway
    /// through a 10 cm wall.
    FurnishedRoom,
    /// A bright room and a dark room behind a 10 cm wall; the door between stands 8° ajar, so
    /// light reaches the dark room only through the gap.
    DoorAjar,
    /// As `door-ajar` with the door closed: the dark room must receive no light at all.
    DoorSealed,
}

impl Generated {
    pub const ALL: [Generated; 3] = [
        Generated::FurnishedRoom,
        Generated::DoorAjar,
        Generated::DoorSealed,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Generated::FurnishedRoom => "furnished-room",
            Generated::DoorAjar => "door-ajar",
            Generated::DoorSealed => "door-sealed",
        }
    }
}

/// Build one of the bundled scenes (deterministic: the same scene on every run and machine).
pub fn generate(which: Generated) -> Scene {
    match which {
        Generated::FurnishedRoom => furnished_room(),
        Generated::DoorAjar => door_rooms(8.0),
        Generated::DoorSealed => door_rooms(0.0),
    }
}

fn shell(b: &mut SceneBuilder) -> ShellMaterials {
    ShellMaterials {
        floor: b.material("oak", [0.55, 0.4, 0.25], [0.0; 3]),
        ceiling: b.material("ceiling", [0.85; 3], [0.0; 3]),
        walls: b.material("plaster", [0.75, 0.73, 0.7], [0.0; 3]),
        frame: b.material("frame", [0.6, 0.6, 0.6], [0.0; 3]),
    }
}

/// Longest edge of the rooms' and the furniture's quads (metres): a mesh fine enough for
/// light interpolated between vertices (the player's per-corner indirect light); with one quad
/// per wall, a 4 m floor triangle would spread the light of the doorway corner over the room.
const MESH_EDGE: f64 = 0.25;

/// Width of the door leaf and of its doorway, its height and thickness (metres).
const DOOR: (f64, f64, f64) = (0.9, 2.1, 0.04);

/// Two 4 × 2.5 × 4 m rooms behind a 10 cm wall with a 0.9 × 2.1 m doorway; a 1 m² ceiling
/// light in the bright one. The door leaf is hinged on the dark side of the wall at the
/// doorway's z0 edge and turned `ajar_deg` into the dark room (0: closed, its inner face filling
/// the doorway exactly, no floor under it: every edge where the bright side meets the dark side
/// is shared bit for bit, so no ray can pass).
fn door_rooms(ajar_deg: f64) -> Scene {
    let mut b = SceneBuilder::with_shared_vertices().max_edge(MESH_EDGE);
    let m = shell(&mut b);
    let (w, t, z0) = (4.0, 0.1, 1.5);
    let (door_w, door_h, door_t) = DOOR;
    let row = RoomRow {
        height: 2.5,
        depth: 4.0,
        rooms: vec![
            Room {
                name: "bright",
                width: w,
                light: Some((2.0, 2.0, 1.0, [10.0; 3])),
                floor_hole: None,
            },
            Room {
                name: "dark",
                width: w,
                light: None,
                // The closed leaf stands on the floor x ∈ [0, door_t] of the dark room.
                floor_hole: (ajar_deg == 0.0).then_some([0.0, door_t, z0, z0 + door_w]),
            },
        ],
        walls: vec![(
            t,
            Some(Doorway {
                z0,
                z1: z0 + door_w,
                height: door_h,
            }),
        )],
    };
    row.build(&mut b, m);
    let x1 = w + t;
    let door = b.material("door", [0.6, 0.5, 0.4], [0.0; 3]);
    let a = ajar_deg.to_radians();
    let (s, c) = (a.sin(), a.cos());
    b.cuboid(
        "dark.door",
        DVec3::new(x1, 0.0, z0),
        [
            DVec3::new(c, 0.0, -s) * door_t,
            DVec3::Y * door_h,
            DVec3::new(s, 0.0, c) * door_w,
        ],
        door,
        &[crate::scene::builder::Face::NegY],
    );
    let wood = b.material("walnut", [0.35, 0.22, 0.12], [0.0; 3]);
    let red = b.material("red_fabric", [0.6, 0.12, 0.1], [0.0; 3]);
    let blue = b.material("blue_paint", [0.15, 0.25, 0.55], [0.0; 3]);
    furniture::table(
        &mut b,
        "dark.table",
        DVec3::new(x1 + 1.4, 0.0, 1.6),
        DVec3::new(1.2, 0.04, 0.8),
        0.75,
        0.06,
        wood,
    );
    furniture::block(
        &mut b,
        "dark.sofa",
        DVec3::new(x1 + 1.0, 0.0, 3.1),
        DVec3::new(1.8, 0.8, 0.8),
        red,
    );
    furniture::block(
        &mut b,
        "dark.cabinet",
        DVec3::new(x1 + w - 0.5, 0.0, 0.4),
        DVec3::new(0.45, 1.2, 1.0),
        blue,
    );
    b.build()
}

/// A 3 m wide studio with a bright ceiling light and a 6 m wide living room with a dim lamp,
/// 5 m deep and 2.8 m high, behind a 10 cm wall with an open 1 × 2.1 m doorway.
fn furnished_room() -> Scene {
    use furniture::*;
    let mut b = SceneBuilder::with_shared_vertices().max_edge(MESH_EDGE);
    let m = shell(&mut b);
    let row = RoomRow {
        height: 2.8,
        depth: 5.0,
        rooms: vec![
            Room {
                name: "studio",
                width: 3.0,
                light: Some((1.5, 2.5, 1.0, [12.0; 3])),
                floor_hole: None,
            },
            Room {
                name: "living",
                width: 6.0,
                light: Some((3.0, 2.5, 0.5, [6.0; 3])),
                floor_hole: None,
            },
        ],
        walls: vec![(
            0.1,
            Some(Doorway {
                z0: 2.0,
                z1: 3.0,
                height: 2.1,
            }),
        )],
    };
    row.build(&mut b, m);
    let x0 = 3.1;
    let at = |x: f64, y: f64, z: f64| DVec3::new(x0 + x, y, z);
    let wood = b.material("walnut", [0.35, 0.22, 0.12], [0.0; 3]);
    let chair_wood = b.material("beech", [0.6, 0.45, 0.3], [0.0; 3]);
    let red = b.material("red_fabric", [0.6, 0.12, 0.1], [0.0; 3]);
    let shelf = b.material("white_shelf", [0.8, 0.78, 0.75], [0.0; 3]);
    let gold = b.material("gilt", [0.7, 0.55, 0.25], [0.0; 3]);
    let marble = b.material("marble", [0.82, 0.8, 0.78], [0.0; 3]);
    let glaze = b.material("blue_glaze", [0.15, 0.3, 0.6], [0.0; 3]);
    let grey = b.material("grey_cabinet", [0.4, 0.42, 0.45], [0.0; 3]);
    table(
        &mut b,
        "living.table",
        at(2.2, 0.0, 1.8),
        DVec3::new(1.6, 0.04, 0.9),
        0.75,
        0.06,
        wood,
    );
    for (k, (x, z, facing)) in [
        (2.6, 1.45, DVec3::Z),
        (3.4, 1.45, DVec3::Z),
        (2.6, 3.05, -DVec3::Z),
        (3.4, 3.05, -DVec3::Z),
    ]
    .into_iter()
    .enumerate()
    {
        chair(
            &mut b,
            &format!("living.chair_{}", k + 1),
            at(x, 0.0, z),
            facing,
            chair_wood,
        );
    }
    let sofa = "living.sofa";
    b.cuboid(
        sofa,
        at(2.0, 0.0, 3.98),
        [DVec3::X * 2.0, DVec3::Y * 0.42, DVec3::Z * 0.75],
        red,
        &[
            crate::scene::builder::Face::NegY,
            crate::scene::builder::Face::PosZ,
        ],
    );
    block(
        &mut b,
        sofa,
        at(2.0, 0.0, 4.73),
        DVec3::new(2.0, 0.85, 0.25),
        red,
    );
    bookshelf(
        &mut b,
        "living.bookshelf",
        x0 + 6.0,
        0.6,
        DVec3::new(0.35, 2.0, 1.2),
        5,
        shelf,
    );
    picture(
        &mut b,
        "living.picture",
        5.0,
        at(3.0, 1.55, 0.0),
        (1.0, 0.7),
        gold,
    );
    statue(
        &mut b,
        "living.statue",
        at(5.3, 0.0, 4.3),
        1.7,
        200,
        160,
        marble,
    );
    vase(
        &mut b,
        "living.vase",
        at(3.0, 0.75, 2.25),
        0.35,
        48,
        64,
        glaze,
    );
    block(
        &mut b,
        "studio.cabinet",
        DVec3::new(0.2, 0.0, 0.3),
        DVec3::new(0.5, 0.9, 1.4),
        grey,
    );
    b.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_are_valid_and_the_furnished_room_is_of_real_size() {
        for which in Generated::ALL {
            let s = generate(which);
            s.validate(std::path::Path::new(which.name())).unwrap();
            assert_eq!(s.degenerate_triangles().count(), 0, "{}", which.name());
        }
        assert!(generate(Generated::FurnishedRoom).triangles.len() >= 50_000);
    }

    /// The closed door's inner face shares every vertex on its rim with the doorway's lining
    /// (jambs, lintel, threshold): watertight, so no ray slips between them.
    #[test]
    fn closed_door_shares_its_rim_with_the_doorway() {
        let s = generate(Generated::DoorSealed);
        let object = |name: &str| s.objects.iter().position(|o| o == name).unwrap() as u32;
        let verts = |o: u32| -> std::collections::BTreeSet<u32> {
            (0..s.triangles.len())
                .filter(|&t| s.triangle_object[t] == o)
                .flat_map(|t| s.triangles[t])
                .collect()
        };
        let (door, lining) = (verts(object("dark.door")), verts(object("doorway_1")));
        let x1 = 4.1f32;
        let rim: Vec<u32> = door
            .iter()
            .copied()
            .filter(|&v| {
                let [x, y, z] = s.positions[v as usize];
                x == x1
                    && (y == 0.0 || y == DOOR.1 as f32 || z == 1.5 || z == (1.5 + DOOR.0) as f32)
            })
            .collect();
        // 2.1 m split into 9 and 0.9 m into 4: 2 · (9 + 4) rim vertices.
        assert_eq!(rim.len(), 26);
        for v in rim {
            assert!(
                lining.contains(&v),
                "door vertex {:?} is not the doorway's",
                s.positions[v as usize]
            );
        }
    }
}

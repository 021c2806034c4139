//! A row of rooms along x, separated by walls with doorways: the shell of the bundled indoor
//! scenes.
//!
//! Room k spans x ∈ [x0_k, x1_k], y ∈ [0, height], z ∈ [0, depth]; wall k (between rooms k and
//! k + 1) is a solid slab x ∈ [x1_k, x0_{k+1}] whose doorway (if any) is a hole z ∈ [z0, z1],
//! y ∈ [0, h] lined by two jambs, a lintel and a threshold. Every face is a grid of quads over the
//! same breaks (room corners, doorway edges, light edges), so surfaces that meet share their
//! edges exactly: the shell is watertight for the bake's watertight ray test, and no light
//! leaves a room except through a doorway. Faces point into the rooms; the back of every face
//! (the inside of a wall slab) is never lit.

use crate::scene::builder::SceneBuilder;
use glam::DVec3;

/// A doorway in a wall: the hole z ∈ [z0, z1], y ∈ [0, height].
#[derive(Clone, Copy, Debug)]
pub struct Doorway {
    pub z0: f64,
    pub z1: f64,
    pub height: f64,
}

/// One room of the row.
#[derive(Clone, Debug)]
pub struct Room {
    /// Object-name prefix, e.g. "bright" → "bright.floor".
    pub name: &'static str,
    pub width: f64,
    /// A square ceiling light (centre x offset within the room, centre z, side) and its radiance.
    pub light: Option<(f64, f64, f64, [f32; 3])>,
    /// Floor left out under something that stands on it and seals it, [x0, x1, z0, z1] in the
    /// room's own x (a hidden floor piece would meet a closed door's edge from the other room).
    pub floor_hole: Option<[f64; 4]>,
}

/// The rooms and the walls between them.
#[derive(Clone, Debug)]
pub struct RoomRow {
    pub height: f64,
    pub depth: f64,
    pub rooms: Vec<Room>,
    /// `rooms.len() − 1` walls: (thickness, doorway).
    pub walls: Vec<(f64, Option<Doorway>)>,
}

/// Materials of the shell.
#[derive(Clone, Copy, Debug)]
pub struct ShellMaterials {
    pub floor: u32,
    pub ceiling: u32,
    pub walls: u32,
    pub frame: u32,
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

impl RoomRow {
    /// x extent of each room.
    pub fn room_x(&self) -> Vec<(f64, f64)> {
        let mut x = 0.0;
        let mut out = Vec::new();
        for (k, room) in self.rooms.iter().enumerate() {
            out.push((x, x + room.width));
            x += room.width + self.walls.get(k).map_or(0.0, |w| w.0);
        }
        out
    }

    /// Build the shell into `b`; each room's light is a material added here ("<room>.light").
    pub fn build(&self, b: &mut SceneBuilder, m: ShellMaterials) {
        let xs = self.room_x();
        let (h, d) = (self.height, self.depth);
        for (k, room) in self.rooms.iter().enumerate() {
            let (x0, x1) = xs[k];
            let doors: Vec<Doorway> = [k.checked_sub(1), Some(k)]
                .into_iter()
                .flatten()
                .filter_map(|w| self.walls.get(w).and_then(|w| w.1))
                .collect();
            let light = room.light.map(|(cx, cz, side, radiance)| {
                let mat = b.material(&format!("{}.light", room.name), [0.8; 3], radiance);
                (
                    x0 + cx - side / 2.0,
                    x0 + cx + side / 2.0,
                    cz - side / 2.0,
                    cz + side / 2.0,
                    mat,
                )
            });
            let mut bx = vec![0.0, x1 - x0];
            let mut bz = vec![0.0, d];
            let mut by = vec![0.0, h];
            for door in &doors {
                bz.extend([door.z0, door.z1]);
                by.push(door.height);
            }
            if let Some((lx0, lx1, lz0, lz1, _)) = light {
                bx.extend([lx0 - x0, lx1 - x0]);
                bz.extend([lz0, lz1]);
            }
            if let Some([hx0, hx1, hz0, hz1]) = room.floor_hole {
                bx.extend([hx0, hx1]);
                bz.extend([hz0, hz1]);
            }
            let (bx, by, bz) = (sorted(bx), sorted(by), sorted(bz));
            let origin = DVec3::new(x0, 0.0, 0.0);
            let name = |part: &str| format!("{}.{part}", room.name);
            // Floor (+y = Z × X) and ceiling (−y = X × Z), the light a cell of the ceiling.
            b.grid(origin, (DVec3::Z, &bz), (DVec3::X, &bx), |i, j| {
                let hidden = room.floor_hole.is_some_and(|[hx0, hx1, hz0, hz1]| {
                    (hx0..hx1).contains(&bx[j]) && (hz0..hz1).contains(&bz[i])
                });
                (!hidden).then(|| (name("floor"), m.floor))
            });
            b.grid(
                origin + DVec3::Y * h,
                (DVec3::X, &bx),
                (DVec3::Z, &bz),
                |i, j| match light {
                    Some((lx0, _, lz0, _, mat)) if bx[i] == lx0 - x0 && bz[j] == lz0 => {
                        Some((name("light"), mat))
                    }
                    _ => Some((name("ceiling"), m.ceiling)),
                },
            );
            // Side walls z = 0 (+z = X × Y) and z = depth (−z = Y × X).
            let walls = || Some((name("walls"), m.walls));
            b.grid(origin, (DVec3::X, &bx), (DVec3::Y, &by), |_, _| walls());
            b.grid(
                origin + DVec3::Z * d,
                (DVec3::Y, &by),
                (DVec3::X, &bx),
                |_, _| walls(),
            );
            // End walls x = x0 (+x = Y × Z) and x = x1 (−x = Z × Y), with doorway holes.
            let hole = |door: Option<Doorway>, y: f64, z: f64| {
                door.is_some_and(|dw| y < dw.height && z >= dw.z0 && z < dw.z1)
            };
            let left = k.checked_sub(1).and_then(|w| self.walls[w].1);
            let right = self.walls.get(k).and_then(|w| w.1);
            b.grid(origin, (DVec3::Y, &by), (DVec3::Z, &bz), |i, j| {
                (!hole(left, by[i], bz[j])).then(|| (name("walls"), m.walls))
            });
            b.grid(
                origin + DVec3::X * (x1 - x0),
                (DVec3::Z, &bz),
                (DVec3::Y, &by),
                |i, j| (!hole(right, by[j], bz[i])).then(|| (name("walls"), m.walls)),
            );
        }
        // Doorway linings: jambs, lintel and threshold, spanning the wall's thickness.
        for (k, (t, door)) in self.walls.iter().enumerate() {
            let Some(dw) = door else { continue };
            let x0 = xs[k].1;
            let xt = [0.0, *t];
            let object = format!("doorway_{}", k + 1);
            let at = |y: f64, z: f64| DVec3::new(x0, y, z);
            let ys = [0.0, dw.height];
            let zs = [dw.z0, dw.z1];
            let cell = |_, _| Some((object.clone(), m.frame));
            // Jamb z = z0 faces +z (X × Y); jamb z = z1 faces −z (Y × X).
            b.grid(at(0.0, dw.z0), (DVec3::X, &xt), (DVec3::Y, &ys), cell);
            b.grid(at(0.0, dw.z1), (DVec3::Y, &ys), (DVec3::X, &xt), cell);
            // Lintel faces −y (X × Z); threshold faces +y (Z × X).
            b.grid(at(dw.height, 0.0), (DVec3::X, &xt), (DVec3::Z, &zs), cell);
            b.grid(at(0.0, 0.0), (DVec3::Z, &zs), (DVec3::X, &xt), cell);
        }
    }
}

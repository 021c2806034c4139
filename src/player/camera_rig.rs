//! The window's two cameras, as plain state a test can drive: an orbit around a target (drag,
//! arrows, wheel) and a fly camera for walking through interiors (WASD + mouse, Q/E down/up,
//! Shift 4× faster, wheel scales the speed). Both turn into a [`Camera`] every frame.

use crate::render::camera::Camera;
use glam::Vec3;

/// An orbit around `target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub target: Vec3,
    pub distance: f32,
    /// Degrees around +y from +z.
    pub azimuth: f32,
    /// Degrees above the horizontal plane.
    pub elevation: f32,
    pub fov: f32,
}

impl Orbit {
    /// The orbit through `c`'s eye around its target.
    pub fn from_camera(c: &Camera) -> Orbit {
        let v = c.eye - c.target;
        let distance = v.length().max(1e-6);
        Orbit {
            target: c.target,
            distance,
            azimuth: v.x.atan2(v.z).to_degrees(),
            elevation: (v.y / distance).clamp(-1.0, 1.0).asin().to_degrees(),
            fov: c.fov_y_deg,
        }
    }

    pub fn camera(&self) -> Camera {
        Camera::orbit(
            self.target,
            self.distance,
            self.azimuth,
            self.elevation,
            self.fov,
        )
    }
}

/// Which movement keys are held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Held {
    pub forward: bool,
    pub back: bool,
    pub left: bool,
    pub right: bool,
    pub up: bool,
    pub down: bool,
    pub fast: bool,
}

/// A free-flying camera: an eye, a heading (yaw) and a pitch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fly {
    pub eye: Vec3,
    /// Degrees around +y; 0 looks along −z, 90 along −x.
    pub yaw: f32,
    /// Degrees above the horizontal plane, within ±89.
    pub pitch: f32,
    pub fov: f32,
    /// Metres (scene units) per second.
    pub speed: f32,
    /// Clip planes, fixed from the scene's size so that depth precision does not change as the
    /// eye moves.
    pub near: f32,
    pub far: f32,
}

/// Degrees of turn per pixel of mouse movement.
pub const LOOK_DEG_PER_PIXEL: f32 = 0.15;
/// How many times the speed Shift gives.
pub const FAST: f32 = 4.0;

impl Fly {
    /// A fly camera at `c`'s eye looking where it looks, in a scene of diagonal `diagonal`:
    /// the speed crosses a fifteenth of the diagonal per second (Dabrovic Sponza: 2.6 m/s).
    pub fn from_camera(c: &Camera, diagonal: f32) -> Fly {
        let d = (c.target - c.eye).normalize_or(Vec3::NEG_Z);
        let diagonal = diagonal.max(1e-6);
        Fly {
            eye: c.eye,
            yaw: (-d.x).atan2(-d.z).to_degrees(),
            pitch: d.y.clamp(-1.0, 1.0).asin().to_degrees().clamp(-89.0, 89.0),
            fov: c.fov_y_deg,
            speed: diagonal / 15.0,
            near: diagonal * 1e-4,
            far: diagonal * 4.0,
        }
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (y, p) = (self.yaw.to_radians(), self.pitch.to_radians());
        Vec3::new(-y.sin() * p.cos(), p.sin(), -y.cos() * p.cos())
    }

    /// Unit vector to the right of the view, horizontal.
    pub fn right(&self) -> Vec3 {
        let y = self.yaw.to_radians();
        Vec3::new(y.cos(), 0.0, -y.sin())
    }

    /// Move for `dt` seconds with the keys `held`: forward/back along the view, left/right
    /// horizontally, up/down along +y; diagonals are no faster than straight lines.
    pub fn step(&mut self, held: Held, dt: f32) {
        let axis = |plus: bool, minus: bool| plus as i32 as f32 - minus as i32 as f32;
        let v = self.forward() * axis(held.forward, held.back)
            + self.right() * axis(held.right, held.left)
            + Vec3::Y * axis(held.up, held.down);
        let speed = self.speed * if held.fast { FAST } else { 1.0 };
        self.eye += v.normalize_or_zero() * speed * dt;
    }

    /// Turn by a mouse movement of (`dx`, `dy`) pixels (right and down positive).
    pub fn look(&mut self, dx: f32, dy: f32) {
        self.yaw = (self.yaw - dx * LOOK_DEG_PER_PIXEL).rem_euclid(360.0);
        self.pitch = (self.pitch - dy * LOOK_DEG_PER_PIXEL).clamp(-89.0, 89.0);
    }

    pub fn camera(&self) -> Camera {
        Camera {
            eye: self.eye,
            target: self.eye + self.forward(),
            up: Vec3::Y,
            fov_y_deg: self.fov,
            near: self.near,
            far: self.far,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(eye: Vec3, target: Vec3) -> Camera {
        Camera {
            eye,
            target,
            up: Vec3::Y,
            fov_y_deg: 60.0,
            near: 0.01,
            far: 100.0,
        }
    }

    #[test]
    fn a_fly_camera_looks_where_the_camera_it_starts_from_looks() {
        for target in [
            Vec3::new(3.0, 1.0, -2.0),
            Vec3::new(-1.0, -2.0, 5.0),
            Vec3::X,
            Vec3::NEG_Z,
        ] {
            let c = camera(Vec3::new(0.5, 1.0, 0.0), target);
            let f = Fly::from_camera(&c, 30.0);
            let want = (c.target - c.eye).normalize();
            assert!((f.forward() - want).length() < 1e-5, "{target}");
            assert!(f.right().dot(want).abs() < 1e-5 && f.right().y == 0.0);
            // Right-handed: right × up points backwards.
            assert!(f.right().cross(Vec3::Y).dot(want) < 0.0);
        }
    }

    #[test]
    fn moving_covers_speed_times_time_in_the_held_direction() {
        let mut f = Fly::from_camera(&camera(Vec3::ZERO, Vec3::NEG_Z), 30.0);
        assert!((f.speed - 2.0).abs() < 1e-6);
        f.step(
            Held {
                forward: true,
                ..Default::default()
            },
            0.5,
        );
        assert!((f.eye - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // Forward and right together: still `speed`, at 45°.
        let start = f.eye;
        f.step(
            Held {
                forward: true,
                right: true,
                fast: true,
                ..Default::default()
            },
            1.0,
        );
        let moved = f.eye - start;
        assert!((moved.length() - 2.0 * FAST).abs() < 1e-5);
        assert!((moved.x - moved.length() / 2f32.sqrt()).abs() < 1e-5);
        // Opposite keys cancel.
        let before = f.eye;
        f.step(
            Held {
                up: true,
                down: true,
                ..Default::default()
            },
            1.0,
        );
        assert_eq!(f.eye, before);
    }

    #[test]
    fn looking_turns_and_stops_short_of_the_poles() {
        let mut f = Fly::from_camera(&camera(Vec3::ZERO, Vec3::NEG_Z), 30.0);
        f.look(90.0 / LOOK_DEG_PER_PIXEL, 0.0);
        assert!((f.forward() - Vec3::X).length() < 1e-5, "{}", f.forward());
        f.look(0.0, -1e6);
        assert_eq!(f.pitch, 89.0);
        assert!(f.forward().y < 1.0 && f.camera().target != f.eye);
    }

    #[test]
    fn the_orbit_round_trips_through_its_camera() {
        let o = Orbit {
            target: Vec3::new(1.0, 2.0, 3.0),
            distance: 5.0,
            azimuth: 40.0,
            elevation: 25.0,
            fov: 45.0,
        };
        let back = Orbit::from_camera(&o.camera());
        assert!((back.distance - 5.0).abs() < 1e-4);
        assert!((back.azimuth - 40.0).abs() < 1e-3 && (back.elevation - 25.0).abs() < 1e-3);
    }
}

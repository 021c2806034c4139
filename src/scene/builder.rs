//! Building a [`Scene`] in code: polygons, grids of quads with holes, closed boxes and surfaces
//! of revolution. Used by the bundled scene generators (`scene::generate`) and by the synthetic
//! scenes of tests and benchmarks (`tests/support/fixtures.rs`).
//!
//! Every face winds counter-clockwise about its front normal (the scene convention). Coordinates
//! are given in f64 and stored as f32; two faces built from the same f64 corners therefore share
//! bit-identical edges, which the watertight ray test relies on where surfaces meet.

use super::{Material, Scene};
use glam::DVec3;
use std::collections::HashMap;

/// Builds a [`Scene`] from quads and polygons.
#[derive(Default)]
pub struct SceneBuilder {
    scene: Scene,
    /// With shared vertices: f32 bit pattern of a position → its index.
    shared: Option<HashMap<[u32; 3], u32>>,
    /// Rectangles and grid cells are split so that no edge is longer than this.
    max_edge: Option<f64>,
}

impl SceneBuilder {
    /// A regular `segments`-gon of circumradius `r` at `centre` facing `normal`.
    pub fn disc(
        &mut self,
        object: &str,
        centre: DVec3,
        normal: DVec3,
        r: f64,
        segments: usize,
        material: u32,
    ) {
        let n = normal.normalize();
        let (t, b) = basis(n);
        let pts: Vec<DVec3> = (0..segments)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / segments as f64;
                centre + r * (t * a.cos() + b * a.sin())
            })
            .collect();
        self.polygon(object, &pts, material);
    }

    /// Every triangle gets its own three vertices.
    pub fn new() -> Self {
        Self::default()
    }

    /// Triangles that touch at a corner share one vertex (a connected mesh, smaller files).
    pub fn with_shared_vertices() -> Self {
        SceneBuilder {
            scene: Scene::default(),
            shared: Some(HashMap::new()),
            max_edge: None,
        }
    }

    /// Split rectangles and grid cells into equal cells no longer than `edge` on a side: meshes
    /// fine enough for per-vertex light. The splits of an interval depend only on its ends,
    /// so faces that share an edge keep sharing every vertex along it.
    pub fn max_edge(mut self, edge: f64) -> Self {
        self.max_edge = Some(edge);
        self
    }

    /// `breaks` with every interval [a, b] split into n equal parts, a + (b − a)·(k/n), n the
    /// fewest that keep parts of length `len(a, b)` within `max_edge`.
    fn split(&self, breaks: &[f64], len: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        let mut out = vec![breaks[0]];
        for w in breaks.windows(2) {
            let n = match self.max_edge {
                Some(m) => (len(w[0], w[1]) / m).ceil().max(1.0) as usize,
                None => 1,
            };
            out.extend((1..n).map(|k| w[0] + (w[1] - w[0]) * (k as f64 / n as f64)));
            out.push(w[1]);
        }
        out
    }

    /// Add a material; returns its index.
    pub fn material(&mut self, name: &str, albedo: [f32; 3], emission: [f32; 3]) -> u32 {
        self.scene
            .materials
            .push(Material::plain(name, albedo, emission));
        (self.scene.materials.len() - 1) as u32
    }

    fn object(&mut self, name: &str) -> u32 {
        match self.scene.objects.iter().position(|o| o == name) {
            Some(i) => i as u32,
            None => {
                self.scene.objects.push(name.into());
                (self.scene.objects.len() - 1) as u32
            }
        }
    }

    fn vertex(&mut self, p: DVec3) -> u32 {
        let p = p.as_vec3().to_array();
        let next = self.scene.positions.len() as u32;
        if let Some(shared) = &mut self.shared {
            let key = p.map(f32::to_bits);
            if let Some(&i) = shared.get(&key) {
                return i;
            }
            shared.insert(key, next);
        }
        self.scene.positions.push(p);
        next
    }

    /// A triangle (counter-clockwise front face).
    pub fn triangle(&mut self, object: &str, corners: [DVec3; 3], material: u32) {
        let o = self.object(object);
        let tri = corners.map(|c| self.vertex(c));
        self.scene.triangles.push(tri);
        self.scene.triangle_material.push(material);
        self.scene.triangle_object.push(o);
    }

    /// A convex polygon as a triangle fan (counter-clockwise about its front normal).
    pub fn polygon(&mut self, object: &str, corners: &[DVec3], material: u32) {
        for i in 1..corners.len() - 1 {
            self.triangle(object, [corners[0], corners[i], corners[i + 1]], material);
        }
    }

    /// The rectangle `centre ± u ± v` facing `u × v` (split by [`Self::max_edge`] if set).
    pub fn rectangle(&mut self, object: &str, centre: DVec3, u: DVec3, v: DVec3, material: u32) {
        if self.max_edge.is_some() {
            let unit = [0.0, 1.0];
            let object = object.to_string();
            self.grid(
                centre - u - v,
                (2.0 * u, &unit),
                (2.0 * v, &unit),
                |_, _| Some((object.clone(), material)),
            );
            return;
        }
        self.polygon(
            object,
            &[
                centre - u - v,
                centre + u - v,
                centre + u + v,
                centre - u + v,
            ],
            material,
        );
    }

    /// The cells `origin + a·u + b·v`, a ∈ [us[i], us[i+1]], b ∈ [vs[j], vs[j+1]] (breaks
    /// ascending; each cell split by [`Self::max_edge`] if set), facing u × v,
    /// for which `cell(i, j)` names an object and a material (`None`: a hole). Neighbouring cells
    /// share their edges exactly, so a face split for a doorway or a light stays watertight.
    pub fn grid(
        &mut self,
        origin: DVec3,
        (u, us): (DVec3, &[f64]),
        (v, vs): (DVec3, &[f64]),
        mut cell: impl FnMut(usize, usize) -> Option<(String, u32)>,
    ) {
        // Cells of the split grid map back to the caller's cells (breaks ascending).
        let su = self.split(us, |a, b| (b - a) * u.length());
        let sv = self.split(vs, |a, b| (b - a) * v.length());
        let owner = |given: &[f64], at: f64| given.partition_point(|&g| g <= at).saturating_sub(1);
        for i in 0..su.len().saturating_sub(1) {
            for j in 0..sv.len().saturating_sub(1) {
                if su[i] == su[i + 1] || sv[j] == sv[j + 1] {
                    continue;
                }
                let (ci, cj) = (owner(us, su[i]), owner(vs, sv[j]));
                if let Some((object, material)) = cell(ci, cj) {
                    let p = |a: f64, b: f64| origin + u * a + v * b;
                    let corners = [
                        p(su[i], sv[j]),
                        p(su[i + 1], sv[j]),
                        p(su[i + 1], sv[j + 1]),
                        p(su[i], sv[j + 1]),
                    ];
                    self.polygon(&object, &corners, material);
                }
            }
        }
    }

    /// The six inward-facing faces of the box `[lo, hi]`.
    pub fn box_inside(&mut self, object: &str, lo: DVec3, hi: DVec3, material: u32) {
        let c = (lo + hi) / 2.0;
        let h = (hi - lo) / 2.0;
        let (x, y, z) = (DVec3::X * h.x, DVec3::Y * h.y, DVec3::Z * h.z);
        // Each face's u × v points into the box.
        self.rectangle(object, c - x, y, z, material); // normal +x... y × z = +x
        self.rectangle(object, c + x, z, y, material); // z × y = −x
        self.rectangle(object, c - y, z, x, material); // z × x = +y
        self.rectangle(object, c + y, x, z, material); // x × z = −y
        self.rectangle(object, c - z, x, y, material); // x × y = +z
        self.rectangle(object, c + z, y, x, material); // y × x = −z
    }

    /// The outward faces of the parallelepiped `origin + [0,1]·ex + [0,1]·ey + [0,1]·ez`
    /// (ex, ey, ez right-handed), leaving out the faces in `omit` (a face resting on the floor or
    /// against a wall is never seen).
    pub fn cuboid(
        &mut self,
        object: &str,
        origin: DVec3,
        [ex, ey, ez]: [DVec3; 3],
        material: u32,
        omit: &[Face],
    ) {
        let c = origin + (ex + ey + ez) / 2.0;
        let (x, y, z) = (ex / 2.0, ey / 2.0, ez / 2.0);
        let faces = [
            (Face::NegX, c - x, z, y),
            (Face::PosX, c + x, y, z),
            (Face::NegY, c - y, x, z),
            (Face::PosY, c + y, z, x),
            (Face::NegZ, c - z, y, x),
            (Face::PosZ, c + z, x, y),
        ];
        for (face, centre, u, v) in faces {
            if !omit.contains(&face) {
                self.rectangle(object, centre, u, v, material);
            }
        }
    }

    /// A surface of revolution about the vertical axis through `base`: `profile` lists
    /// (radius, height) from bottom to top; a radius of 0 at either end closes the surface at
    /// the axis. Faces point away from the axis. `segments` steps around.
    pub fn lathe(
        &mut self,
        object: &str,
        base: DVec3,
        profile: &[(f64, f64)],
        segments: usize,
        material: u32,
    ) {
        let point = |(r, y): (f64, f64), s: usize| {
            let a = std::f64::consts::TAU * (s % segments) as f64 / segments as f64;
            base + DVec3::new(r * a.cos(), y, r * a.sin())
        };
        for k in 0..profile.len() - 1 {
            let (lo, hi) = (profile[k], profile[k + 1]);
            for s in 0..segments {
                let quad = [
                    point(lo, s),
                    point(hi, s),
                    point(hi, s + 1),
                    point(lo, s + 1),
                ];
                if lo.0 == 0.0 {
                    self.triangle(object, [quad[0], quad[1], quad[2]], material);
                } else if hi.0 == 0.0 {
                    self.triangle(object, [quad[0], quad[1], quad[3]], material);
                } else {
                    self.polygon(object, &quad, material);
                }
            }
        }
    }

    pub fn build(self) -> Scene {
        self.scene
    }
}

/// A face of [`SceneBuilder::cuboid`], by its outward direction along the box's own edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Face {
    NegX,
    PosX,
    NegY,
    PosY,
    NegZ,
    PosZ,
}

/// An orthonormal basis (t, b) around the unit vector `n` (Duff et al. 2017, branchless).
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn normal(s: &Scene, t: usize) -> glam::Vec3 {
        let [a, b, c] = s.corners(t);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn cuboid_faces_point_outward_and_close() {
        let mut b = SceneBuilder::with_shared_vertices();
        let m = b.material("m", [0.5; 3], [0.0; 3]);
        let o = DVec3::new(1.0, 2.0, 3.0);
        b.cuboid("box", o, [DVec3::X, DVec3::Y * 2.0, DVec3::Z * 3.0], m, &[]);
        let s = b.build();
        assert_eq!(s.positions.len(), 8);
        assert_eq!(s.triangles.len(), 12);
        let centre = glam::Vec3::new(1.5, 3.0, 4.5);
        for t in 0..12 {
            let [a, ..] = s.corners(t);
            assert!(
                normal(&s, t).dot(a - centre) > 0.0,
                "triangle {t} faces inward"
            );
        }
        // Surface area of a 1 × 2 × 3 box: 2 (2 + 3 + 6) = 22.
        assert!((s.total_area() - 22.0).abs() < 1e-5);
    }

    #[test]
    fn lathe_of_a_cylinder_has_its_area_and_faces_out() {
        let mut b = SceneBuilder::with_shared_vertices();
        let m = b.material("m", [0.5; 3], [0.0; 3]);
        let profile = [(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (0.0, 2.0)];
        b.lathe("c", DVec3::ZERO, &profile, 256, m);
        let s = b.build();
        // A regular 256-gon prism against the cylinder 2πrh + 2πr²: 1e-4 apart at 256 steps.
        let exact = 2.0 * std::f64::consts::PI * 2.0 + 2.0 * std::f64::consts::PI;
        assert!((s.total_area() / exact - 1.0).abs() < 1e-3);
        // Convex: every outward normal points away from the centre.
        for t in 0..s.triangles.len() {
            let [a, bb, c] = s.corners(t);
            let d = (a + bb + c) / 3.0 - glam::Vec3::Y;
            assert!(normal(&s, t).dot(d) > 0.0, "triangle {t} faces inward");
        }
    }

    #[test]
    fn grid_cells_share_edges_and_skip_holes() {
        let mut b = SceneBuilder::with_shared_vertices();
        let m = b.material("m", [0.5; 3], [0.0; 3]);
        let xs = [0.0, 1.0, 2.0, 3.0];
        b.grid(DVec3::ZERO, (DVec3::X, &xs), (DVec3::Z, &xs), |i, j| {
            (i != 1 || j != 1).then(|| ("g".to_string(), m))
        });
        let s = b.build();
        assert_eq!(s.triangles.len(), 16);
        assert_eq!(s.positions.len(), 16);
        assert!((s.total_area() - 8.0).abs() < 1e-6);
        // X × Z = −Y.
        assert!(normal(&s, 0).y < -0.99);
    }
}

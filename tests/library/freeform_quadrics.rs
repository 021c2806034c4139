//! Each quadric of the freeform description against its closed-form ray intersection (f64),
//! including tangent rays, rays that start inside, and rays parallel to a cylinder's axis.

use relume::freeform::field::Field;
use relume::freeform::reference::first_hit;
use relume::scene::freeform::FreeformScene;
use std::path::Path;

fn field(shape: &str) -> Field {
    let text = format!("Freeform(shape: {shape})");
    let scene = FreeformScene::parse(Path::new("test.ron"), &text).unwrap();
    Field::compile(&scene.shape).unwrap()
}

fn hit(f: &Field, o: [f64; 3], d: [f64; 3]) -> Option<f64> {
    first_hit(f, o, d, 0.0, 1e6).map(|h| h.t)
}

fn close(a: Option<f64>, b: Option<f64>) {
    match (a, b) {
        (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "{a} vs {b}"),
        (None, None) => {}
        _ => panic!("{a:?} vs {b:?}"),
    }
}

#[test]
fn plane_upward_ray_misses() {
    let f = field("Surface(base: Plane(normal: (0.0, 1.0, 0.0), offset: -1.0))");
    close(hit(&f, [0.0, 2.0, 5.0], [0.0, 0.6, -0.8]), None);
    close(hit(&f, [0.0, 2.0, 5.0], [0.0, -0.6, -0.8]), Some(3.0 / 0.6));
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / l)
}

/// Smallest root > 0 of a t² + b t + c (the closed form, by the textbook formula in f64 with
/// the stable variant), or the tangent root when the discriminant is 0.
fn first_root(a: f64, b: f64, c: f64) -> Option<f64> {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let mut r = [q / a, c / q];
    r.sort_by(f64::total_cmp);
    r.into_iter().find(|t| *t > 0.0)
}

#[test]
fn sphere_and_ellipsoid_hits_are_the_closed_form() {
    let f = field("Surface(base: Sphere(radius: 2.0), transform: (translate: (1.0, -1.0, 0.5)))");
    let c = [1.0, -1.0, 0.5];
    for (o, d) in [
        ([10.0, 0.3, -2.0], [-1.0, -0.1, 0.2]),
        ([1.0, -1.0, 0.5], [0.3, 0.4, 0.5]), // from the centre (inside)
        ([1.5, -0.5, 1.0], [-0.2, 0.9, 0.1]), // inside, off-centre
        ([1.0, -1.0, 9.0], [0.0, 0.0, -1.0]),
    ] {
        let d = unit(d);
        let oc: [f64; 3] = std::array::from_fn(|k| o[k] - c[k]);
        let b = 2.0 * (oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]);
        let cc = oc.iter().map(|x| x * x).sum::<f64>() - 4.0;
        close(hit(&f, o, d), first_root(1.0, b, cc));
    }
    // Tangent: the ray grazes the sphere of radius 2 at (1, 1, 0.5).
    close(hit(&f, [-5.0, 1.0, 0.5], [1.0, 0.0, 0.0]), Some(6.0));
    // A hair outside the tangent: misses.
    close(hit(&f, [-5.0, 1.0 + 1e-7, 0.5], [1.0, 0.0, 0.0]), None);

    let e = field("Surface(base: Ellipsoid(radii: (3.0, 1.0, 2.0)))");
    let (o, d) = ([7.0, 0.2, 1.0], unit([-1.0, 0.05, -0.1]));
    let s = [1.0 / 9.0, 1.0, 0.25];
    let a: f64 = (0..3).map(|k| s[k] * d[k] * d[k]).sum();
    let b: f64 = (0..3).map(|k| 2.0 * s[k] * o[k] * d[k]).sum();
    let c: f64 = (0..3).map(|k| s[k] * o[k] * o[k]).sum::<f64>() - 1.0;
    close(hit(&e, o, d), first_root(a, b, c));
    // Tangent to the ellipsoid's top at (0, 1, 0).
    close(hit(&e, [-4.0, 1.0, 0.0], [1.0, 0.0, 0.0]), Some(4.0));
}

#[test]
fn cylinder_hits_including_rays_along_its_axis() {
    let f = field("Surface(base: Cylinder(radius: 0.5))");
    let (o, d) = ([3.0, 1.0, 0.2], unit([-1.0, 0.3, 0.0]));
    close(
        hit(&f, o, d),
        first_root(
            d[0] * d[0] + d[2] * d[2],
            2.0 * (o[0] * d[0] + o[2] * d[2]),
            o[0] * o[0] + o[2] * o[2] - 0.25,
        ),
    );
    // Parallel to the axis, outside: never hits; inside: never leaves.
    close(hit(&f, [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]), None);
    close(hit(&f, [0.1, 0.0, 0.0], [0.0, -1.0, 0.0]), None);
    // Parallel to the axis on the surface itself is a degenerate case; tangent from outside:
    close(hit(&f, [-4.0, 7.0, 0.5], [1.0, 0.0, 0.0]), Some(4.0));
    // Starting inside, leaving through the wall.
    close(hit(&f, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), Some(0.5));
    // Rotated to lie along x: a ray along x never hits.
    let g = field("Surface(base: Cylinder(radius: 0.5), transform: (rotate: (0.0, 0.0, 90.0)))");
    close(hit(&g, [-9.0, 0.1, 0.1], [1.0, 0.0, 0.0]), None);
    close(hit(&g, [0.0, 5.0, 0.0], [0.0, -1.0, 0.0]), Some(4.5));
}

#[test]
fn cone_paraboloid_hyperboloids_plane_and_general_match_closed_forms() {
    // Cone of half-angle 45°: x² + z² = y².
    let f = field("Surface(base: Cone(half_angle: 45.0))");
    let (o, d) = ([5.0, 2.0, 0.0], unit([-1.0, 0.0, 0.0]));
    close(hit(&f, o, d), Some(3.0));
    let t = 30f64.to_radians().tan();
    let f = field("Surface(base: Cone(half_angle: 30.0))");
    let (o, d) = ([4.0, 3.0, 1.0], unit([-1.0, -0.2, -0.1]));
    let k = t * t;
    close(
        hit(&f, o, d),
        first_root(
            d[0] * d[0] + d[2] * d[2] - k * d[1] * d[1],
            2.0 * (o[0] * d[0] + o[2] * d[2] - k * o[1] * d[1]),
            o[0] * o[0] + o[2] * o[2] - k * o[1] * o[1],
        ),
    );
    // Paraboloid (x² + z²)/r² = y/h with r = 1, h = 2: along −y from above at x = 0.5 → y = 0.5.
    let f = field("Surface(base: Paraboloid(radius: 1.0, height: 2.0))");
    close(hit(&f, [0.5, 9.0, 0.0], [0.0, -1.0, 0.0]), Some(8.5));
    // One sheet, r = 1, h = 1: at y = 0 the waist radius is 1.
    let f = field("Surface(base: Hyperboloid(radius: 1.0, height: 1.0))");
    close(hit(&f, [5.0, 0.0, 0.0], [-1.0, 0.0, 0.0]), Some(4.0));
    // From inside along the axis: never leaves.
    close(hit(&f, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]), None);
    // Two sheets: y² = 1 + x² at x = 0 → the bowl at y = 1.
    let f = field("Surface(base: Hyperboloid(radius: 1.0, height: 1.0, sheets: 2))");
    close(hit(&f, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]), Some(1.0));
    close(
        hit(&f, [3.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        Some(10f64.sqrt()),
    );
    // A tilted plane.
    let f = field("Surface(base: Plane(normal: (1.0, 1.0, 0.0), offset: 0.0))");
    close(hit(&f, [1.0, 3.0, 0.0], [0.0, -1.0, 0.0]), Some(4.0));
    close(hit(&f, [1.0, 3.0, 0.0], [0.0, 0.0, 1.0]), None);
    // The general form of the unit sphere scaled by 3 and moved: same as Sphere.
    let f = field("Surface(base: General(matrix: ((1.0,0.0,0.0,0.0),(0.0,1.0,0.0,0.0),(0.0,0.0,1.0,0.0),(0.0,0.0,0.0,-1.0))), transform: (translate: (0.0, 0.0, -2.0), scale: (3.0, 3.0, 3.0)))");
    close(hit(&f, [0.0, 0.0, 10.0], [0.0, 0.0, -1.0]), Some(9.0));
}

#[test]
fn far_from_the_origin_the_hit_keeps_its_precision() {
    // A sphere of radius 1 at 1e5 from the origin, seen from 10 away.
    let f =
        field("Surface(base: Sphere(radius: 1.0), transform: (translate: (100000.0, 0.0, 0.0)))");
    close(hit(&f, [100010.0, 0.0, 0.0], [-1.0, 0.0, 0.0]), Some(9.0));
}

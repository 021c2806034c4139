//! How far a mesh is from the freeform surface it approximates: the one-sided mesh → surface
//! distance (samples on the triangles projected onto the surface by Newton steps along the
//! gradient) and the surface → mesh coverage distance (surface points found by the exact
//! reference along grid lines, brute-force point–triangle distances). Together they bound the
//! Hausdorff distance the mesher promises (`mesh.rs`).

use super::field::{dot, Field, Op};
use super::mesh::{bits, cross, dist, gradient, lerp, restrict, sub, Mesh};
use super::reference::first_hit;
use rayon::prelude::*;

/// The foot of Newton steps `x ← x − f∇f/|∇f|²` from `x`: a surface point, when they converge.
fn project(field: &Field, x: [f64; 3]) -> Option<[f64; 3]> {
    let mut p = x;
    for _ in 0..64 {
        let (f, g, _) = gradient(field, p);
        let g2 = dot(g, g);
        if !(g2 > 0.0 && g2.is_finite()) {
            return None;
        }
        p = std::array::from_fn(|k| p[k] - f / g2 * g[k]);
        if (f / g2).abs() * g2.sqrt() <= 1e-13 * (1.0 + dot(p, p).sqrt()) {
            return Some(p);
        }
    }
    None
}

/// For a field that is one shape texture, its distance bound along the carrier's normal (where
/// Newton fails: near the poles of a sphere carrier); infinity otherwise.
fn texture_bound(field: &Field, x: [f64; 3]) -> f64 {
    match (field.ops.as_slice(), field.leaves.as_slice()) {
        ([Op::Leaf(0)], [leaf]) => leaf
            .texture
            .map_or(f64::INFINITY, |t| field.textures[t].distance_bound(x)),
        _ => f64::INFINITY,
    }
}

/// The distance from `x` to the surface, from above: to the [`project`] foot, or when Newton
/// does not converge to the nearer exact hit of the rays along ±∇f.
pub fn surface_distance(field: &Field, x: [f64; 3]) -> f64 {
    let along_normal = texture_bound(field, x);
    if let Some(p) = project(field, x) {
        return dist(p, x).min(along_normal);
    }
    let (_, g, _) = gradient(field, x);
    let len = dot(g, g).sqrt();
    let n = if len > 0.0 && len.is_finite() {
        g.map(|v| v / len)
    } else {
        [0.0, 1.0, 0.0]
    };
    let hit = |s: f64| first_hit(field, x, n.map(|v| s * v), 0.0, 1e6).map(|h| h.t);
    hit(1.0)
        .into_iter()
        .chain(hit(-1.0))
        .fold(along_normal, f64::min)
}

/// The one-sided Hausdorff distance mesh → surface: the largest [`surface_distance`] over
/// sample points of every triangle (its barycentric lattice of `m` steps, `m ≥ 2` the least
/// giving `samples_per_triangle` points, and its centroid). Triangles are bucketed by centroid
/// in 16³ boxes over the mesh and project on the field restricted to their box grown by a box
/// (a foot outside that is recomputed on the whole field). The other way: [`coverage_distance`].
pub fn hausdorff_to_surface(field: &Field, mesh: &Mesh, samples_per_triangle: usize) -> f64 {
    let m = (2..)
        .find(|m| (m + 1) * (m + 2) / 2 >= samples_per_triangle)
        .unwrap_or(2);
    let corners = |t: usize| mesh.triangles[t].map(|i| mesh.positions[i as usize]);
    let centroid = |[a, b, c]: [[f64; 3]; 3]| std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
    let lo = mesh.positions.iter().fold([f64::INFINITY; 3], |l, p| {
        std::array::from_fn(|k| l[k].min(p[k]))
    });
    let hi = mesh.positions.iter().fold([f64::NEG_INFINITY; 3], |h, p| {
        std::array::from_fn(|k| h[k].max(p[k]))
    });
    let s = (0..3).map(|k| hi[k] - lo[k]).fold(1e-9, f64::max) / 16.0;
    let mut order: Vec<([i64; 3], usize)> = (0..mesh.triangles.len())
        .map(|t| (centroid(corners(t)), t))
        .map(|(c, t)| {
            (
                std::array::from_fn(|k| ((c[k] - lo[k]) / s).floor() as i64),
                t,
            )
        })
        .collect();
    order.sort_unstable();
    let groups: Vec<&[([i64; 3], usize)]> = order.chunk_by(|x, y| x.0 == y.0).collect();
    let worst = |g: &&[([i64; 3], usize)]| {
        let blo: [f64; 3] = std::array::from_fn(|k| lo[k] + (g[0].0[k] - 1) as f64 * s);
        let bhi: [f64; 3] = std::array::from_fn(|k| lo[k] + (g[0].0[k] + 2) as f64 * s);
        let local = restrict(field, blo, bhi);
        let d = |x: [f64; 3]| match project(&local, x) {
            Some(p) if (0..3).all(|k| p[k] >= blo[k] && p[k] <= bhi[k]) => {
                dist(p, x).min(texture_bound(field, x))
            }
            _ => surface_distance(field, x),
        };
        let mut worst = 0.0f64;
        for &(_, t) in g.iter() {
            let [a, b, c] = corners(t);
            worst = worst.max(d(centroid([a, b, c])));
            for (i, j) in (0..=m).flat_map(|i| (0..=m - i).map(move |j| (i, j))) {
                let (u, v) = (i as f64 / m as f64, j as f64 / m as f64);
                worst = worst.max(d(std::array::from_fn(|k| {
                    a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k])
                })));
            }
        }
        worst
    };
    groups.par_iter().map(worst).reduce(|| 0.0, f64::max)
}

/// Surface points inside the box: every crossing (exact [`first_hit`], repeated) of the lines
/// parallel to each axis through an `n × n` grid of cell centres over the box's other two axes.
pub fn surface_samples(field: &Field, lo: [f64; 3], hi: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    let lines: Vec<(usize, usize)> = (0..3)
        .flat_map(|a| (0..n * n).map(move |ij| (a, ij)))
        .collect();
    let line = |&(a, ij): &(usize, usize)| {
        let (b, c, len) = ((a + 1) % 3, (a + 2) % 3, hi[a] - lo[a]);
        let mut o = lo;
        o[b] += ((ij / n) as f64 + 0.5) / n as f64 * (hi[b] - lo[b]);
        o[c] += ((ij % n) as f64 + 0.5) / n as f64 * (hi[c] - lo[c]);
        let d = bits(1 << a).map(|v| v as f64);
        let (mut t_min, mut pts) = (0.0, Vec::new());
        while let Some(hit) = first_hit(field, o, d, t_min, len) {
            if pts.len() >= 64 {
                break;
            } else if hit.t <= t_min {
                t_min += 1e-9 * len; // a tangent (point) interval: step past it
            } else {
                pts.push(lerp(o, std::array::from_fn(|k| o[k] + d[k]), hit.t));
                t_min = hit.t;
            }
        }
        pts
    };
    let per_line: Vec<Vec<[f64; 3]>> = lines.par_iter().map(line).collect();
    per_line.concat()
}

/// The distance from `p` to triangle `abc`: to its plane when `p` projects inside it, else to
/// the nearest edge.
pub fn point_triangle_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let n = cross(sub(b, a), sub(c, a));
    let edges = [(a, b), (b, c), (c, a)];
    if dot(n, n) > 0.0
        && edges
            .iter()
            .all(|&(u, v)| dot(cross(sub(v, u), sub(p, u)), n) >= 0.0)
    {
        return dot(sub(p, a), n).abs() / dot(n, n).sqrt();
    }
    let segment = |&(u, v): &([f64; 3], [f64; 3])| {
        let d = sub(v, u);
        let t = if dot(d, d) > 0.0 {
            dot(sub(p, u), d) / dot(d, d)
        } else {
            0.0
        };
        dist(p, lerp(u, v, t.clamp(0.0, 1.0)))
    };
    edges.iter().map(segment).fold(f64::INFINITY, f64::min)
}

/// Surface → mesh: the largest distance from a [`surface_samples`] point to the mesh (brute
/// force over the triangles, swept in order of centroid x and pruned by bounding spheres; for
/// tests). With [`hausdorff_to_surface`] it bounds the two-sided Hausdorff distance.
pub fn coverage_distance(field: &Field, mesh: &Mesh, lo: [f64; 3], hi: [f64; 3], n: usize) -> f64 {
    type Tri = ([f64; 3], f64, [[f64; 3]; 3]);
    let mut tris: Vec<Tri> = (mesh.triangles.iter())
        .map(|t| {
            let v = t.map(|i| mesh.positions[i as usize]);
            let c = std::array::from_fn(|k| (v[0][k] + v[1][k] + v[2][k]) / 3.0);
            (c, v.iter().map(|&p| dist(p, c)).fold(0.0, f64::max), v)
        })
        .collect();
    tris.sort_by(|x, y| x.0[0].total_cmp(&y.0[0]));
    let r_max = tris.iter().map(|t| t.1).fold(0.0, f64::max);
    let nearest = |&p: &[f64; 3]| {
        let start = tris.partition_point(|t| t.0[0] < p[0]);
        let mut best = f64::INFINITY;
        let mut visit = |t: &Tri| {
            if dist(p, t.0) - t.1 < best {
                best = best.min(point_triangle_distance(p, t.2[0], t.2[1], t.2[2]));
            }
            (t.0[0] - p[0]).abs() <= best + r_max
        };
        for t in &tris[start..] {
            if !visit(t) {
                break;
            }
        }
        for t in tris[..start].iter().rev() {
            if !visit(t) {
                break;
            }
        }
        best
    };
    let points = surface_samples(field, lo, hi, n);
    points.par_iter().map(nearest).reduce(|| 0.0, f64::max)
}

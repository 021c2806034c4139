"""Per-object mean irradiance of a textured OBJ scene under a sun, by Mitsuba 3's path tracer:
the independent reference of relume's textured radiosity on the Dabrovic Sponza (a cross-check
tool, never in the product; the untextured rooms use mitsuba_objects.py).

usage: mitsuba_textured.py SCENE.obj SPP REPEATS MIN_AREA_SHARE DX DY DZ LUX

Reads the OBJ (v / vt / o / usemtl / f) and its MTL (Kd, map_Kd; texture names resolved
case-insensitively, backslashes allowed, options before the name skipped) and gives every
(object, material) part a face-normal mesh with a Lambertian BSDF whose reflectance is
Kd x map_Kd: the texture decoded from sRGB to linear, multiplied by Kd, read with nearest-texel
lookups and repeat wrapping (what relume integrates). One `directional` emitter of irradiance
LUX (W/m^2 per channel) travels along (DX, DY, DZ). For every object with at least
MIN_AREA_SHARE of the scene's area, each of its parts carries an `irradiancemeter` in turn and
the object's mean is the area-weighted mean of its parts'. REPEATS renders with different seeds,
SPP samples each, by the `path` integrator with unbounded depth.

An irradiance meter starts its rays on the surface, so it never sees a delta light such as the
sun directly: what it measures is the light arriving from other surfaces (`indirect`). The
direct part is computed here with Mitsuba's own ray tracer: DIRECT_POINTS points uniform over
each object's area, each lit by LUX x cos on its front face unless a shadow ray towards the sun
is blocked. Prints JSON: {object: {"indirect": [r, g, b], "indirect_stderr": [r, g, b],
"direct": [r, g, b], "total": [r, g, b], "area": A}}.
"""
import json
import os
import sys
import tempfile

import mitsuba as mi
import numpy as np
from PIL import Image

mi.set_variant("scalar_rgb")

path = sys.argv[1]
spp, repeats, share = int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
sun_dir = [float(x) for x in sys.argv[5:8]]
lux = float(sys.argv[8])
folder = os.path.dirname(path)

# MTL texture options and how many values each takes (min, max).
ARITY = {"-o": (1, 3), "-s": (1, 3), "-t": (1, 3), "-mm": (2, 2)}
ARITY.update({k: (1, 1) for k in ("-blendu", "-blendv", "-bm", "-boost", "-cc", "-clamp",
                                  "-imfchan", "-texres", "-type")})


def resolve(name):
    name = name.replace("\\", "/")
    p = os.path.join(folder, name)
    if os.path.exists(p):
        return p
    cur = folder
    for part in name.split("/"):
        match = [e for e in os.listdir(cur) if e.lower() == part.lower()]
        if not match:
            return None
        cur = os.path.join(cur, match[0])
    return cur


def texture_name(words):
    i = 0
    while i < len(words) and words[i].startswith("-"):
        lo, hi = ARITY[words[i]]
        i += 1
        taken = 0
        while taken < hi and i < len(words):
            try:
                float(words[i])
            except ValueError:
                if taken >= lo:
                    break
            i += 1
            taken += 1
    return " ".join(words[i:])


materials, cur = {}, None
mtllib = open(path).read().split("mtllib ")[1].split("\n")[0].strip()
with open(os.path.join(folder, mtllib)) as f:
    for line in f:
        w = line.split()
        if not w or w[0].startswith("#"):
            continue
        if w[0] == "newmtl":
            cur = w[1]
            materials[cur] = {"Kd": [0.5] * 3, "map": None}
        elif w[0] == "Kd":
            materials[cur]["Kd"] = [float(x) for x in w[1:4]]
        elif w[0] == "map_Kd":
            materials[cur]["map"] = resolve(texture_name(w[1:]))

verts, uvs, parts, order, obj, mat = [], [], {}, [], None, None
with open(path) as f:
    for line in f:
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            verts.append([float(x) for x in w[1:4]])
        elif w[0] == "vt":
            uvs.append([float(x) for x in w[1:3]])
        elif w[0] == "o":
            obj = w[1]
            order.append(obj)
        elif w[0] == "usemtl":
            mat = w[1]
        elif w[0] == "f":
            corners = [[int(x) - 1 if x else -1 for x in (c.split("/") + [""])[:2]] for c in w[1:]]
            for k in range(1, len(corners) - 1):
                parts.setdefault((obj, mat), []).append([corners[0], corners[k], corners[k + 1]])
verts, uvs = np.array(verts), np.array(uvs) if uvs else np.zeros((1, 2))

bitmaps = {}


def reflectance(m):
    if m["map"] is None:
        return {"type": "rgb", "value": m["Kd"]}
    key = (m["map"], tuple(m["Kd"]))
    if key not in bitmaps:
        a = np.asarray(Image.open(m["map"]).convert("RGB")).astype(np.float32) / 255.0
        lin = np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4)
        bitmaps[key] = mi.Bitmap((lin * np.array(m["Kd"], dtype=np.float32)).astype(np.float32))
    return {"type": "bitmap", "bitmap": bitmaps[key], "raw": True, "filter_type": "nearest",
            "wrap_mode": "repeat"}


DIRECT_POINTS = 4096
tmp = tempfile.mkdtemp(prefix="relume-mitsuba-")
shapes, areas, triangles = {}, {}, {}
for (o, m), faces in parts.items():
    faces = np.array(faces)  # [t, 3 corners, (v, vt)]
    tri = verts[faces[:, :, 0]]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    keep = area > 1e-12
    faces, tri, area = faces[keep], tri[keep], area[keep]
    if len(faces) == 0:
        continue
    fname = os.path.join(tmp, f"{len(shapes)}.obj")
    with open(fname, "w") as f:
        for t in tri.reshape(-1, 3):
            f.write("v %r %r %r\n" % tuple(float(x) for x in t))
        for vt in faces[:, :, 1].reshape(-1):
            f.write("vt %r %r\n" % tuple(float(x) for x in (uvs[vt] if vt >= 0 else (0, 0))))
        for i in range(len(faces)):
            f.write("f %d/%d %d/%d %d/%d\n" % (3 * i + 1, 3 * i + 1, 3 * i + 2, 3 * i + 2,
                                               3 * i + 3, 3 * i + 3))
    shapes[(o, m)] = {"type": "obj", "filename": fname, "face_normals": True,
                      "bsdf": {"type": "diffuse", "reflectance": reflectance(materials[m])}}
    areas[(o, m)] = float(area.sum())
    triangles.setdefault(o, []).append((tri, area))

total = sum(areas.values())
by_object = {}
for (o, m), a in areas.items():
    by_object[o] = by_object.get(o, 0.0) + a
measured = [o for o in dict.fromkeys(order) if by_object.get(o, 0.0) >= share * total]

# The whole scene once, for shadow rays.
whole = {"type": "scene"}
for i, shape in enumerate(shapes.values()):
    whole[f"s{i}"] = {k: v for k, v in shape.items() if k != "bsdf"}
whole = mi.load_dict(whole)
to_sun = -np.array(sun_dir) / np.linalg.norm(sun_dir)
lo = np.min(verts, axis=0)
hi = np.max(verts, axis=0)
eps = 1e-4 * np.linalg.norm(hi - lo)
rng = np.random.default_rng(7)


def direct(o):
    tri = np.concatenate([t for t, _ in triangles[o]])
    area = np.concatenate([a for _, a in triangles[o]])
    cdf = np.cumsum(area) / area.sum()
    u = (np.arange(DIRECT_POINTS) + rng.random(DIRECT_POINTS)) / DIRECT_POINTS
    k = np.minimum(np.searchsorted(cdf, u, side="right"), len(tri) - 1)
    r1, r2 = np.sqrt(rng.random(DIRECT_POINTS)), rng.random(DIRECT_POINTS)
    t = tri[k]
    p = t[:, 0] * (1 - r1)[:, None] + t[:, 1] * (r1 * (1 - r2))[:, None] + t[:, 2] * (r1 * r2)[:, None]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    cos = n @ to_sun
    lit = 0.0
    for j in np.nonzero(cos > 0)[0]:
        ray = mi.Ray3f(mi.Point3f(*(p[j] + n[j] * eps)), mi.Vector3f(*to_sun))
        if not whole.ray_test(ray):
            lit += cos[j]
    return lux * lit / DIRECT_POINTS


out = {}
for target in measured:
    runs = np.zeros((repeats, 3))
    for key in [k for k in shapes if k[0] == target]:
        for seed in range(repeats):
            scene = {"type": "scene", "integrator": {"type": "path", "max_depth": -1},
                     "sun": {"type": "directional", "direction": sun_dir,
                             "irradiance": {"type": "rgb", "value": [lux] * 3}}}
            for i, (k, shape) in enumerate(shapes.items()):
                shape = dict(shape)
                if k == key:
                    shape["sensor"] = {
                        "type": "irradiancemeter",
                        "film": {"type": "hdrfilm", "width": 1, "height": 1, "pixel_format": "rgb",
                                 "rfilter": {"type": "box"}},
                        "sampler": {"type": "independent", "sample_count": spp},
                    }
                scene[f"s{i}"] = shape
            img = mi.render(mi.load_dict(scene), seed=seed)
            runs[seed] += np.array(img).reshape(-1)[:3] * areas[key] / by_object[target]
    d = direct(target)
    out[target] = {
        "indirect": runs.mean(0).tolist(),
        "indirect_stderr": (runs.std(0, ddof=1) / np.sqrt(repeats)).tolist() if repeats > 1 else [0.0] * 3,
        "direct": [d] * 3,
        "total": (runs.mean(0) + d).tolist(),
        "area": by_object[target],
    }
    print(target, out[target], file=sys.stderr, flush=True)
print(json.dumps(out))

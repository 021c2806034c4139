"""Per-object mean irradiance of an OBJ scene by Mitsuba 3's path tracer: the independent
reference of relume's radiosity on the bundled rooms (a cross-check tool, never in the product).

usage: mitsuba_objects.py SCENE.obj SPP REPEATS [OBJECT_PREFIX ...]

Reads a plain OBJ (v / o / usemtl / f lines, polygons fan-triangulated; MTL with Kd and Ke) as
`relume-bake generate-scene` writes it, gives every object a face-normal mesh with a diffuse BSDF of its Kd and an area emitter of
its Ke, and attaches an `irradiancemeter` (mean irradiance over the shape's whole area, in
W/m^2, RGB) to each object whose name starts with one of the prefixes. Each object is rendered
REPEATS times with different seeds, SPP samples each, by the `path` integrator with unbounded
depth (Russian roulette after 5 bounces, unbiased). Prints JSON: {object: {"mean": [r, g, b],
"stderr": [r, g, b], "area": A}}.
"""
import json
import os
import sys
import tempfile

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

path, spp, repeats = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
prefixes = sys.argv[4:] or [""]
# RELUME_EMITTER_DROP=d moves emitters by d along -y: a light in its ceiling's plane (the Cornell
# box) would otherwise z-fight with the ceiling in Mitsuba (relume cuts the ceiling instead).
drop = float(os.environ.get("RELUME_EMITTER_DROP", "0"))

materials, cur = {}, None
with open(os.path.join(os.path.dirname(path), open(path).read().split("mtllib ")[1].split()[0])) as f:
    for line in f:
        w = line.split()
        if not w or w[0].startswith("#"):
            continue
        if w[0] == "newmtl":
            cur = w[1]
            materials[cur] = {"Kd": [0.5] * 3, "Ke": [0.0] * 3}
        elif w[0] in ("Kd", "Ke"):
            materials[cur][w[0]] = [float(x) for x in w[1:4]]

verts, objects, order, obj, mat = [], {}, [], None, None
with open(path) as f:
    for line in f:
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            verts.append([float(x) for x in w[1:4]])
        elif w[0] == "o":
            obj = w[1]
            order.append(obj)
        elif w[0] == "usemtl":
            mat = w[1]
        elif w[0] == "f":
            key = (obj, mat)
            poly = [int(x.split("/")[0]) - 1 for x in w[1:]]
            for k in range(1, len(poly) - 1):
                objects.setdefault(key, []).append([poly[0], poly[k], poly[k + 1]])
verts = np.array(verts)

tmp = tempfile.mkdtemp(prefix="relume-mitsuba-")
shapes, areas = {}, {}
for (obj, mat), faces in objects.items():
    faces = np.array(faces)
    used, inverse = np.unique(faces, return_inverse=True)
    fname = os.path.join(tmp, f"{len(shapes)}.obj")
    with open(fname, "w") as f:
        for v in verts[used]:
            f.write("v %r %r %r\n" % tuple(float(x) for x in v))
        for t in inverse.reshape(-1, 3):
            f.write("f %d %d %d\n" % tuple(t + 1))
    tri = verts[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()
    m = materials[mat]
    if max(m["Ke"]) > 0 and drop:
        sub = verts[used].copy()
        sub[:, 1] -= drop
        with open(fname, "w") as f:
            for v in sub:
                f.write("v %r %r %r\n" % tuple(float(x) for x in v))
            for t in inverse.reshape(-1, 3):
                f.write("f %d %d %d\n" % tuple(t + 1))
    shape = {
        "type": "obj",
        "filename": fname,
        "face_normals": True,
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["Kd"]}},
    }
    if max(m["Ke"]) > 0:
        shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["Ke"]}}
    shapes[(obj, mat)] = shape
    areas[obj] = areas.get(obj, 0.0) + area

measured = [o for o in dict.fromkeys(order) if any(o.startswith(p) for p in prefixes)]
out = {}
for target in measured:
    keys = [k for k in shapes if k[0] == target]
    if len(keys) != 1:
        sys.exit(f"object {target} has {len(keys)} materials; the meter needs one shape per object")
    runs = []
    for seed in range(repeats):
        scene = {"type": "scene", "integrator": {"type": "path", "max_depth": -1}}
        for i, (k, shape) in enumerate(shapes.items()):
            shape = dict(shape)
            if k[0] == target:
                shape["sensor"] = {
                    "type": "irradiancemeter",
                    "film": {"type": "hdrfilm", "width": 1, "height": 1, "pixel_format": "rgb",
                             "rfilter": {"type": "box"}},
                    "sampler": {"type": "independent", "sample_count": spp},
                }
            scene[f"s{i}"] = shape
        img = mi.render(mi.load_dict(scene), seed=seed)
        runs.append(np.array(img).reshape(-1)[:3])
    runs = np.array(runs)
    out[target] = {
        "mean": runs.mean(0).tolist(),
        "stderr": (runs.std(0, ddof=1) / np.sqrt(repeats)).tolist() if repeats > 1 else [0.0] * 3,
        "area": areas[target],
    }
print(json.dumps(out))

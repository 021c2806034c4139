"""Writes room.gltf (+ room.bin, checker.png) and room.glb: a small scene that exercises the glTF
loader. Test data only (run once, output committed); relume never runs Python.

Contents:
- node "floor": a 2x2 m quad at y=0, material "checker" (baseColorFactor 0.8 grey x a 2x2 texture)
- node "group" (translation (0, 0.5, 0), uniform scale 2) with child "box" (translation (0.25, 0, 0),
  rotation 90 deg about +y): a unit-size cube (+-0.1) with material "red"
- node "lamp": quad at y=1.5 facing down, material "lamp": emissiveFactor (1, 0.9, 0.8) x
  KHR_materials_emissive_strength 5
- node "sun": directional light rotated -90 deg about x (pointing down -y), intensity 3
- node "bulb", child of "group" at (0, 0.5, 0): point light, colour (1, 0.5, 0.25), intensity 20
"""
import base64, json, math, struct, zlib

def png_rgb(w, h, pixels):
    raw = b"".join(b"\x00" + bytes(sum((list(p) for p in pixels[y * w:(y + 1) * w]), [])) for y in range(h))
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))

checker = png_rgb(2, 2, [(255, 255, 255), (0, 0, 0), (188, 188, 188), (128, 64, 32)])

floor_pos = [(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)]
floor_idx = [0, 1, 2, 0, 2, 3]
uv = [(0, 0), (0, 1), (1, 1), (1, 0)]
lamp_pos = [(-0.2, 1.5, -0.2), (0.2, 1.5, -0.2), (0.2, 1.5, 0.2), (-0.2, 1.5, 0.2)]
lamp_idx = [0, 1, 2, 0, 2, 3]
s = 0.1
cube_pos, cube_idx = [], []
for axis in range(3):
    for sign in (-1, 1):
        n = [0, 0, 0]; n[axis] = sign
        u = [0, 0, 0]; u[(axis + 1) % 3] = 1
        v = [0, 0, 0]; v[(axis + 2) % 3] = 1
        if sign < 0:
            u, v = v, u
        base = len(cube_pos)
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            cube_pos.append(tuple(s * (n[k] + a * u[k] + b * v[k]) for k in range(3)))
        cube_idx += [base, base + 1, base + 2, base, base + 2, base + 3]

blob = b""; views = []; accessors = []
def add(data, target, count, ctype, typ, mn=None, mx=None):
    global blob
    while len(blob) % 4: blob += b"\x00"
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
    blob += data
    acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": typ}
    if mn is not None: acc["min"] = mn; acc["max"] = mx
    accessors.append(acc)
    return len(accessors) - 1
def vec3(ps):
    return add(b"".join(struct.pack("<3f", *p) for p in ps), 34962, len(ps), 5126, "VEC3",
               [min(p[k] for p in ps) for k in range(3)], [max(p[k] for p in ps) for k in range(3)])
def idx(ix):
    return add(struct.pack("<%dH" % len(ix), *ix), 34963, len(ix), 5123, "SCALAR")
fp, fi, ft = vec3(floor_pos), idx(floor_idx), add(b"".join(struct.pack("<2f", *t) for t in uv), 34962, 4, 5126, "VEC2")
cp, ci = vec3(cube_pos), idx(cube_idx)
lp, li = vec3(lamp_pos), idx(lamp_idx)

q = math.sqrt(0.5)
doc = {
    "asset": {"version": "2.0", "generator": "relume scenes/gltf-room/generate.py"},
    "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1, 1, 0.9], "intensity": 3},
        {"name": "bulb", "type": "point", "color": [1, 0.5, 0.25], "intensity": 20, "range": 10}]}},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 3, 4]}],
    "nodes": [
        {"name": "floor", "mesh": 0},
        {"name": "group", "translation": [0, 0.5, 0], "scale": [2, 2, 2], "children": [2, 5]},
        {"name": "box", "mesh": 1, "translation": [0.25, 0, 0], "rotation": [0, q, 0, q]},
        {"name": "lamp", "mesh": 2},
        {"name": "sun", "rotation": [-q, 0, 0, q], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "bulb", "translation": [0, 0.5, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
    ],
    "meshes": [
        {"name": "floor", "primitives": [{"attributes": {"POSITION": fp, "TEXCOORD_0": ft}, "indices": fi, "material": 0}]},
        {"name": "cube", "primitives": [{"attributes": {"POSITION": cp}, "indices": ci, "material": 1}]},
        {"name": "lamp", "primitives": [{"attributes": {"POSITION": lp}, "indices": li, "material": 2}]},
    ],
    "materials": [
        {"name": "checker", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "baseColorTexture": {"index": 0}, "metallicFactor": 0}},
        {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1], "metallicFactor": 0}},
        {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0},
         "emissiveFactor": [1, 0.9, 0.8], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}},
    ],
    "textures": [{"source": 0}],
    "images": [{"uri": "checker.png"}],
    "buffers": [{"uri": "room.bin", "byteLength": len(blob)}],
    "bufferViews": views,
    "accessors": accessors,
}
open("room.bin", "wb").write(blob)
open("checker.png", "wb").write(checker)
open("room.gltf", "w").write(json.dumps(doc, indent=1))

# GLB: image embedded as a buffer view, buffer in the BIN chunk.
glb_blob = blob
while len(glb_blob) % 4: glb_blob += b"\x00"
doc2 = json.loads(json.dumps(doc))
doc2["bufferViews"].append({"buffer": 0, "byteOffset": len(glb_blob), "byteLength": len(checker)})
glb_blob += checker
while len(glb_blob) % 4: glb_blob += b"\x00"
doc2["images"] = [{"bufferView": len(doc2["bufferViews"]) - 1, "mimeType": "image/png"}]
doc2["buffers"] = [{"byteLength": len(glb_blob)}]
js = json.dumps(doc2).encode()
while len(js) % 4: js += b" "
glb = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(glb_blob))
glb += struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(glb_blob), 0x004E4942) + glb_blob
open("room.glb", "wb").write(glb)

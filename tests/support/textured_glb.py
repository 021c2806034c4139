# Per textured primitive of a relume GLB export: predict `_RADIANCE` from `COLOR_0` / exposure x
# the base colour factor x the mean linear value of the embedded image (Pillow), on unclamped
# vertices; also count the materials whose alpha travels as a mask. Prints JSON.
# Usage: python3 textured_glb.py FILE.glb
import io, json, struct, sys
import numpy as np
from PIL import Image
raw = open(sys.argv[1], 'rb').read()
jlen, = struct.unpack_from('<I', raw, 12)
doc = json.loads(raw[20:20 + jlen])
bin_ = raw[28 + jlen:]
exposure = doc['scenes'][0]['extras']['relume']['exposure']
def view(i):
    v = doc['bufferViews'][i]
    o = v.get('byteOffset', 0)
    return bin_[o:o + v['byteLength']]
def acc(i):
    a = doc['accessors'][i]
    n = {'VEC3': 3, 'VEC2': 2, 'SCALAR': 1}[a['type']]
    return np.frombuffer(view(a['bufferView']), dtype=np.float32, count=a['count'] * n).reshape(a['count'], n)
def linear(c):
    c = c / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
worst, checked, textured = 0.0, 0, 0
for mesh in doc['meshes']:
    for p in mesh['primitives']:
        pbr = doc['materials'][p['material']]['pbrMetallicRoughness']
        if 'baseColorTexture' not in pbr:
            continue
        textured += 1
        src = doc['textures'][pbr['baseColorTexture']['index']]['source']
        img = np.asarray(Image.open(io.BytesIO(view(doc['images'][src]['bufferView']))).convert('RGBA'))
        mean = linear(img[:, :, :3].astype(np.float64)).reshape(-1, 3).mean(axis=0) * np.array(pbr['baseColorFactor'][:3])
        col, rad = acc(p['attributes']['COLOR_0']), acc(p['attributes']['_RADIANCE'])
        ok = (col < 0.999).all(axis=1) & (rad.max(axis=1) > 1e-3)
        if ok.any():
            err = np.abs(col[ok] / exposure * mean - rad[ok]).max(axis=1) / rad[ok].max(axis=1)
            worst = max(worst, float(err.max()))
            checked += int(ok.sum())
masks = sum(1 for m in doc['materials'] if m.get('alphaMode') == 'MASK')
print(json.dumps({'textured_primitives': textured, 'checked': checked, 'worst': worst, 'masks': masks}))

"""Writes the binary members of the bad-input corpus (the text ones are committed as written).
Test data only: relume never runs Python."""
import struct, zlib
import numpy as np, tifffile

def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
# A PNG whose header says 0x0 pixels.
open("zero-size.png", "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 0, 0, 8, 0, 0, 0, 0))
                                  + chunk(b"IDAT", zlib.compress(b"")) + chunk(b"IEND", b""))
# A TIFF of 64-bit floats (a sample format relume does not read).
tifffile.imwrite("float64.tif", np.zeros((4, 4), dtype=np.float64))
# A TIFF of RGB bytes (three samples per pixel: not a height map).
tifffile.imwrite("rgb.tif", np.zeros((4, 4, 3), dtype=np.uint8), photometric="rgb")
# A float32 TIFF with a NaN height (rejected under the default no-data policy).
a = np.arange(16, dtype=np.float32).reshape(4, 4); a[2, 1] = np.nan
tifffile.imwrite("nan-height.tif", a)
# A GLB whose JSON chunk length runs past the end of the file.
js = b'{"asset":{"version":"2.0"}}  '
open("broken-chunk.glb", "wb").write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js)) + struct.pack("<II", len(js) + 100, 0x4E4F534A) + js)
# A colour PNG (channels differ): not a height map.
raw = b"\x00" + bytes([255, 0, 0, 0, 255, 0])
open("colour.png", "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 1, 8, 2, 0, 0, 0))
                               + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
# A raw f32 file of 3 values (not a whole 2x2 grid).
open("short.raw", "wb").write(struct.pack("<3f", 1, 2, 3))
# Added with the discovered corpus (tests/cli/bad_inputs.rs):
# A .npy of the wrong shape and one of float64, for tampered bakes given to the player.
np.save("wrong-shape.npy", np.zeros((3, 5), dtype=np.float32))
np.save("float64.npy", np.zeros((3, 4, 4), dtype=np.float64))
# A raw f32 2x2 grid with a NaN.
open("nan.raw", "wb").write(struct.pack("<4f", 1, float("nan"), 3, 4))
# The first 2000 bytes of the bundled Puget Sound JPEG, and 5000 of the Big Tujunga GeoTIFF.
open("truncated.jpg", "wb").write(open("../../scenes/dem/puget_sound_4k.jpg", "rb").read()[:2000])
open("truncated.tif", "wb").write(open("../../scenes/dem/srtm_bigtujunga_30m.tif", "rb").read()[:5000])
# An EXR header of version 1 (relume reads OpenEXR 2.0).
open("not-an-exr.exr", "wb").write(b"v/1\x01" + b"\x00" * 60)
# 200 random bytes named .ron.
import random
random.seed(7)
open("binary.ron", "wb").write(bytes(random.randrange(256) for _ in range(200)))
# An EXR whose header declares 4096x4096 ZIP texels (256 chunks) but whose file ends after 1000
# bytes: refused before the decoder allocates and fills what is missing.
import OpenEXR, Imath
_h = OpenEXR.Header(4096, 4096)
_h["channels"] = {"Y": Imath.Channel(Imath.PixelType(Imath.PixelType.FLOAT))}
_h["compression"] = Imath.Compression(Imath.Compression.ZIP_COMPRESSION)
_f = OpenEXR.OutputFile("exr-chunks-missing.exr", _h)
_f.writePixels({"Y": np.zeros((4096, 4096), np.float32).tobytes()})
_f.close()
_b = open("exr-chunks-missing.exr", "rb").read()[:1000]
open("exr-chunks-missing.exr", "wb").write(_b)

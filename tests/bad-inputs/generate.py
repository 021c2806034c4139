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

#!/usr/bin/env python3
"""Denoise an Ajar EXR with Intel Open Image Denoise (pyoidn from PyPI).

Optional demonstration, never a dependency of Ajar: tests/oidn/run.sh makes
a venv under build/oidn with `pyoidn` (which bundles the OIDN library) and
`OpenEXR`, renders with `--aov albedo,normal` and runs this script.

usage: denoise.py IN.exr OUT.exr [OUT.png]
Reads R,G,B and, if present, albedo.R/G/B and normal.X/Y/Z (as written by
`ajar render --aov albedo,normal`), denoises the HDR colour with them as
auxiliary images, and writes RGBA to OUT.exr (and an sRGB PNG preview)."""
import sys

import numpy as np
import OpenEXR
import pyoidn


def channels(parts, names):
    """The named channels as an (h, w, len(names)) float32 array, or None."""
    ch = parts[0].channels
    try:
        return np.stack([np.asarray(ch[n].pixels, dtype=np.float32) for n in names], axis=-1)
    except KeyError:
        return None


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    with OpenEXR.File(sys.argv[1], separate_channels=True) as f:
        parts = f.parts
        color = channels(parts, ["R", "G", "B"])
        albedo = channels(parts, ["albedo.R", "albedo.G", "albedo.B"])
        normal = channels(parts, ["normal.X", "normal.Y", "normal.Z"])
    if color is None:
        sys.exit(f"{sys.argv[1]}: no R, G, B channels")
    # OIDN wants the normal only with the albedo.
    out = pyoidn.denoise(color, albedo, normal if albedo is not None else None, hdr=True)
    out = np.ascontiguousarray(out, dtype=np.float32)
    h, w, _ = out.shape
    rgba = np.concatenate([out, np.ones((h, w, 1), np.float32)], axis=-1)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGBA": rgba}) as f:
        f.write(sys.argv[2])
    if len(sys.argv) == 4:
        srgb = np.where(out <= 0.0031308, 12.92 * out, 1.055 * np.power(np.maximum(out, 0), 1 / 2.4) - 0.055)
        png = (np.clip(srgb, 0, 1) * 255 + 0.5).astype(np.uint8)
        write_png(sys.argv[3], png)
    print(f"denoised {sys.argv[1]} ({w}x{h}, albedo {'yes' if albedo is not None else 'no'}, "
          f"normal {'yes' if normal is not None and albedo is not None else 'no'}) -> {sys.argv[2]}")


def write_png(path, rgb):
    """A plain 8-bit RGB PNG (zlib only, no imaging library needed)."""
    import struct
    import zlib

    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""A small synthetic booth capture for 'replica booth build': the shipped booth's three lamps
(names, ceiling geometry and CIE spectra as data/booth/booth.json has them), each photographed as
six bracketed 8-bit greyscale PNGs of a ceiling whose luminance falls from a flat centre towards
the edges (not the shipped booth's images, so the booth built differs from it), and calibrated
by a spot of known luminance at the centre.

    make_capture.py OUT_DIR [SCALE]   -> OUT_DIR/capture.json and OUT_DIR/*.png

SCALE multiplies every lamp's luminance (default 1), for a second, different capture.
The format is documented in docs/booth-capture.md."""
import json
import math
import os
import struct
import sys
import zlib

W, H = 96, 64
CORNERS = [[8, 8], [88, 8], [88, 56], [8, 56]]  # ceiling uv (0,0),(1,0),(1,1),(0,1)
SECONDS = [1 / 4000, 1 / 1000, 1 / 250, 1 / 60, 1 / 15, 1 / 4]
LAMPS = [("tungsten", "A", 2200.0), ("d50-fluorescent", "F8", 2600.0),
         ("d65-fluorescent", "F7", 2600.0)]


def write_png(path, rows):
    """8-bit greyscale PNG, no filtering."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = b"".join(b"\0" + bytes(r) for r in rows)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 0, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def camera(x):
    """An S-shaped camera response of exposure x, quantised (as tests/unit/booth/hdr_capture_test)."""
    x = max(x, 0.0)
    return min(255, max(0, round(255.0 * (x / (x + 1.0)) ** (1.0 / 1.8))))


def luminance(px, py, peak):
    """The scene seen by the camera: the ceiling inside the corners, a dim wall outside."""
    (x0, y0), (x1, y1) = CORNERS[0], CORNERS[2]
    if not (x0 <= px < x1 and y0 <= py < y1):
        return 5.0
    u = (px + 0.5 - x0) / (x1 - x0) - 0.5
    v = (py + 0.5 - y0) / (y1 - y0) - 0.5
    r = math.hypot(u, v)
    return peak * (1.0 if r < 0.15 else max(0.35, 1.0 - 1.6 * (r - 0.15)))


def main():
    out = sys.argv[1]
    scale = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
    os.makedirs(out, exist_ok=True)
    lights = []
    for name, column, nominal in LAMPS:
        peak = nominal * 1.25 * scale
        exposures = []
        for i, t in enumerate(SECONDS):
            rows = [[camera(luminance(x, y, peak) * t * 0.5) for x in range(W)] for y in range(H)]
            file = f"{name}-{i}.png"
            write_png(os.path.join(out, file), rows)
            exposures.append({"file": file, "seconds": t})
        lights.append({
            "name": name,
            "spd_column": column,
            "centre": [0.0, 0.62, -0.05],
            "edge_u": [1.0, 0.0, 0.0],
            "edge_v": [0.0, 0.0, 0.5],
            "texels": [32, 16],
            "corners": CORNERS,
            "exposures": exposures,
            "calibration": {"spot": {"x": 48, "y": 32, "radius": 4, "cdm2": peak}},
        })
    with open(os.path.join(out, "capture.json"), "w") as f:
        json.dump({"lights": lights}, f, indent=2)


if __name__ == "__main__":
    main()

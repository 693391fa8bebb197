"""Helpers of 'replica figures' (data/figures/figures.py): reading OpenEXR frames, the CIE tables,
colorimetry (XYZ, CIELAB, CIEDE2000, sRGB at a fixed white balance), running 'replica render'
with a progress line, and writing each figure's caption and numbers."""
import csv
import math
import os
import shlex
import struct
import subprocess
import sys
import time
import zlib

import numpy as np


def read_exr(path):
    """Scan-line OpenEXR (NONE, ZIPS or ZIP; HALF, FLOAT or UINT) -> {channel: H x W float32}."""
    d = open(path, 'rb').read()
    if d[:4] != b'\x76\x2f\x31\x01':
        raise ValueError(f'{path}: not OpenEXR')
    p, attrs = 8, {}
    while d[p] != 0:
        e = d.index(b'\0', p)
        name = d[p:e].decode()
        p = d.index(b'\0', e + 1) + 1
        size, = struct.unpack_from('<i', d, p)
        attrs[name] = d[p + 4:p + 4 + size]
        p += 4 + size
    p += 1
    chans, raw, q = [], attrs['channels'], 0
    while raw[q] != 0:
        e = raw.index(b'\0', q)
        ptype, = struct.unpack_from('<i', raw, e + 1)
        chans.append((raw[q:e].decode(), ptype))
        q = e + 17
    x0, y0, x1, y1 = struct.unpack('<4i', attrs['dataWindow'])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    comp = attrs['compression'][0]
    if comp not in (0, 2, 3):
        raise ValueError(f'{path}: compression {comp} is not read here')
    lines = 16 if comp == 3 else 1
    offsets = struct.unpack_from(f'<{(h + lines - 1) // lines}Q', d, p)
    nbytes = {0: 4, 1: 2, 2: 4}
    dtype = {0: '<u4', 1: '<f2', 2: '<f4'}
    out = {c: np.zeros((h, w), np.float32) for c, _ in chans}
    for off in offsets:
        y, size = struct.unpack_from('<ii', d, off)
        blk = d[off + 8:off + 8 + size]
        n = min(lines, y1 + 1 - y)
        if comp != 0 and size < n * w * sum(nbytes[t] for _, t in chans):
            t = np.frombuffer(zlib.decompress(blk), np.uint8).astype(np.int64)
            t = (np.cumsum(np.concatenate([t[:1], t[1:] - 128])) & 0xFF).astype(np.uint8)
            half = (len(t) + 1) // 2
            b = np.empty(len(t), np.uint8)
            b[0::2], b[1::2] = t[:half], t[half:]
            blk = b.tobytes()
        q = 0
        for r in range(n):
            for c, t in chans:
                nb = w * nbytes[t]
                out[c][y - y0 + r] = np.frombuffer(blk[q:q + nb], dtype[t])
                q += nb
    return out


def load_table(path):
    """A spectral CSV of the data folder ('#' comments, a header, one row a wavelength)."""
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith('#')) if r]
    head = rows[0]
    values = np.array([[float(v) for v in r] for r in rows[1:]])
    return {name: values[:, i] for i, name in enumerate(head)}


class Colour:
    """The CIE 1931 observer and the 10 nm illuminants of the data folder (380-730 nm, 36 bands)."""

    def __init__(self, data):
        cmf = load_table(os.path.join(data, 'spectra', 'cie1931_2deg_cmf_10nm_380_730.csv'))
        self.cmf = np.stack([cmf['xbar'], cmf['ybar'], cmf['zbar']])
        self.ill = load_table(
            os.path.join(data, 'spectra', 'cie_illuminants_10nm_380_730_triangular.csv'))

    def xyz(self, spd, refl):
        """Relative XYZ of a reflectance under a light: the perfect white has Y = 100."""
        k = 100.0 / (self.cmf[1] @ spd)
        return k * (self.cmf @ (spd * refl))


def lab(xyz, white):
    xyz = np.asarray(xyz, float)
    t = xyz / np.asarray(white, float)
    f = np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]),
                     200 * (f[..., 1] - f[..., 2])], -1)


def de00(lab1, lab2):
    """CIEDE2000 (Sharma, Wu and Dalal 2005) of two CIELAB colours."""
    L1, a1, b1 = lab1
    L2, a2, b2 = lab2
    cb = (math.hypot(a1, b1) + math.hypot(a2, b2)) / 2
    g = 0.5 * (1 - math.sqrt(cb ** 7 / (cb ** 7 + 25.0 ** 7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1, c2 = math.hypot(a1p, b1), math.hypot(a2p, b2)
    h1 = math.degrees(math.atan2(b1, a1p)) % 360 if c1 > 0 else 0.0
    h2 = math.degrees(math.atan2(b2, a2p)) % 360 if c2 > 0 else 0.0
    dh = 0.0
    if c1 * c2 > 0:
        dh = h2 - h1
        dh = dh - 360 if dh > 180 else (dh + 360 if dh < -180 else dh)
    dH = 2 * math.sqrt(c1 * c2) * math.sin(math.radians(dh / 2))
    lb, cbp = (L1 + L2) / 2, (c1 + c2) / 2
    if c1 * c2 == 0:
        hb = h1 + h2
    elif abs(h1 - h2) <= 180:
        hb = (h1 + h2) / 2
    else:
        hb = (h1 + h2 + 360) / 2 if h1 + h2 < 360 else (h1 + h2 - 360) / 2
    t = (1 - 0.17 * math.cos(math.radians(hb - 30)) + 0.24 * math.cos(math.radians(2 * hb)) +
         0.32 * math.cos(math.radians(3 * hb + 6)) - 0.20 * math.cos(math.radians(4 * hb - 63)))
    rt = (-2 * math.sqrt(cbp ** 7 / (cbp ** 7 + 25.0 ** 7)) *
          math.sin(math.radians(60 * math.exp(-((hb - 275) / 25) ** 2))))
    sl = 1 + 0.015 * (lb - 50) ** 2 / math.sqrt(20 + (lb - 50) ** 2)
    sc, sh = 1 + 0.045 * cbp, 1 + 0.015 * cbp * t
    dl, dc = (L2 - L1) / sl, (c2 - c1) / sc
    return math.sqrt(dl ** 2 + dc ** 2 + (dH / sh) ** 2 + rt * dc * (dH / sh))


def daylight_white(cct):
    """The CIE daylight locus at a correlated colour temperature (4000-25000 K), Y = 1."""
    if cct <= 7000:
        x = -4.6070e9 / cct ** 3 + 2.9678e6 / cct ** 2 + 0.09911e3 / cct + 0.244063
    else:
        x = -2.0064e9 / cct ** 3 + 1.9018e6 / cct ** 2 + 0.24748e3 / cct + 0.237040
    y = -3.0 * x * x + 2.870 * x - 0.275
    return np.array([x / y, 1.0, (1 - x - y) / y])


BRADFORD = np.array([[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367],
                     [0.0389, -0.0685, 1.0296]])
XYZ_TO_SRGB = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415],
                        [0.0557, -0.2040, 1.0570]])
D65_WHITE = np.array([0.95047, 1.0, 1.08883])


def srgb(xyz, white_cct=5500.0, exposure=1.0):
    """Absolute XYZ (... x 3) -> 8-bit-ready sRGB in [0, 1], white balanced once for white_cct (a
    camera set to that CCT, as the paper's Fig. 6) and scaled so that Y = exposure is white."""
    src = BRADFORD @ daylight_white(white_cct)
    dst = BRADFORD @ D65_WHITE
    m = XYZ_TO_SRGB @ np.linalg.inv(BRADFORD) @ np.diag(dst / src) @ BRADFORD
    rgb = np.clip((np.asarray(xyz, float) / exposure) @ m.T, 0.0, 1.0)
    return np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)


def frame_xyz(path):
    img = read_exr(path)
    return np.stack([img['X'], img['Y'], img['Z']], -1)


class Runner:
    """Runs 'replica' for the panels, a progress line each on stderr, and keeps each command line
    for the captions."""

    def __init__(self, replica, extra):
        self.replica, self.extra, self.commands = replica, extra, {}

    def render(self, fig, label, args, out):
        cmd = [self.replica, 'render'] + args + self.extra + ['--out', out]
        start = time.monotonic()
        progress(f'{fig}: {label}: {shlex.join(["replica"] + cmd[1:])}')
        r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if r.returncode != 0:
            raise RuntimeError(f'{fig}: {label}: replica render failed: {r.stderr.strip()}')
        progress(f'{fig}: {label}: done in {time.monotonic() - start:.1f} s')
        self.commands.setdefault(fig, []).append((label, shlex.join(['replica'] + cmd[1:])))
        return frame_xyz(out)


def progress(line):
    print(f'figures: {line}', file=sys.stderr, flush=True)


def write_csv(path, header, rows, comment):
    with open(path, 'w', newline='') as f:
        f.write(f'# {comment}\n')
        w = csv.writer(f, lineterminator='\n')
        w.writerow(header)
        for r in rows:
            w.writerow([f'{v:.6g}' if isinstance(v, float) else v for v in r])


def write_caption(path, title, what, commands):
    with open(path, 'w') as f:
        f.write(f'{title}\n\n{what}\n\nPanels, each made by:\n')
        for label, cmd in commands:
            f.write(f'- {label}: {cmd}\n')

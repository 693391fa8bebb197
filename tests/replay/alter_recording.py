#!/usr/bin/env python3
"""Writes a copy of a recording with changes, for tests/replay/older_recording.sh: keys of its run
configuration set (as an older build would have recorded them) and thumbnails replaced by a flat
colour (what was shown, tampered with), and for tests/replay/hostile_input.sh the accelerometer's
recorded scale on every raw input (a JSON value: 1e308, 0, null). The copy is unchunked MCAP (as format 1 wrote it; the
reader takes it for every format), its zstd chunks decompressed with the zstd command.

usage: alter_recording.py IN OUT [--config KEY=JSON]... [--session KEY=JSON]...
                          [--tamper-thumbnails N] [--drop-thumbnails] [--accel-scale JSON]
"""
import argparse
import base64
import json
import struct
import subprocess
import sys
import zlib

MAGIC = b"\x89MCAP0\r\n"


def records(data, at, end):
    while at < end:
        op = data[at]
        (length,) = struct.unpack_from("<Q", data, at + 1)
        yield op, data[at + 9:at + 9 + length]
        at += 9 + length


def string(body, at):
    (n,) = struct.unpack_from("<I", body, at)
    return body[at + 4:at + 4 + n].decode(), at + 4 + n


def rec(op, body):
    return bytes([op]) + struct.pack("<Q", len(body)) + body


def png_chunk(kind, payload):
    return (struct.pack(">I", len(payload)) + kind + payload +
            struct.pack(">I", zlib.crc32(kind + payload) & 0xFFFFFFFF))


def flat_png(like, rgb):
    """A PNG of the same size as the PNG 'like', every pixel 'rgb' (8-bit RGB)."""
    width, height = struct.unpack(">II", like[16:24])
    row = b"\x00" + bytes(rgb) * width
    return (b"\x89PNG\r\n\x1a\n" +
            png_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            png_chunk(b"IDAT", zlib.compress(row * height)) + png_chunk(b"IEND", b""))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--config", action="append", default=[], help="KEY=JSON value to set")
    p.add_argument("--session", action="append", default=[],
                   help="KEY=JSON value to set in the session (format_version, software)")
    p.add_argument("--tamper-thumbnails", type=int, default=0,
                   help="replace the first N thumbnails by a flat magenta")
    p.add_argument("--drop-thumbnails", action="store_true")
    p.add_argument("--accel-scale", help="JSON value for each axis of every raw accelerometer "
                   "input's scale")
    a = p.parse_args()
    data = open(a.input, "rb").read()
    if data[:8] != MAGIC:
        sys.exit(f"{a.input}: not an MCAP file")
    flat = []  # (op, body) of the data section, chunks opened
    for op, body in records(data, 8, len(data) - 8):
        if op == 0x0F:  # data end: the summary after it is not copied
            break
        if op == 0x06:
            at = 8 * 3 + 4
            compression, at = string(body, at)
            (length,) = struct.unpack_from("<Q", body, at)
            payload = body[at + 8:at + 8 + length]
            if compression == "zstd":
                payload = subprocess.run(["zstd", "-d", "-c"], input=payload, check=True,
                                         capture_output=True).stdout
            elif compression:
                sys.exit(f"{a.input}: chunk compression {compression!r} not handled")
            flat.extend(records(payload, 0, len(payload)))
        elif op not in (0x07, 0x08, 0x0A, 0x0B, 0x0D, 0x0E):  # indexes go with the chunks
            flat.append((op, body))
    topics = {}
    out = []
    tampered = 0
    for op, body in flat:
        if op == 0x04:
            (cid,) = struct.unpack_from("<H", body, 0)
            topics[cid], _ = string(body, 4)
        elif op == 0x05:
            (cid,) = struct.unpack_from("<H", body, 0)
            head, payload = body[:22], body[22:]
            topic = topics.get(cid)
            if topic == "/replica/session" and (a.config or a.session):
                session = json.loads(payload)
                config = json.loads(session["config"])
                for item in a.config:
                    key, value = item.split("=", 1)
                    config[key] = json.loads(value)
                session["config"] = json.dumps(config)
                for item in a.session:
                    key, value = item.split("=", 1)
                    session[key] = json.loads(value)
                payload = json.dumps(session).encode()
            elif topic == "/replica/raw/accel" and a.accel_scale is not None:
                msg = json.loads(payload)
                v = json.loads(a.accel_scale)
                msg["scale"] = [v, v, v]
                payload = json.dumps(msg).encode()
            elif topic == "/replica/thumbnail":
                if a.drop_thumbnails:
                    continue
                if tampered < a.tamper_thumbnails:
                    msg = json.loads(payload)
                    png = base64.b64decode(msg["data"])
                    msg["data"] = base64.b64encode(flat_png(png, (255, 0, 255))).decode()
                    payload = json.dumps(msg).encode()
                    tampered += 1
            body = head + payload
        out.append(rec(op, body))
    footer = rec(0x0F, struct.pack("<I", 0)) + rec(0x02, struct.pack("<QQI", 0, 0, 0))
    open(a.output, "wb").write(MAGIC + b"".join(out) + footer + MAGIC)
    if tampered < a.tamper_thumbnails:
        sys.exit(f"{a.input}: only {tampered} thumbnails to tamper with")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes hostile recordings for tests/replay/hostile_input.sh: well-formed MCAP (so that the checks
under test, not the framing, refuse them) that lie about sizes, hold decompression bombs, name files
outside the data folder, carry impossible frames or terminal escapes. Written by hand (uncompressed
chunks, or zstd frames of RLE blocks) so that no zstd library is needed.

usage: craft_recordings.py OUTDIR
"""
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib

MAGIC = b"\x89MCAP0\r\n"


def rec(op, body):
    return bytes([op]) + struct.pack("<Q", len(body)) + body


def s(text):
    b = text.encode() if isinstance(text, str) else text
    return struct.pack("<I", len(b)) + b


def schema(sid, name):
    return rec(0x03, struct.pack("<H", sid) + s(name) + s("jsonschema") + s('{"type":"object"}'))


def channel(cid, sid, topic):
    return rec(0x04, struct.pack("<HH", cid, sid) + s(topic) + s("json") + struct.pack("<I", 0))


def message(cid, seq, t, data):
    return rec(0x05, struct.pack("<HIQQ", cid, seq, t, t) + data)


def chunk(records, compression="", claimed=None, payload=None, crc=True):
    body = payload if payload is not None else records
    size = claimed if claimed is not None else len(records)
    c = zlib.crc32(records) & 0xFFFFFFFF if crc and payload is None else 0
    return rec(0x06, struct.pack("<QQQI", 0, 0, size, c) + s(compression) +
               struct.pack("<Q", len(body)) + body)


def rle_zstd(n, byte=b"\x00"):
    """A zstd frame of n copies of one byte: single segment, 8-byte content size, RLE blocks."""
    out = struct.pack("<I", 0xFD2FB528) + bytes([0xE0]) + struct.pack("<Q", n)
    left = n
    while True:
        k = min(left, 128 * 1024)
        left -= k
        last = 1 if left == 0 else 0
        out += struct.pack("<I", last | (1 << 1) | (k << 3))[:3] + byte
        if left == 0:
            return out


def finish(parts):
    data = MAGIC + rec(0x01, s("") + s("replica 0.1.0 (format 3)")) + b"".join(parts)
    data += rec(0x0F, struct.pack("<I", 0))
    data += rec(0x02, struct.pack("<QQI", 0, 0, 0)) + MAGIC
    return data


TOPICS = [(1, "replica.Session", "/replica/session"), (2, "replica.SpectrometerSample",
          "/hal/spectrometer"), (3, "replica.TrackerPose", "/hal/tracker"),
          (4, "replica.AccelSample", "/hal/accel"), (5, "replica.Frame", "/replica/frame"),
          (6, "replica.RecorderStatus", "/replica/recorder"),
          (7, "replica.LampSelectorSample", "/hal/lamp_selector")]

CONFIG = {"basis": "replica_k6", "booth": "replica-booth-1", "booth_lights": 32,
          "display": "displays/wide-ips-synthetic.json", "display_black_cd_m2": 0.4,
          "display_digest": "1ba0ae061986ad8c", "display_inverse": "analytic",
          "display_peak_cd_m2": 800.0, "false_colour": False, "flare_subtraction": True,
          "gamut_mapping": "hue", "height": 20, "horizon_directions": 8, "lights_u": 8,
          "lights_v": 4, "rate_hz": 60.0, "renderer": "booth", "scene": "colorchecker",
          "scene_digest": "fe8aaccefc1a0c64", "scene_dir": "scenes/colorchecker",
          "spectrometer_calibration": "spectrometer/sim_usb2000_responsivity.csv",
          "specular_samples": 16, "viewing_compensation": True, "width": 32}


DELETE = object()  # a config_changes value: remove the key


def device(model):
    return {"firmware": "sim", "model": model, "serial": "SIM-1", "source": "sim"}


def session(config, software="replica 0.1.0"):
    return {"accel": device("accel"), "booth": "replica-booth-1", "config": json.dumps(config),
            "display_profile": "wide-ips-synthetic", "format_version": 3,
            "lamp_selector": device(""), "scene": "colorchecker", "software": software,
            "spectrometer": device("spectrometer"), "tracker": device("tracker"),
            "wall_clock_start_ns": 1795445344985983302}


def recording(config_changes=None, frames=((0, 0), (1, 16666667)), software="replica 0.1.0",
              extra=(), session_changes=None, config_text=None):
    config = dict(CONFIG)
    config.update(config_changes or {})
    for key, value in (config_changes or {}).items():
        if value is DELETE:
            del config[key]
    sess = session(config, software)
    if config_text is not None:  # the configuration string exactly as given
        sess["config"] = config_text
    sess.update(session_changes or {})
    records = b"".join(schema(i, n) for i, n, _ in TOPICS)
    records += b"".join(channel(i, i, t) for i, _, t in TOPICS)
    records += message(1, 0, 0, json.dumps(sess).encode())
    for k, (index, tick) in enumerate(frames):
        records += message(5, k, tick, json.dumps({"frame": index, "tick_ns": tick}).encode())
    for cid, data in extra:
        records += message(cid, 0, 0, data)
    return finish([chunk(records)])


def nested_chunks(size, claimed_zero):
    """Chunks nested in chunks to 'size' bytes, each holding the next: claiming 0 uncompressed
    bytes, or their true size with a wrong CRC. Recover tries each as a place to resynchronise.
    Written outermost first (each level's header is 49 bytes), so that writing it is linear."""
    header = 9 + 28 + 4 + 8
    levels = size // header
    out = [MAGIC]
    for k in range(levels, 0, -1):
        inner = (k - 1) * header
        body = struct.pack("<QQQI", 0, 0, 0 if claimed_zero else inner, 0xDEADBEEF)
        out.append(bytes([0x06]) + struct.pack("<Q", header - 9 + inner) + body + s("") +
                   struct.pack("<Q", inner))
    return b"".join(out)


def indexed(records, chunk_offset):
    """A recording whose summary holds one Chunk Index claiming the chunk at 'chunk_offset'."""
    head = MAGIC + rec(0x01, s("") + s("replica 0.1.0 (format 3)"))
    the_chunk = chunk(records)
    data = head + the_chunk + rec(0x0F, struct.pack("<I", 0))
    index = rec(0x08, struct.pack("<QQQQ", 0, 0, chunk_offset, len(the_chunk)) + s(b"") +
                struct.pack("<Q", 0) + s("") + struct.pack("<QQ", 0, 0))
    summary_start = len(data)
    return data + index + rec(0x02, struct.pack("<QQI", summary_start, 0, 0)) + MAGIC


def session_records(config, second_session=None):
    """The records of a sound recording; with 'second_session', a second /replica/session
    channel (id 8) whose message holds that configuration."""
    records = b"".join(schema(i, n) for i, n, _ in TOPICS)
    records += b"".join(channel(i, i, t) for i, _, t in TOPICS)
    records += message(1, 0, 0, json.dumps(session(config)).encode())
    records += message(5, 0, 0, json.dumps({"frame": 0, "tick_ns": 0}).encode())
    if second_session is not None:
        records += channel(8, 1, "/replica/session")
        records += message(8, 0, 0, json.dumps(session(second_session)).encode())
    return records


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)

    def write(name, data):
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)

    write("sound.mcap", recording())
    write("frame-16384x1.mcap", recording({"width": 16384, "height": 1}))
    write("profile-etc-shadow.mcap", recording({"display": "/etc/shadow"}))
    write("calibration-dotdot.mcap",
          recording({"spectrometer_calibration": "../../../../etc/passwd"}))
    write("scene-elsewhere.mcap", recording({"scene_dir": "/tmp", "scene_digest": ""}))
    write("scene-undigested.mcap", recording({"scene_digest": ""}))
    write("rate-nan.mcap", recording({"rate_hz": 0.0}))
    write("lights-overflow.mcap", recording({"lights_u": 65536, "lights_v": 65536}))
    # The session message and the run configuration against their written schemas.
    write("session-format-string.mcap", recording(session_changes={"format_version": "3"}))
    write("session-config-object.mcap", recording(session_changes={"config": {"width": 32}}))
    write("session-clock-negative.mcap", recording(session_changes={"wall_clock_start_ns": -5}))
    write("session-device-number.mcap",
          recording(session_changes={"tracker": {"model": 7, "serial": "", "firmware": "",
                                                 "source": "sim"}}))
    write("session-unknown-key.mcap", recording(session_changes={"owner": "someone"}))
    write("config-rate-1e308.mcap", recording({"rate_hz": 1e308}))
    write("config-rate-inf.mcap", recording(config_text=json.dumps(CONFIG).replace(
        '"rate_hz": 60.0', '"rate_hz": 1e999')))
    write("config-width-string.mcap", recording({"width": "32"}))
    write("config-width-missing.mcap", recording({"width": DELETE}))
    write("config-rotation-8.mcap",
          recording({"t_booth_tracker": {"rotation": [1, 0, 0, 0, 1, 0, 0, 0],
                                         "translation": [0, 0.42, 0.05]}}))
    write("config-lod-bias-null.mcap", recording({"specular_lod_bias": None}))
    write("config-not-json.mcap", recording(config_text='{"width": 32,'))
    write("config-unknown-key.mcap", recording({"exposure_hack": 3}))
    write("tick-backwards.mcap", recording(frames=((0, 20000000), (1, 10000000))))
    write("tick-285-years.mcap", recording(frames=((0, 0), (1, 9000000000000000000))))
    write("escapes.mcap", recording(software="\x1b]0;owned\x07\x1b[2J\x1b[31mreplica"))
    spectrum = {"t": 0, "seq": 0, "integration_time_us": 1000, "counts": [7] * 20000,
                "wavelength_coeffs": [0, 0, 0, 0], "nonlinearity_coeffs": [0] * 8,
                "saturated": False}
    write("spectrum-20000-counts.mcap", recording(extra=[(2, json.dumps(spectrum).encode())]))
    big = json.dumps({"frame": 0, "tick_ns": 0, "pad": "x" * (2 << 20)}).encode()
    write("message-2mib.mcap", recording(extra=[(5, big)]))
    # Issue 32: JSON nested 100,000 deep in the run configuration and in the session message.
    deep = "[" * 100000 + "]" * 100000
    write("config-deep.mcap", recording(config_text='{"width": ' + deep + "}"))
    write("session-deep.mcap",
          recording(session_changes={"owner": json.loads("[" * 200 + "]" * 200)}))
    # A second /replica/session channel with another frame size.
    write("session-twice.mcap", finish([chunk(session_records(
        CONFIG, dict(CONFIG, width=640, height=480)))]))
    # A chunk index claiming offset 2^63; and one off by a byte.
    write("index-2pow63.mcap", indexed(session_records(CONFIG), 1 << 63))
    write("index-off-by-one.mcap", indexed(session_records(CONFIG), 8 + 9 + 32 + 1))
    write("index-sound.mcap", indexed(session_records(CONFIG), 8 + 9 + 32))
    # 16 MiB of nested chunks for recover (quadratic before: 143 s).
    write("nested-zero-16mib.mcap", nested_chunks(16 << 20, True))
    write("nested-crc-16mib.mcap", nested_chunks(16 << 20, False))
    # Chunks that claim 256 MiB each (4, and 200) but hold a few bytes.
    tiny = rle_zstd(16)
    write("claims-4x256mib.mcap",
          finish([chunk(b"", "zstd", 256 << 20, tiny) for _ in range(4)]))
    write("claims-200x256mib.mcap",
          finish([chunk(b"", "zstd", 256 << 20, tiny) for _ in range(200)]))
    # A chunk whose frame holds less than it claims.
    write("claims-more-than-frame.mcap", finish([chunk(b"", "zstd", 8 << 20, tiny)]))
    # A decompression bomb within the per-chunk limit: 40 chunks of 16 MiB (640 MiB) from ~20 KiB.
    # Each decompresses to zero bytes that read as empty records of an unknown opcode (9 bytes
    # each, hence 16 MiB - 1), so every chunk is sound and only the total budget stops them.
    size = (16 << 20) - 1
    bomb = rle_zstd(size)
    write("bomb-40x16mib.mcap", finish([chunk(b"", "zstd", size, bomb) for _ in range(40)]))
    # The worst for memory: chunks of the smallest messages (33 bytes each, every one kept), 40 of
    # 16 MiB from 60 KB. Needs a real compressor: written only where the zstd program exists.
    zstd = shutil.which("zstd")
    if zstd:
        defs = b"".join(schema(i, n) for i, n, _ in TOPICS)
        defs += b"".join(channel(i, i, t) for i, _, t in TOPICS)
        one = message(5, 0, 0, b"{}")
        records = one * ((16 << 20) // len(one))
        packed = subprocess.run([zstd, "-19", "-q", "-c", "--content-size"], input=records,
                                capture_output=True, check=True).stdout
        write("messages-40x16mib.mcap",
              finish([chunk(defs)] + [chunk(records, "zstd", len(records), packed)] * 40))


if __name__ == "__main__":
    main()

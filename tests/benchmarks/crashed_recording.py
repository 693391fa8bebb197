#!/usr/bin/env python3
"""Writes a large recording as a crash leaves one, for measuring `replica recover`.

Usage: crashed_recording.py GOLDEN OUT REPEATS

OUT is GOLDEN's magic and Header record, then GOLDEN's data-section records (everything after the
Header up to the Data End record) repeated REPEATS times, and no Data End, summary or footer: what a
SIGKILL or power cut leaves. tests/replay/goldens/kiosk-painting.mcap repeated 344 times is the
105,163,216-byte file of docs/limits.md ("What the limits cost, measured").
"""
import struct
import sys

MAGIC = b"\x89MCAP0\r\n"
HEADER, DATA_END = 0x01, 0x0F


def main():
    golden, out, repeats = sys.argv[1], sys.argv[2], int(sys.argv[3])
    data = open(golden, "rb").read()
    if not data.startswith(MAGIC):
        sys.exit(f"{golden}: not an MCAP file")
    at = len(MAGIC)
    head = body_start = body_end = None
    while at + 9 <= len(data):
        op, length = struct.unpack_from("<BQ", data, at)
        end = at + 9 + length
        if op == HEADER and head is None:
            head = data[: end]
            body_start = end
        elif op == DATA_END:
            body_end = at
            break
        at = end
    if head is None or body_end is None:
        sys.exit(f"{golden}: no Header or no Data End record")
    body = data[body_start:body_end]
    with open(out, "wb") as f:
        f.write(head)
        for _ in range(repeats):
            f.write(body)


if __name__ == "__main__":
    main()

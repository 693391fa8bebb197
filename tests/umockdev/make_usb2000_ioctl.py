#!/usr/bin/env python3
"""Writes the usbdevfs ioctl record (umockdev's ioctl-tree format) of a USB2000+ session, from the
protocol in docs hardware-protocols section 1, for the real libusb path under umockdev-run:
open (initialise), the EEPROM calibration read, trigger mode and integration time, two spectra
(the first is discarded by the driver after an integration-time change) and a third whose
transfer fails with ENODEV: the device unplugged.

Record fields: ioctl return value, URB type (3 = bulk), endpoint (decimal), status, flags,
buffer length, actual length, error count, data (hex). An indented record is the reply to the
command above it. OUT data must match the driver's bytes exactly."""
import struct
import sys

EEPROM = {0: "USB2+F00001", 1: "339.2", 2: "0.3797", 3: "-1.62e-05", 4: "-1.3e-10",
          14: "1", 6: "1.0", 7: "-2e-06"}
REPLY_BUFFER = 64            # the driver reads replies into 64 bytes
SPECTRUM_BUFFER = 4097 + 512  # and spectra into 4097 + 512
ENODEV = 19


def out(data):
    return f"USBDEVFS_REAPURBNDELAY 0 3 1 0 0 {len(data)} {len(data)} 0 {data.hex().upper()}"


def reply(ep, buffer_len, data, status=0):
    return (f" USBDEVFS_REAPURBNDELAY 0 3 {ep} {status} 0 {buffer_len} {len(data)} 0 "
            f"{data.hex().upper()}")


def slot(n):
    if n == 17:  # saturation: binary u16 LE in data bytes 4-5
        data = bytes(4) + struct.pack("<H", 60000) + bytes(9)
    else:
        text = EEPROM.get(n, "").encode()
        data = text + bytes(15 - len(text))
    return bytes([0x05, n]) + data


def spectrum(k):
    # Pixel i: a smooth ramp plus a peak at pixel 1000 + 10 k; dark pixels 6..20 at 1000.
    counts = [1000 + (i % 1024) // 8 for i in range(2048)]
    counts[1000 + 10 * k] = 30000 + k
    return struct.pack("<2048H", *counts) + bytes([0x69])


lines = [out(bytes([0x01]))]
for n in [0, 1, 2, 3, 4, 14, 6, 7, 17]:
    lines += [out(bytes([0x05, n])), reply(0x81, REPLY_BUFFER, slot(n))]
lines.append(out(bytes([0x0A, 0x00, 0x00])))                   # trigger mode 0
lines.append(out(bytes([0x02]) + struct.pack("<I", 100000)))   # 100 ms
for k in range(2):
    lines += [out(bytes([0x09])), reply(0x82, SPECTRUM_BUFFER, spectrum(k))]
lines += [out(bytes([0x09])), reply(0x82, SPECTRUM_BUFFER, b"", status=-ENODEV)]
sys.stdout.write("\n".join(lines) + "\n")

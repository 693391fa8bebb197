#!/usr/bin/env python3
"""Compares the guest's screendump with the frames the host rendered headless.

compare-screen.py SCREEN.png FRAMES_DIR
Each frame-NNNNNN.png in FRAMES_DIR is one frame of the same recording replayed on the host. The
screen shows one of them (which one depends on when the screendump was taken): the best match is
reported with its count of differing pixels and largest channel difference. Exit 0 when a frame
matches exactly (RGB; the screendump has no alpha), 1 otherwise.
"""
import os
import sys

from PIL import Image, ImageChops


def main():
    screen = Image.open(sys.argv[1]).convert("RGB")
    if screen.getbbox() is None:
        print("compare-screen: the screen is black: it shows no frame")
        return 1
    frames = sorted(p for p in os.listdir(sys.argv[2]) if p.endswith(".png"))
    if not frames:
        print("compare-screen: no frames in %s" % sys.argv[2])
        return 1
    best = None
    for name in frames:
        frame = Image.open(os.path.join(sys.argv[2], name)).convert("RGB")
        if frame.size != screen.size:
            print("compare-screen: %s is %dx%d, the screen %dx%d"
                  % (name, *frame.size, *screen.size))
            return 1
        diff = ImageChops.difference(screen, frame)
        bbox = diff.getbbox()
        if bbox is None:
            print("screendump %dx%d equals %s exactly (%d frames compared)"
                  % (*screen.size, name, len(frames)))
            return 0
        # Differing pixels: any channel non-zero.
        r, g, b = diff.point(lambda v: 255 if v else 0).split()
        mask = ImageChops.lighter(ImageChops.lighter(r, g), b)
        count = mask.histogram()[255]
        peak = max(hi for _, hi in diff.getextrema())
        if best is None or count < best[1]:
            best = (name, count, peak)
    w, h = screen.size
    print("screendump %dx%d matches no frame exactly; closest %s: %d pixels (%.3f%%) differ, by "
          "at most %d counts" % (w, h, best[0], best[1], 100.0 * best[1] / (w * h), best[2]))
    return 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Converts an X window dump (xwd, 24/32-bit TrueColor ZPixmap) to PNG with
numpy and matplotlib, which the project already needs, instead of ImageMagick.

usage: xwd_to_png.py in.xwd out.png
"""
import struct
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(src, dst):
    data = open(src, "rb").read()
    fields = struct.unpack(">25I", data[:100])
    (header_size, _version, pixmap_format, _depth, width, height, _xoffset, byte_order, _unit, _bit_order,
     _pad, bits_per_pixel, bytes_per_line, _visual, red_mask, green_mask, blue_mask, _bits_rgb, _cmap_entries,
     ncolors) = fields[:20]
    if pixmap_format != 2 or bits_per_pixel != 32:
        sys.exit(f"xwd_to_png: only 32-bit ZPixmap dumps (got format {pixmap_format}, {bits_per_pixel} bpp)")
    start = header_size + ncolors * 12
    rows = np.frombuffer(data[start:start + bytes_per_line * height], dtype=np.uint8).reshape(height, bytes_per_line)
    pixels = rows[:, :width * 4].copy().view("<u4" if byte_order == 0 else ">u4").reshape(height, width)

    def channel(mask):
        shift = (mask & -mask).bit_length() - 1
        return ((pixels & mask) >> shift).astype(np.uint8)

    rgb = np.dstack([channel(red_mask), channel(green_mask), channel(blue_mask)])
    plt.imsave(dst, rgb)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(*sys.argv[1:])

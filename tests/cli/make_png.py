#!/usr/bin/env python3
"""Writes a small 8-bit PNG with exactly known samples, for compare tests no render can give (an
alpha-only change, a pixel differing by a chosen amount).
Usage: make_png.py OUT WIDTH HEIGHT CHANNELS VALUE [X,Y,C=VALUE ...]
Every sample is VALUE (0..255) except those named by X,Y,C=VALUE (C: 0 R, 1 G, 2 B, 3 A)."""
import struct
import sys
import zlib


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def main():
    out, w, h, nch, base = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
    rows = [[base] * (w * nch) for _ in range(h)]
    for spec in sys.argv[6:]:
        where, value = spec.split("=")
        x, y, c = (int(v) for v in where.split(","))
        rows[y][x * nch + c] = int(value)
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    colour_type = {3: 2, 4: 6}[nch]
    with open(out, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour_type, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw)))
        f.write(chunk(b"IEND", b""))


main()

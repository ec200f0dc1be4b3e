#!/usr/bin/env python3
"""tools/png_rgb_equal.py A.png B.png: exit 0 when the decoded 8-bit RGB samples of A and B are identical
(alpha, if any, dropped). Prints the colour types and the count of differing samples."""
import struct, sys, zlib

def decode(path):
    d = open(path, 'rb').read()
    assert d[:8] == b'\x89PNG\r\n\x1a\n', path
    i, idat = 8, b''
    while i < len(d):
        n = struct.unpack('>I', d[i:i + 4])[0]
        t = d[i + 4:i + 8]
        if t == b'IHDR':
            w, h, bd, ct, _, _, il = struct.unpack('>IIBBBBB', d[i + 8:i + 21])
            assert bd == 8 and il == 0 and ct in (2, 6), (path, bd, ct, il)
        elif t == b'IDAT':
            idat += d[i + 8:i + 8 + n]
        i += 12 + n
    raw = zlib.decompress(idat)
    bpp = 3 if ct == 2 else 4
    stride = w * bpp
    out, prev = bytearray(), bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        for x in range(w):
            out += line[x * bpp:x * bpp + 3]
    return (w, h, ct), bytes(out)

(ha, a), (hb, b) = decode(sys.argv[1]), decode(sys.argv[2])
diff = sum(x != y for x, y in zip(a, b)) if ha[:2] == hb[:2] else -1
print(f"{sys.argv[1]}: {ha[0]}x{ha[1]} colour type {ha[2]}; {sys.argv[2]}: {hb[0]}x{hb[1]} colour type {hb[2]}; "
      f"RGB samples differing: {diff} of {len(a)}")
sys.exit(0 if diff == 0 else 1)

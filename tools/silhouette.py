"""Silhouettes of rendered images: which pixels are not background, and how two such sets overlap.

Shared by the independent checks against view3dscene (view3dscene_check.py, browser_compare.py).
Pure Python (no PIL on the CI machine): 8-bit RGB/RGBA PNGs only, which both programs write.
"""
import os, struct, subprocess, zlib

V3D_SERVER_ARGS = "-screen 0 640x480x24"


def read_png(path):
    data = open(path, "rb").read()
    pos, chunks, width = 8, [], 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, height, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and ctype in (2, 6), (path, depth, ctype)
            channels = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            chunks.append(body)
        pos += 12 + n
    raw = zlib.decompress(b"".join(chunks))
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            p = (0, a, b, (a + b) // 2, None)[f] if f < 4 else None
            if f == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else b if pb <= pc else c
            line[i] = (line[i] + p) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        prev = line
    return rows


def border_colour(rows):
    """The commonest colour on the image's border: the background of a scene framed inside it."""
    border = rows[0] + rows[-1] + [r[0] for r in rows] + [r[-1] for r in rows]
    return max(set(border), key=border.count)


def mask(rows, bg=None):
    """Pixels farther than 24 of 255 from the background colour (a corner unless given): well above
    8-bit dither and anti-aliasing noise of a flat background, below any lit surface's contrast."""
    bg = rows[0][0] if bg is None else bg
    return {(x, y) for y, r in enumerate(rows) for x, p in enumerate(r)
            if max(abs(p[i] - bg[i]) for i in range(3)) > 24}


def iou(a, b):
    return len(a & b) / len(a | b) if a | b else 1.0


def view3dscene_cmd(scene, width, height, *screenshot_args):
    """view3dscene's headless screenshot command; under xvfb-run unless a display is already set."""
    cmd = ["view3dscene", scene, "--geometry", f"{width}x{height}", *screenshot_args]
    if os.environ.get("DISPLAY"):
        return cmd
    return ["xvfb-run", "-a", "-s", V3D_SERVER_ARGS, *cmd]

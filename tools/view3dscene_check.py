#!/usr/bin/env python3
"""Independent check of animation at --time (SPEC section 12) against view3dscene (Castle Game Engine).

For each scene, renders t = 0, 0.5, 1.0 s with vrmlray and with view3dscene's --screenshot-range
(headless under xvfb-run), and prints the silhouette overlap (intersection over union of the pixels
that are not background) per time, and the overlap of what moved between t = 0 and each time.
Lighting models differ between the two programs; silhouettes (where objects are) do not.

    tools/setup.sh view3dscene xvfb xauth        # the peer, as the benches install theirs
    tools/view3dscene_check.py build/vrmlray WORK_DIR SCENE [SCENE...]
A scene without a Viewpoint gets one in a copy under WORK_DIR (view3dscene frames such files its own
way): the camera vrmlray's framing note names.
"""
import os, re, struct, subprocess, sys, zlib

TIMES = [0.0, 0.5, 1.0]
W, H = 320, 240


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


def mask(rows):
    bg = rows[0][0]  # a corner: background in every frame these scenes have
    return {(x, y) for y, r in enumerate(rows) for x, p in enumerate(r)
            if max(abs(p[i] - bg[i]) for i in range(3)) > 24}


def iou(a, b):
    return len(a & b) / len(a | b) if a | b else 1.0


def main():
    vrmlray, work, scenes = sys.argv[1], sys.argv[2], sys.argv[3:]
    os.makedirs(work, exist_ok=True)
    for scene in scenes:
        stem = os.path.basename(scene).replace(".", "_")
        note = subprocess.run([vrmlray, "render", scene, "-W", str(W), "-H", str(H), "-o",
                               f"{work}/{stem}_probe.png"], capture_output=True, text=True).stderr
        m = re.search(r"no Viewpoint: framed from \+Z at \((\S+) (\S+) (\S+)\)", note)
        if m:  # the same camera for both programs
            text = open(scene).read()
            vp = " ".join(m.groups())
            if scene.endswith(".x3d"):
                text = text.replace("<Scene>", f"<Scene><Viewpoint position='{vp}'/>", 1)
            else:
                lines = text.split("\n")
                lines.insert(2, f"Viewpoint {{ position {vp} }}")
                text = "\n".join(lines)
            scene = f"{work}/{stem}_vp{os.path.splitext(scene)[1]}"
            open(scene, "w").write(text)
        subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 640x480x24", "view3dscene", scene,
                        "--geometry", f"{W}x{H}", "--screenshot-range", "0", "0.5", "3",
                        f"{work}/{stem}_v3d_@counter(1).png"], capture_output=True, timeout=120)
        ours, theirs = [], []
        for k, t in enumerate(TIMES):
            out = f"{work}/{stem}_vr_{k}.png"
            subprocess.run([vrmlray, "render", scene, "-W", str(W), "-H", str(H), "-q", "--time",
                            str(t), "-o", out], check=True)
            ours.append(mask(read_png(out)))
            theirs.append(mask(read_png(f"{work}/{stem}_v3d_{k + 1}.png")))
        row = [f"t={t:g}: {iou(o, v):.3f}" for t, o, v in zip(TIMES, ours, theirs)]
        moved = [f"{iou(ours[0] ^ o, theirs[0] ^ v):.3f}" if (ours[0] ^ o) | (theirs[0] ^ v)
                 else "none" for o, v in zip(ours[1:], theirs[1:])]
        print(f"{os.path.basename(scene)}: silhouette IoU {', '.join(row)}; moved pixels IoU "
              f"t=0.5: {moved[0]}, t=1: {moved[1]}")


main()

#!/usr/bin/env python3
"""Independent check of animation at --time (docs/animation.md) against view3dscene (Castle Game Engine).

For each scene, renders t = 0, 0.5, 1.0 s with vrmlray and with view3dscene's --screenshot-range
(headless under xvfb-run), and prints the silhouette overlap (intersection over union of the pixels
that are not background) per time, and the overlap of what moved between t = 0 and each time.
Lighting models differ between the two programs; silhouettes (where objects are) do not.

    tools/setup.sh view3dscene xvfb xauth        # the peer, as the benches install theirs
    tools/view3dscene_check.py build/vrmlray WORK_DIR SCENE [SCENE...]
A scene without a Viewpoint gets one in a copy under WORK_DIR (view3dscene frames such files its own
way): the camera vrmlray's framing note names.
"""
import os, re, subprocess, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from silhouette import iou, mask, read_png, view3dscene_cmd  # noqa: E402

TIMES = [0.0, 0.5, 1.0]
W, H = 320, 240


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
        subprocess.run(view3dscene_cmd(scene, W, H, "--screenshot-range", "0", "0.5", "3",
                                       f"{work}/{stem}_v3d_@counter(1).png"),
                       capture_output=True, timeout=120)
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

#!/usr/bin/env python3
"""Side by side with an independent browser: vrmlray and view3dscene on every corpus scene.

Every scene gets the same camera in both programs: a copy of the corpus under WORK_DIR (so that
relative URLs still resolve) where each file starts with a Viewpoint looking down -Z that frames the
scene's bounds (vrmlray info) at 320x240, as vrmlray's own framing does, and, when it has none, a
purple Background (the two programs' default backgrounds differ). Both render the copy; the
silhouettes (pixels unlike the border's commonest colour) are compared by intersection over union.
Lighting models differ between ray tracers and browsers; where objects are does not.

    tools/setup.sh                                        # view3dscene, xvfb, xauth among the rest
    tools/browser_compare.py build/vrmlray WORK_DIR [--corpus DIR] [--only SUBSTRING] [--table F]
                             [--vrmlray-args '--sampler grid --spp 4']
Writes WORK_DIR/results.tsv and a Markdown table (worst first) to --table or standard output;
WORK_DIR/side/ holds vrmlray | view3dscene pairs when ImageMagick's montage is installed.
Runs under one xvfb-run unless DISPLAY is set; each program gets a per-file timeout.
"""
import argparse, gzip, math, os, re, shutil, subprocess, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from silhouette import border_colour, iou, mask, read_png, view3dscene_cmd  # noqa: E402

W, H = 320, 240
FOV = 0.785398  # the spec's default fieldOfView, on the smaller side (240) in both programs
FOLDERS = ("vrml97", "x3dv", "x3d")
SKIP_DIRS = re.compile(r"/(bad|warning|warnings|error|errors)/")
SCENE_EXT = re.compile(r"\.(wrl|wrz|x3dv|x3dvz|x3d|x3dz)(\.gz)?$")
# A file without a Background gets this one in both programs (their defaults differ: black and dark
# grey), far from black, white and the greys of lit and unlit surfaces, which it must stand out from.
BACKGROUND = "0.6 0 0.6"
TIMEOUT = 120  # seconds per program and file: view3dscene takes ~1 s, vrmlray a few at most


def fit_position(lo, hi, width=W, height=H):
    """The camera position looking down -Z whose view holds all eight corners of the box, as
    vrmlray's fit_distance (src/render/camera.cpp) computes it for the same image size."""
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    tan_y = math.tan(FOV / 2)
    tan_x = tan_y * width / height
    d = 0.0
    for i in range(8):
        q = [(hi if i >> k & 1 else lo)[k] - c[k] for k in range(3)]
        forward = -q[2]  # the camera looks along -Z
        d = max(d, abs(q[0]) / tan_x - forward, abs(q[1]) / tan_y - forward)
    return c[0], c[1], c[2] + (d if d > 0 else 10.0)


def read_text(path):
    data = open(path, "rb").read()
    zipped = data[:2] == b"\x1f\x8b"
    return (gzip.decompress(data) if zipped else data).decode("utf-8", "replace"), zipped


def with_viewpoint(text, pos, background):
    """The scene text with a bound-first Viewpoint at `pos` (and the comparison's Background when
    `background`); None when there is nowhere to put them."""
    p = " ".join(f"{v:.6g}" for v in pos)
    # In the file's angle unit, as the position is in its length unit: X3D 19775-1 4.3.6 applies
    # UNIT angle to fieldOfView (view3dscene does not, X_ITE and vrmlray do).
    fov = f"{FOV / angle_unit(text):.6g}"
    if text.lstrip().startswith("<"):
        m = re.search(r"<Scene\b[^>]*?>", text)
        if not m or m.group(0).endswith("/>"):
            return None
        vp = f"<Viewpoint position='{p}' orientation='0 0 1 0' fieldOfView='{fov}'/>"
        if background:
            vp += f"<Background skyColor='{BACKGROUND}'/>"
        return text[:m.end()] + vp + text[m.end():]
    if text.startswith("#VRML V1.0"):
        return None  # one root node; its own camera stays
    lines = text.split("\n")
    k = 1  # after the header and the statements that must precede every node
    while k < len(lines) and (not lines[k].strip() or lines[k].lstrip().startswith("#") or
                              lines[k].split()[0] in ("PROFILE", "COMPONENT", "META", "UNIT")):
        k += 1
    lines.insert(k, f"Viewpoint {{ position {p} orientation 0 0 1 0 fieldOfView {fov} }}" +
                 (f" Background {{ skyColor {BACKGROUND} }}" if background else ""))
    return "\n".join(lines)


def info_of(vrmlray, scene):
    """The scene's bounds (None if it has none) and whether it has a Background node."""
    out = subprocess.run([vrmlray, "info", scene], capture_output=True, text=True,
                         timeout=TIMEOUT).stdout
    has_background = re.search(r"^\s+(Texture)?Background\s+\d+$", out, re.M) is not None
    return bounds_in(out), has_background


def bounds_in(out):
    m = re.search(r"^bounds\s+\((\S+) (\S+) (\S+)\) \.\. \((\S+) (\S+) (\S+)\)", out, re.M)
    if not m:
        return None
    v = [float(x) for x in m.groups()]
    return (v[:3], v[3:]) if all(math.isfinite(x) for x in v) else None


def length_unit(text):
    """Metres per the file's length unit: its UNIT length statement (classic or XML), else 1."""
    m = re.search(r"^\s*UNIT\s+length\s+\S+\s+(\S+)", text, re.M) or re.search(
        r"<unit\b(?=[^>]*category=['\"]length['\"])[^>]*conversionFactor=['\"]([^'\"]+)", text)
    try:
        f = float(m.group(1)) if m else 1.0
    except ValueError:
        f = 1.0
    return f if f > 0 else 1.0


def angle_unit(text):
    """Radians per the file's angle unit: its UNIT angle statement (classic or XML), else 1."""
    m = re.search(r"^\s*UNIT\s+angle\s+\S+\s+(\S+)", text, re.M) or re.search(
        r"<unit\b(?=[^>]*category=['\"]angle['\"])[^>]*conversionFactor=['\"]([^'\"]+)", text)
    try:
        f = float(m.group(1)) if m else 1.0
    except ValueError:
        f = 1.0
    return f if f > 0 else 1.0


def prepare(vrmlray, scene):
    """Rewrites the copy `scene` in place with the framing Viewpoint; a note when it could not."""
    b, has_background = info_of(vrmlray, scene)
    if not b:
        return "no bounds: own camera"
    text, zipped = read_text(scene)
    # vrmlray info gives metres; the Viewpoint goes into the file, whose UNIT length scales it.
    metres = length_unit(text)
    pos = [c / metres for c in fit_position(*b)]
    new = with_viewpoint(text, pos, not has_background)
    if new is None:
        return "no place for a Viewpoint: own camera"
    data = new.encode("utf-8")
    os.chmod(scene, 0o644)
    open(scene, "wb").write(gzip.compress(data) if zipped else data)
    return ""


def run(cmd, what):
    """'' when `cmd` ran and exited 0, else a short note."""
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return f"{what} timed out after {TIMEOUT} s"
    return "" if r.returncode == 0 else f"{what} exit {r.returncode}"


def compare_one(vrmlray, scene, out_dir, stem, extra=()):
    ours, theirs = f"{out_dir}/{stem}_vr.png", f"{out_dir}/{stem}_v3d.png"
    notes = [prepare(vrmlray, scene)]
    notes.append(run([vrmlray, "render", scene, "-W", str(W), "-H", str(H), "-q", "-o", ours,
                      *extra], "vrmlray"))
    notes.append(run(view3dscene_cmd(scene, W, H, "--screenshot", "0", theirs), "view3dscene"))
    if not (os.path.exists(ours) and os.path.exists(theirs)):
        return None, 0, 0, "; ".join(n for n in notes if n) or "no image"
    a, b = read_png(ours), read_png(theirs)
    ma, mb = mask(a, border_colour(a)), mask(b, border_colour(b))
    if shutil.which("montage"):
        subprocess.run(["montage", ours, theirs, "-tile", "2x1", "-geometry", "+2+0",
                        f"{out_dir}/side/{stem}.png"], capture_output=True)
    return iou(ma, mb), len(ma), len(mb), "; ".join(n for n in notes if n)


def scenes_under(corpus, only):
    for folder in FOLDERS:
        for root, _, files in os.walk(os.path.join(corpus, folder)):
            for f in sorted(files):
                path = os.path.join(root, f)
                rel = os.path.relpath(path, corpus)
                if SCENE_EXT.search(f) and not SKIP_DIRS.search("/" + rel) and only in rel:
                    yield rel


def table(rows):
    lines = ["| file | IoU | vrmlray px | view3dscene px | note |", "|---|---|---|---|---|"]
    for rel, v, na, nb, note in sorted(rows, key=lambda r: (r[1] is not None, r[1] or 0.0)):
        score = "-" if v is None else f"{v:.3f}"
        lines.append(f"| `{rel}` | {score} | {na} | {nb} | {note} |")
    done = sorted(r[1] for r in rows if r[1] is not None)
    if done:
        lines.append(f"\n{len(done)} of {len(rows)} scenes compared; median IoU "
                     f"{done[len(done) // 2]:.3f}, {sum(v >= 0.9 for v in done)} at 0.9 or above.")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("vrmlray")
    ap.add_argument("work")
    ap.add_argument("--corpus", default=os.path.join(os.path.dirname(__file__),
                                                     "../../shared/corpus"))
    ap.add_argument("--only", default="", help="compare only paths containing this")
    ap.add_argument("--table", help="write the Markdown table here")
    ap.add_argument("--vrmlray-args", default="", help="more render options, e.g. '--spp 4'")
    args = ap.parse_args()
    if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        # One X server for the whole run instead of one per file.
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 640x480x24", sys.executable,
                               *sys.argv])
    vrmlray = os.path.abspath(args.vrmlray)
    copy, out_dir = os.path.join(args.work, "corpus"), os.path.join(args.work, "images")
    shutil.rmtree(copy, ignore_errors=True)  # a fresh copy: no Viewpoint added twice
    os.makedirs(os.path.join(out_dir, "side"), exist_ok=True)
    rows = []
    with open(os.path.join(args.work, "results.tsv"), "w") as tsv:
        for rel in scenes_under(args.corpus, args.only):
            folder = rel.split(os.sep)[0]
            if not os.path.exists(os.path.join(copy, folder)):
                shutil.copytree(os.path.join(args.corpus, folder), os.path.join(copy, folder))
            stem = rel.replace(os.sep, "__")
            try:
                v, na, nb, note = compare_one(vrmlray, os.path.join(copy, rel), out_dir, stem,
                                              args.vrmlray_args.split())
            except (OSError, subprocess.SubprocessError, ValueError, AssertionError) as e:
                v, na, nb, note = None, 0, 0, f"not compared: {e}"  # one file, not the run
            rows.append((rel, v, na, nb, note))
            tsv.write(f"{rel}\t{'' if v is None else f'{v:.4f}'}\t{na}\t{nb}\t{note}\n")
            tsv.flush()
            print(f"{'-' if v is None else f'{v:.3f}'}  {rel}  {note}", file=sys.stderr)
    text = table(rows)
    if args.table:
        open(args.table, "w").write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":  # tools/conformance.py imports the framing from here
    main()

#!/usr/bin/env python3
"""The conformance suites (../shared/conformance: Xj3D's parser tests, Titania's tests) against two browsers.

Every scene file of the suites is framed once by one camera (a Viewpoint looking down -Z that holds the
scene's bounds, as tools/browser_compare.py frames the corpus) and one purple Background, both put into a copy
of the file. The browsers' pictures of those copies are stored as data (tests/conformance/browsers.tsv: the
camera, and per browser the silhouette mask, the pixels unlike the background); CI never runs a browser. The
test renders the same copies with vrmlray and compares each file's outcome with tests/conformance/expected.tsv.

    tools/conformance.py [--vrmlray build/vrmlray]      # the check (CTest 'conformance'): exit 0, 1, or 77 (skip)
    tools/conformance.py --update                       # rewrite expected.tsv and docs/conformance.md, print counts
    tools/conformance.py --browsers [--xite NODE_MODULES]   # re-take the browsers' pictures (view3dscene, X_ITE)
X_ITE's NODE_MODULES: `PUPPETEER_SKIP_DOWNLOAD=1 npm install x_ite puppeteer-core` in a scratch folder (its
node_modules; Chromium is Debian's `chromium`). Without --xite the stored X_ITE silhouettes are kept.
Options: --suite DIR (default: $VRMLRAY_CONFORMANCE, else ../shared/conformance beside the repository;
VRMLRAY_CONFORMANCE=none skips; VRMLRAY_REQUIRE_CORPUS=1 turns a skip into a failure), --work DIR (scratch
folder, default build/conformance), --only SUBSTRING (--browsers: re-take only those files, keep the rest).

Outcome of a file: `error` (vrmlray exits non-zero or writes no image), `blank` (only the background), or
`renders`. A browser "shows" the file when its silhouette is not empty. A file a browser shows must render and
its silhouette must overlap that browser's (intersection over union, the better of the two browsers) by at
least IOU_MATCH, or expected.tsv must give the reason it does not.
"""
import argparse, base64, concurrent.futures, fnmatch, gzip, os, re, shutil, subprocess, sys, zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_compare import bounds_in, fit_position, length_unit, with_viewpoint  # noqa: E402
from silhouette import border_colour, mask, read_png, view3dscene_cmd  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "tests", "conformance")
DOC = os.path.join(ROOT, "docs", "conformance.md")
# Small pictures keep the whole check to a few minutes on two cores; 160x120 keeps browser_compare's 4:3
# (its fit_position takes the size) and holds a 1-pixel line or point of every browser.
W, H = 160, 120
TIMEOUT = 30  # seconds per program and file: every suite file takes well under 2 s in all three programs
# Silhouettes are compared grown by one pixel each way (DILATE): 1-pixel lines, points and glyph strokes
# drawn a pixel aside by another rasterizer, or in another font, would otherwise hardly overlap at all.
# Below half the union the pictures show different things; the two browsers themselves reach 0.5 on nine
# files in ten that both show (docs/conformance.md, Counts).
IOU_MATCH = 0.5
DILATE = 1
SCENE = re.compile(r"\.(wrl|wrz|x3dv|x3dvz|x3d|x3dz|x3db|xml)(\.gz)?$", re.I)
BROWSERS = ("view3dscene", "x_ite")
DEFAULT_CAMERA = (0.0, 0.0, 10.0)  # the Viewpoint node's default position, for scenes without bounds


# ---- the suite and its framed copy --------------------------------------------------------------------------

def suite_folder(given):
    """The suite folder, or exits 77 (CTest's skip) / 1 with one line saying where it looked."""
    env = os.environ.get("VRMLRAY_CONFORMANCE", "")
    folder = given or env or os.path.normpath(os.path.join(ROOT, "..", "shared", "conformance"))
    why = ("VRMLRAY_CONFORMANCE=none" if folder == "none" else
           None if os.path.isdir(folder) else f"no conformance suites at {folder} (set VRMLRAY_CONFORMANCE=DIR)")
    if why is None:
        return folder
    if os.environ.get("VRMLRAY_REQUIRE_CORPUS") == "1" and folder != "none":
        print(f"FAIL: {why} (VRMLRAY_REQUIRE_CORPUS=1)")
        sys.exit(1)
    print(f"SKIPPED: {why}")
    sys.exit(77)


def scene_files(suite):
    out = []
    for root, _, files in os.walk(suite):
        out += [os.path.relpath(os.path.join(root, f), suite) for f in files if SCENE.search(f)]
    return sorted(out)


def decode(data):
    """(text, how to encode it back) of a scene file: gzip, UTF-16 and UTF-8 byte-order marks kept."""
    zipped = data[:2] == b"\x1f\x8b"
    raw = gzip.decompress(data) if zipped else data
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        text, codec, bom = raw.decode("utf-16"), "utf-16", ""
    else:
        text, codec = raw.decode("utf-8", "replace"), "utf-8"
        bom = "\ufeff" if text.startswith("\ufeff") else ""
        text = text[len(bom):]
    return text, (zipped, codec, bom)


def encode(text, how):
    zipped, codec, bom = how
    data = (bom + text).encode(codec)
    return gzip.compress(data, mtime=0) if zipped else data


def frame_file(path, camera):
    """Puts the comparison's Viewpoint and Background into the copy at `path`; False when the file has no
    place for them (binary, VRML 1.0, an X3D document without <Scene>): it keeps its own camera."""
    data = open(path, "rb").read()
    try:
        text, how = decode(data)
    except (OSError, EOFError, UnicodeError, zlib.error):
        return False
    if "\x00" in text[:200]:
        return False
    new = with_viewpoint(text, camera, True)
    if new is None:
        return False
    os.chmod(path, 0o644)
    open(path, "wb").write(encode(new, how))
    return True


def framed_copy(suite, work, cameras):
    """A copy of the suite under `work` (relative URLs still resolve) with every scene framed by its
    camera; returns the files that kept their own camera."""
    copy = os.path.join(work, "suite")
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(suite, copy, symlinks=True)
    own = set()
    for rel, camera in cameras.items():
        if not frame_file(os.path.join(copy, rel), camera):
            own.add(rel)
    return copy, own


# ---- masks as data ------------------------------------------------------------------------------------------

def pack_mask(pixels):
    """A silhouette as text: W*H bits row-major, zlib, base64 ('-' when empty)."""
    if not pixels:
        return "-"
    bits = bytearray(W * H // 8)
    for x, y in pixels:
        i = y * W + x
        bits[i >> 3] |= 0x80 >> (i & 7)
    return base64.b64encode(zlib.compress(bytes(bits), 9)).decode()


def unpack_mask(text):
    if text in ("", "-"):
        return set()
    bits = zlib.decompress(base64.b64decode(text))
    return {((k * 8 + j) % W, (k * 8 + j) // W) for k, byte in enumerate(bits) if byte
            for j in range(8) if byte & (0x80 >> j)}


def silhouette(png):
    rows = read_png(png)
    assert len(rows) == H and len(rows[0]) == W, (png, len(rows[0]), len(rows))
    return mask(rows, border_colour(rows))


def read_tsv(path):
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8") as f:
        return [line.rstrip("\n").split("\t") for line in f if line.strip() and not line.startswith("#")]


def read_browsers():
    """{file: (camera, {browser: mask or None (no picture)}, note)} from browsers.tsv."""
    out = {}
    for row in read_tsv(os.path.join(DATA, "browsers.tsv"))[1:]:
        rel, camera, v3d, xite, note = (row + [""] * 5)[:5]
        cam = tuple(float(v) for v in camera.split()) if camera not in ("", "own") else None
        out[rel] = (cam, {b: None if m == "" else unpack_mask(m) for b, m in zip(BROWSERS, (v3d, xite))},
                    note)
    return out


# ---- vrmlray ------------------------------------------------------------------------------------------------

def run(cmd, cwd=None):
    """(exit code, stderr); exit None on a timeout."""
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=TIMEOUT, cwd=cwd)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {TIMEOUT} s"
    return r.returncode, r.stderr


def parallel(fn, items):
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        return list(pool.map(fn, items))


def camera_of(vrmlray, suite, rel, scratch):
    """The framing camera position from the scene's bounds (vrmlray info; when vrmlray cannot read the
    file, from Castle's tovrmlx3d rewrite of it, when that exists), else the Viewpoint default."""
    path = os.path.join(suite, rel)
    out = subprocess.run([vrmlray, "info", path], capture_output=True, text=True, errors="replace",
                         timeout=TIMEOUT).stdout
    b = bounds_in(out)
    if b is None and shutil.which("tovrmlx3d"):
        # Written beside the original's copy so that its Inlines still resolve.
        conv = os.path.join(scratch, rel) + ".tovrmlx3d.x3dv"
        try:
            r = subprocess.run(["tovrmlx3d", "--no-x3d-extensions", path], capture_output=True,
                               timeout=TIMEOUT)
            if r.returncode == 0 and r.stdout:
                open(conv, "wb").write(r.stdout)
                b = bounds_in(subprocess.run([vrmlray, "info", conv], capture_output=True, text=True,
                                             errors="replace", timeout=TIMEOUT).stdout)
        except subprocess.TimeoutExpired:
            pass
    if b is None:
        return DEFAULT_CAMERA
    metres = length_unit(decode(open(path, "rb").read())[0])
    return tuple(round(c / metres, 6) for c in fit_position(*b, W, H))


def render_all(vrmlray, copy, files, out_dir):
    """{file: (exit code or None, stderr, silhouette or None)} for every file, rendered at W x H."""
    os.makedirs(out_dir, exist_ok=True)

    def one(rel):
        png = os.path.join(out_dir, rel.replace(os.sep, "__") + ".png")
        if os.path.exists(png):
            os.remove(png)
        code, err = run([vrmlray, "render", rel, "-W", str(W), "-H", str(H), "--timeout", str(TIMEOUT),
                         "-o", png], cwd=copy)
        shape = silhouette(png) if code == 0 and os.path.exists(png) else None
        return rel, (code, err, shape)

    return dict(parallel(one, files))


# ---- outcomes and reasons -----------------------------------------------------------------------------------

def outcome_of(code, shape):
    return "error" if code != 0 or shape is None else "blank" if not shape else "renders"


def grown_rows(pixels):
    """The silhouette as one integer a row (bit x = column x), grown by DILATE pixels each way."""
    rows = [0] * H
    for x, y in pixels:
        rows[y] |= 1 << x
    full = (1 << W) - 1
    for _ in range(DILATE):
        wide = [(r | r << 1 | r >> 1) & full for r in rows]
        rows = [wide[y] | (wide[y - 1] if y else 0) | (wide[y + 1] if y + 1 < H else 0) for y in range(H)]
    return rows


def tolerant_iou(a, b):
    """Intersection over union of two silhouettes grown by DILATE pixels (1.0 when both are empty)."""
    ra, rb = grown_rows(a), grown_rows(b)
    union = sum(bin(x | y).count("1") for x, y in zip(ra, rb))
    return sum(bin(x & y).count("1") for x, y in zip(ra, rb)) / union if union else 1.0


def best_iou(shape, browser_masks):
    """The better overlap with a browser that shows the file; None when none shows it."""
    shown = [m for m in browser_masks.values() if m]
    if not shown:
        return None
    return max(tolerant_iou(shape or set(), m) for m in shown)


def broken_on_purpose(rel):
    for pattern, reason in read_tsv(os.path.join(DATA, "broken.tsv")):
        if fnmatch.fnmatch(rel, pattern):
            return reason
    return None


def examined(rel):
    """The reason a person found on looking at the file and the three pictures (examined.tsv), if any."""
    for pattern, reason in read_tsv(os.path.join(DATA, "examined.tsv")):
        if fnmatch.fnmatch(rel, pattern):
            return reason
    return None


WARNING = re.compile(r"^(\S.*?):(\d+:\d+:)? (warning|error): (.*)$")
CAUSES = [  # (pattern on a warning's message, cause); the first that matches names the cause, with its names
    (re.compile(r"unknown node type '([^']+)'"), "unknown node types"),
    (re.compile(r"^(\w+) is not a geometry vrmlray renders"), "not drawn"),
    (re.compile(r"^(\w+) has no area and is not rendered"), "not drawn"),
    (re.compile(r"EXTERNPROTO (\S+) not resolved"), "EXTERNPROTO not found"),
    (re.compile(r"(\w+): no texture image could be loaded"), "texture file missing"),
    (re.compile(r"(Inline)\b.*not found"), "file missing"),
    (re.compile(r"(Script)\b.* is not run"), "not run"),
    (re.compile(r"Script(?: '[^']*')?: .*?\b(\w*Error|ran longer)"), "script stopped"),
    (re.compile(r"Script(?: '[^']*')?: (Browser\.\w+|cannot set|createVrmlFromString|createX3DFromString)"),
     "script call ignored"),
]


def causes_in(stderr):
    """The causes the warnings name, each with the names it was met with: ['unknown node types: A, B', ...]."""
    found = {}
    for line in stderr.splitlines():
        m = WARNING.match(line)
        if not m or m.group(3) != "warning":
            continue
        for pattern, cause in CAUSES:
            c = pattern.search(m.group(4))
            if c:
                names = found.setdefault(cause, [])
                if c.group(1) not in names:
                    names.append(c.group(1))
                break
    return [f"{cause}: {', '.join(names)}" for cause, names in found.items()]


def first_error(stderr):
    for line in stderr.splitlines():
        m = WARNING.match(line)
        if m and m.group(3) == "error":
            # Without its line:col, which are the framed copy's (one line more in a classic file).
            return m.group(4)[:160]
    return stderr.strip().splitlines()[-1][:160] if stderr.strip() else "no message"


# Nodes of X3D components a file may use that are drawn by few programs: named in a reason when no
# warning explains a difference (a fact about the file, not a claim about vrmlray).
COMPONENT_NODES = re.compile(
    r"\b(LayerSet|LayoutLayer|LayoutGroup|Layer|Viewport|Geo(?:Coordinate|ElevationGrid|Location|LOD|Origin|"
    r"Transform|Viewpoint|PositionInterpolator)|Nurbs[A-Z]\w*|ClipPlane|LocalFog|MatrixTransform|"
    r"(?:Arc|ArcClose|Circle|Disk|Polyline|Polypoint|Rectangle|TriangleSet)2D|ParticleSystem|CAD(?:Assembly|"
    r"Face|Layer|Part)|MovieTexture|ComposedShader|TimeSensor|Script)\b")


def component_hint(text):
    names = sorted(set(COMPONENT_NODES.findall(text)))
    if len(names) > 6:  # a file that lists every node type (Titania's NodeIndex): a few, and the count
        names = names[:6] + [f"... ({len(names)} in all)"]
    return "uses: " + ", ".join(names) if names else ""


def reason_for(rel, text, outcome, stderr, sizes=""):
    """Why the file does not render what a browser shows, from what the program said and the file."""
    purpose = broken_on_purpose(rel)
    if purpose:
        return purpose
    if outcome == "error":
        return "error: " + first_error(stderr)
    causes = causes_in(stderr)
    if not causes and examined(rel):
        return examined(rel) + (f" ({sizes})" if sizes else "")
    if not causes:
        # No message explains it: what the file uses, and the silhouettes' sizes, for a person to look at.
        causes.append((component_hint(text) or "unexplained") + (f" ({sizes})" if sizes else ""))
    return "; ".join(causes)


# ---- the browsers' pictures (--browsers) --------------------------------------------------------------------

def view3dscene_pictures(copy, files, out_dir):
    """{file: png path or None} from view3dscene (Castle), one process a file, under the one X server."""
    def one(rel):
        png = os.path.join(out_dir, rel.replace(os.sep, "__") + ".v3d.png")
        code, _ = run(view3dscene_cmd(os.path.join(copy, rel), W, H, "--screenshot", "0", png))
        return rel, png if code == 0 and os.path.exists(png) else None
    return dict(parallel(one, files))


def xite_pictures(modules, copy, files, out_dir):
    """{file: png path or None} from X_ITE in headless Chromium (tools/xite_screens.mjs)."""
    sub = os.path.join(out_dir, "xite")
    os.makedirs(sub, exist_ok=True)
    listing = os.path.join(out_dir, "xite_list.txt")
    open(listing, "w").write("\n".join(files) + "\n")
    r = subprocess.run(["node", os.path.join(ROOT, "tools", "xite_screens.mjs"), modules, copy, listing, sub,
                        str(W), str(H), str(TIMEOUT)], capture_output=True, text=True, errors="replace",
                       timeout=TIMEOUT * len(files) + 120)
    status = dict(line.split("\t", 1) for line in r.stdout.splitlines() if "\t" in line)
    if r.returncode != 0:
        print(f"X_ITE driver exit {r.returncode}: {r.stderr.strip()[-400:]}", file=sys.stderr)
    return {rel: os.path.join(sub, rel.replace(os.sep, "__") + ".png") if status.get(rel) == "ok" else None
            for rel in files}


def mask_cell(png):
    """A browser's cell in browsers.tsv: '' for no picture, else its packed silhouette."""
    if png is None:
        return ""
    try:
        return pack_mask(silhouette(png))
    except (AssertionError, OSError, ValueError, zlib.error):
        return ""


def take_browser_pictures(args, vrmlray, suite, files):
    work = os.path.join(args.work, "browsers")
    shutil.rmtree(work, ignore_errors=True)
    scratch = os.path.join(work, "scratch")  # a plain copy: tovrmlx3d's rewrites sit beside the originals
    shutil.copytree(suite, scratch, symlinks=True)
    cameras = dict(parallel(lambda rel: (rel, camera_of(vrmlray, scratch, rel, scratch)), files))
    copy, own = framed_copy(suite, work, cameras)
    out_dir = os.path.join(work, "images")
    os.makedirs(out_dir, exist_ok=True)
    pictures = {"view3dscene": view3dscene_pictures(copy, files, out_dir)}
    if args.xite:
        pictures["x_ite"] = xite_pictures(os.path.abspath(args.xite), copy, files, out_dir)
    old = {row[0]: row for row in read_tsv(os.path.join(DATA, "browsers.tsv"))[1:]}
    for rel in files:
        camera = "own" if rel in own else " ".join(f"{v:.6g}" for v in cameras[rel])
        cells = [mask_cell(pictures[b][rel]) if b in pictures else (old.get(rel, [""] * 5) + [""] * 5)[2 + i]
                 for i, b in enumerate(BROWSERS)]
        note = "no bounds: the default Viewpoint" if cameras[rel] == DEFAULT_CAMERA else ""
        old[rel] = [rel, camera, *cells, note]
    with open(os.path.join(DATA, "browsers.tsv"), "w", encoding="utf-8") as f:
        f.write("# written by tools/conformance.py --browsers; silhouettes as tools/conformance.py packs them\n")
        f.write("file\tcamera\tview3dscene\tx_ite\tnote\n")
        for rel in sorted(old):
            f.write("\t".join(old[rel]) + "\n")
    shown = {b: sum(1 for rel in files if (unpack_mask(old[rel][2 + i]) if old[rel][2 + i] else None))
             for i, b in enumerate(BROWSERS)}
    print(f"{len(files)} files: " + ", ".join(f"{b} shows {n}" for b, n in shown.items()))


# ---- the check and the expected table -----------------------------------------------------------------------

def measure(vrmlray, suite, files, work):
    """{file: (outcome, best IoU or None, reason or '')} of vrmlray on the framed copies."""
    browsers = read_browsers()
    cameras = {rel: (browsers[rel][0] or DEFAULT_CAMERA) if rel in browsers else DEFAULT_CAMERA
               for rel in files}
    copy, _ = framed_copy(suite, work, cameras)
    rendered = render_all(vrmlray, copy, files, os.path.join(work, "images"))
    out = {}
    for rel in files:
        code, err, shape = rendered[rel]
        outcome = outcome_of(code, shape)
        masks = browsers[rel][1] if rel in browsers else {}
        best = best_iou(shape, masks)
        ok = best is None or (outcome == "renders" and best >= IOU_MATCH)
        # Errors and blanks get their cause even when no browser shows the file: the counts by cause.
        why = not ok or outcome != "renders"
        text = decode(open(os.path.join(suite, rel), "rb").read())[0] if why else ""
        sizes = ", ".join([f"vrmlray {len(shape or ())} px"] +
                          [f"{b} {len(m)} px" for b, m in masks.items() if m is not None])
        out[rel] = (outcome, best, reason_for(rel, text, outcome, err, sizes) if why else "")
    return out, browsers


def match_word(outcome, best):
    return "-" if best is None else "yes" if outcome == "renders" and best >= IOU_MATCH else "no"


def cause_keys(reason):
    """The causes a reason names, one a node type or file kind, names of files and values taken out:
    the rows of the count by cause (a file counts under each of its causes)."""
    if reason.startswith(("error: ", "broken on purpose", "X3D binary")):
        return [re.sub(r"'[^']*'", "'…'", reason)[:100]]
    # A person's reason (examined.tsv) counts under its cause alone; its detail is for the file's row.
    for _, looked in read_tsv(os.path.join(DATA, "examined.tsv")):
        cause = looked.partition(": ")[0]
        if reason.startswith(cause + ": "):
            return [f"examined: {cause}"]
    keys = []
    for part in reason.split("; "):
        cause, _, names = re.sub(r" \(vrmlray \d+ px.*\)$", "", part).partition(": ")
        keys += [f"{cause}: {n}" for n in names.split(", ")] if names else [cause]
    return keys


def write_expected(results):
    with open(os.path.join(DATA, "expected.tsv"), "w", encoding="utf-8") as f:
        f.write("# written by tools/conformance.py --update: vrmlray's outcome on each conformance file, the best\n"
                f"# silhouette IoU against a browser that shows it ('-': none does), whether that is >= {IOU_MATCH},\n"
                "# and the reason a file a browser shows does not render it (or the cause of an error or blank)\n")
        f.write("file\toutcome\tiou\tmatch\treason\n")
        for rel, (outcome, best, reason) in sorted(results.items()):
            iou_text = "-" if best is None else f"{best:.3f}"
            f.write(f"{rel}\t{outcome}\t{iou_text}\t{match_word(outcome, best)}\t{reason}\n")


def counts(results, browsers):
    """The summary lines: outcomes, and those a browser shows, by cause."""
    lines, missing = [], {}
    for kind in ("renders", "error", "blank"):
        rels = [r for r, v in results.items() if v[0] == kind]
        shown = [r for r in rels if results[r][1] is not None]
        lines.append(f"{kind}: {len(rels)} files, {len(shown)} of them shown by a browser")
    for rel, (outcome, best, reason) in results.items():
        if best is not None and match_word(outcome, best) == "no":
            for key in cause_keys(reason):
                missing.setdefault(key, []).append(rel)
    n_shown = {b: sum(1 for rel in results if rel in browsers and browsers[rel][1].get(b)) for b in BROWSERS}
    n_taken = {b: sum(1 for rel in results if rel in browsers and browsers[rel][1].get(b) is not None)
               for b in BROWSERS}
    lines.append("browsers: " + ", ".join(f"{b} shows {n_shown[b]} of the {n_taken[b]} it drew" for b in BROWSERS))
    # The threshold's yardstick: how often the two browsers agree with each other by the same measure.
    both = [tolerant_iou(*(browsers[rel][1][b] for b in BROWSERS)) for rel in results
            if rel in browsers and all(browsers[rel][1].get(b) for b in BROWSERS)]
    if both:
        agree = sum(v >= IOU_MATCH for v in both)
        lines.append(f"the two browsers' silhouettes overlap by IoU >= {IOU_MATCH} on {agree} of the {len(both)}"
                     f" files both show (median {sorted(both)[len(both) // 2]:.3f})")
    lines.append(f"a browser shows it, vrmlray does not (error, blank, or IoU < {IOU_MATCH}): "
                 f"{len({rel for rels in missing.values() for rel in rels})} files")
    return lines, missing


def write_doc(results, browsers, summary, missing):
    out = ["# Conformance suites against two browsers", "",
           "Every scene file of the conformance suites beside the repository (`../shared/conformance/`: Xj3D's",
           "parser tests and Titania's tests) is framed by one camera and one purple Background put into a copy, and",
           f"drawn at {W}x{H} by view3dscene (Castle 4.2, Debian) and X_ITE (npm `x_ite`, headless Chromium), whose",
           "silhouettes are stored in `tests/conformance/browsers.tsv`, and by vrmlray. The CTest `conformance`",
           "compares vrmlray's outcome on each file with `tests/conformance/expected.tsv`; `tools/conformance.py",
           "--update` rewrites that table and this page, `tools/conformance.py --browsers --xite DIR` the browsers'",
           f"data. A browser *shows* a file when its silhouette is not empty; vrmlray matches it when the",
           f"silhouettes' intersection over union with the better browser is at least {IOU_MATCH}. The camera is",
           "written in the file's units: its position in the UNIT length, its fieldOfView in the UNIT angle",
           "(X3D 19775-1 4.3.6; view3dscene reads fieldOfView in radians whatever the unit, so its stored pictures",
           "of such files, taken when the harness wrote radians, show the intended camera).", "",
           "X_ITE runs from a folder of npm packages: `PUPPETEER_SKIP_DOWNLOAD=1 npm install x_ite puppeteer-core`",
           "(Chromium is Debian's). The reasons come from vrmlray's own warnings and errors, from",
           "`tests/conformance/broken.tsv` (the files the suites' README names as broken on purpose), from",
           "`tests/conformance/examined.tsv` (what a person found on looking at a file no warning explains, counted",
           "as \"examined\"), and, when nothing else explains a difference, from the X3D component nodes the file uses.",
           "",
           "## Counts", ""] + [f"- {line}" for line in summary] + ["", "## By cause", "",
           "Files a browser shows that vrmlray does not render, by cause (a file counts under each of its causes).",
           "", "| cause | files |", "|---|---|"]
    for key, rels in sorted(missing.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        out.append(f"| {key.replace('|', '/')} | {len(rels)} |")
    out += ["", "## Every file a browser shows that vrmlray does not render", "",
            "| file | vrmlray | IoU | view3dscene px | X_ITE px | reason |", "|---|---|---|---|---|---|"]
    for rel, (outcome, best, reason) in sorted(results.items()):
        if best is None or match_word(outcome, best) == "yes":
            continue
        px = [browsers[rel][1].get(b) for b in BROWSERS]
        cells = ["-" if m is None else str(len(m)) for m in px]
        out.append(f"| `{rel}` | {outcome} | {best:.2f} | {cells[0]} | {cells[1]} | {reason.replace('|', '/')} |")
    open(DOC, "w", encoding="utf-8").write("\n".join(out) + "\n")


def compare_with_expected(results):
    """The lines of the failures: outcome or match unlike the table, or a shown file left without reason."""
    expected = {row[0]: row for row in read_tsv(os.path.join(DATA, "expected.tsv"))[1:]}
    fails = []
    for rel, (outcome, best, _) in sorted(results.items()):
        row = expected.get(rel)
        if row is None:
            fails.append(f"{rel}: not in expected.tsv (new file?)")
            continue
        _, want, _, want_match, reason = (row + [""] * 5)[:5]
        got_match = match_word(outcome, best)
        if (outcome, got_match) != (want, want_match):
            fails.append(f"{rel}: {outcome}, IoU {'-' if best is None else f'{best:.3f}'} (match {got_match}); "
                         f"the table says {want} (match {want_match})")
        elif want_match == "no" and not reason.strip():
            fails.append(f"{rel}: a browser shows it and vrmlray does not, with no reason in the table")
    fails += [f"{rel}: in expected.tsv but not in the suite" for rel in sorted(set(expected) - set(results))]
    return fails


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vrmlray", default=os.path.join(ROOT, "build", "vrmlray"))
    ap.add_argument("--suite", help="the conformance folder (default ../shared/conformance)")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "conformance"))
    ap.add_argument("--update", action="store_true", help="rewrite expected.tsv and docs/conformance.md")
    ap.add_argument("--browsers", action="store_true", help="re-take the browsers' pictures")
    ap.add_argument("--xite", help="node_modules holding x_ite and puppeteer-core (--browsers)")
    ap.add_argument("--only", default="", help="--browsers: only files whose path contains this")
    args = ap.parse_args()
    if args.browsers and not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        # One X server for all of view3dscene's pictures instead of one a file.
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 640x480x24", sys.executable, *sys.argv])
    suite = suite_folder(args.suite)
    vrmlray = os.path.abspath(args.vrmlray)
    files = scene_files(suite)
    os.makedirs(args.work, exist_ok=True)
    if args.browsers:
        take_browser_pictures(args, vrmlray, suite, [f for f in files if args.only in f])
        return 0
    results, browsers = measure(vrmlray, suite, files, os.path.join(args.work, "check"))
    summary, missing = counts(results, browsers)
    if args.update:
        write_expected(results)
        write_doc(results, browsers, summary, missing)
        print("\n".join(summary))
        for key, rels in sorted(missing.items(), key=lambda kv: -len(kv[1])):
            print(f"  {len(rels):4d}  {key}")
        return 0
    fails = compare_with_expected(results)
    for line in fails:
        print("FAIL: " + line)
    failed = sum(1 for line in fails if not line.endswith("but not in the suite"))
    print(f"conformance: {len(files) - failed} passed, {failed} failed" + (
        f", {len(fails) - failed} rows of expected.tsv name no file of the suite" if len(fails) > failed else "") +
        ("; a change that is right: tools/conformance.py --update, and commit the tables" if fails else ""))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())

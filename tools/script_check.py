#!/usr/bin/env python3
"""Scripts against X_ITE: every corpus and conformance file with a Script, at t = 0 and at a later time.

X_ITE (npm `x_ite` in Debian's headless Chromium) runs the files' ECMAScript as a browser does. Each file is
framed as tools/conformance.py frames it (the conformance files keep the camera stored in
tests/conformance/browsers.tsv), and X_ITE's clock is made virtual (tools/xite_screens.mjs TIMES) so that
its pictures are of the world TIMES seconds after the load, as vrmlray's --time counts them. X_ITE's
silhouettes are stored as data (tests/scripts/xite.tsv); CI never runs a browser. vrmlray renders the same
framed copies at the same times; a file matches at a time when the silhouettes' overlap (intersection over
union, grown by a pixel as tools/conformance.py grows them) is at least IOU_MATCH.

    tools/script_check.py --browser --xite NODE_MODULES   # re-take X_ITE's pictures (a few minutes)
    tools/script_check.py --update                        # rewrite tests/scripts/expected.tsv, docs/scripts_xite.md
    tools/script_check.py                                 # the check (CTest 'script_xite'): exit 0, 1 or 77

A file that does not match needs a reason: vrmlray's own warnings (a Script error, an API it does not
have), tests/scripts/examined.tsv (what a person found on looking), or the nodes the file uses.
"""
import argparse, os, re, shutil, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import conformance as conf  # noqa: E402

ROOT = conf.ROOT
DATA = os.path.join(ROOT, "tests", "scripts")
DOC = os.path.join(ROOT, "docs", "scripts_xite.md")
# t = 0 is what initialize() builds; 1.5 s is a later time at which a Script between a TimeSensor and a
# Transform has moved something in most of the files that have one (cycleIntervals of 1-10 s).
TIMES = (0.0, 1.5)
# The bar for "renders what X_ITE shows": the two browsers themselves overlap by a median 0.985 on
# the conformance files (docs/conformance.md), so 0.95 leaves room for rasterisers, not for other shapes.
IOU_MATCH = 0.95
SCRIPT = re.compile(r"\bScript\b")


def script_files(suites):
    """[(key, suite folder, path in the suite)] of every scene file that names a Script."""
    out = []
    for name, folder in suites.items():
        for rel in conf.scene_files(folder):
            try:
                text = conf.decode(open(os.path.join(folder, rel), "rb").read())[0]
            except (OSError, EOFError, UnicodeError, conf.zlib.error):
                continue
            if SCRIPT.search(text):
                out.append((f"{name}/{rel}", folder, rel))
    return out


def suites_beside():
    """{name: folder} of the corpus and the conformance suites; exits 77 (skip) or 1 as conformance does."""
    shared = os.path.normpath(os.path.join(ROOT, "..", "shared"))
    corpus = os.environ.get("VRMLRAY_CORPUS") or os.path.join(shared, "corpus")
    suites = {"corpus": corpus, "conformance": conf.suite_folder(None)}
    missing = [f for f in suites.values() if not os.path.isdir(f)]
    if missing:
        conf.suite_folder(missing[0])  # one line saying where it looked; exits
    return suites


def read_stored():
    """{(key, time): (camera, mask or None)} from xite.tsv."""
    out = {}
    for key, time, camera, cell in ((row + [""] * 4)[:4] for row in conf.read_tsv(os.path.join(DATA, "xite.tsv"))[1:]):
        cam = tuple(float(v) for v in camera.split()) if camera not in ("", "own") else None
        out[(key, float(time))] = (cam, None if cell == "" else conf.unpack_mask(cell))
    return out


def cameras_for(vrmlray, files, work):
    """{key: camera}: the conformance table's own cameras, else framed from vrmlray's bounds."""
    stored = conf.read_browsers()
    out = {}
    for key, folder, rel in files:
        if key.startswith("conformance/") and rel in stored and stored[rel][0]:
            out[key] = stored[rel][0]
        else:  # camera_of may write a tovrmlx3d rewrite under work
            os.makedirs(os.path.dirname(os.path.join(work, rel)), exist_ok=True)
            out[key] = conf.camera_of(vrmlray, folder, rel, work)
    return out


def framed_copies(files, cameras, work):
    """{key: (copy folder, path in it)}: each suite copied once, its Script files framed."""
    out = {}
    for folder in sorted({f for _, f, _ in files}):
        mine = [(key, rel) for key, f, rel in files if f == folder]
        copy, _ = conf.framed_copy(folder, os.path.join(work, os.path.basename(folder)),
                                   {rel: cameras[key] for key, rel in mine})
        out.update({key: (copy, rel) for key, rel in mine})
    return out


def take_xite(modules, vrmlray, files, work):
    cameras = cameras_for(vrmlray, files, work)
    copies = framed_copies(files, cameras, work)
    rows = []
    for copy in sorted({c for c, _ in copies.values()}):
        keys = [k for k, (c, _) in copies.items() if c == copy]
        listing, out_dir = os.path.join(work, "list.txt"), os.path.join(work, "xite")
        os.makedirs(out_dir, exist_ok=True)
        open(listing, "w").write("\n".join(copies[k][1] for k in keys) + "\n")
        r = subprocess.run(["node", os.path.join(ROOT, "tools", "xite_screens.mjs"), modules, copy, listing,
                            out_dir, str(conf.W), str(conf.H), str(conf.TIMEOUT), ",".join(f"{t:g}" for t in TIMES)],
                           capture_output=True, text=True, errors="replace",
                           timeout=conf.TIMEOUT * len(keys) * 2 + 120)
        status = dict(line.split("\t", 1) for line in r.stdout.splitlines() if "\t" in line)
        for k in keys:
            rel = copies[k][1]
            for t in TIMES:
                png = os.path.join(out_dir, rel.replace(os.sep, "__") + f"@{t:g}.png")
                cell = conf.mask_cell(png if status.get(rel) == "ok" and os.path.exists(png) else None)
                rows.append([k, f"{t:g}", " ".join(f"{v:.6g}" for v in cameras[k]), cell])
    os.makedirs(DATA, exist_ok=True)
    with open(os.path.join(DATA, "xite.tsv"), "w", encoding="utf-8") as f:
        f.write("# written by tools/script_check.py --browser: X_ITE's silhouette of each Script file at each time\n")
        f.write("file\ttime\tcamera\tx_ite\n")
        for row in sorted(rows):
            f.write("\t".join(row) + "\n")
    shown = sum(1 for row in rows if row[3] not in ("", "-"))
    print(f"{len(files)} files at {len(TIMES)} times: X_ITE shows {shown} of {len(rows)} pictures")


def render(vrmlray, copy, rel, t, out_dir):
    png = os.path.join(out_dir, rel.replace(os.sep, "__") + f"@{t:g}.png")
    code, err = conf.run([vrmlray, "render", rel, "-W", str(conf.W), "-H", str(conf.H), "--time", f"{t:g}",
                          "--timeout", str(conf.TIMEOUT), "-o", png], cwd=copy)
    shape = conf.silhouette(png) if code == 0 and os.path.exists(png) else None
    return conf.outcome_of(code, shape), shape, err


def examined(key):
    for pattern, reason in conf.read_tsv(os.path.join(DATA, "examined.tsv")):
        if conf.fnmatch.fnmatch(key, pattern):
            return reason
    return None


def measure(vrmlray, files, work):
    """{(key, time): (outcome, IoU or None when X_ITE shows nothing, reason)} of vrmlray on the copies."""
    stored = read_stored()
    cameras = {key: stored.get((key, TIMES[0]), (None, None))[0] or conf.DEFAULT_CAMERA for key, _, _ in files}
    copies = framed_copies(files, cameras, work)
    out_dir = os.path.join(work, "images")
    os.makedirs(out_dir, exist_ok=True)
    jobs = [(key, t) for key, _, _ in files for t in TIMES]

    def one(job):
        key, t = job
        copy, rel = copies[key]
        outcome, shape, err = render(vrmlray, copy, rel, t, out_dir)
        xite = stored.get(job, (None, None))[1]
        iou = conf.tolerant_iou(shape or set(), xite) if xite else None
        if iou is None or (outcome == "renders" and iou >= IOU_MATCH):
            return job, (outcome, iou, "")
        text = conf.decode(open(os.path.join(copy, rel), "rb").read())[0]
        sizes = f"vrmlray {len(shape or ())} px, x_ite {len(xite)} px"
        why = examined(key) or conf.reason_for(rel, text, outcome, err, sizes)
        return job, (outcome, iou, why)

    return dict(conf.parallel(one, jobs))


def match_word(outcome, iou):
    return "-" if iou is None else "yes" if outcome == "renders" and iou >= IOU_MATCH else "no"


def write_tables(results, files):
    with open(os.path.join(DATA, "expected.tsv"), "w", encoding="utf-8") as f:
        f.write("# written by tools/script_check.py --update: vrmlray against X_ITE on each Script file and time\n")
        f.write("file\ttime\toutcome\tiou\tmatch\treason\n")
        for (key, t), (outcome, iou, why) in sorted(results.items()):
            f.write(f"{key}\t{t:g}\t{outcome}\t{'-' if iou is None else f'{iou:.3f}'}\t"
                    f"{match_word(outcome, iou)}\t{why}\n")
    shown = [(k, v) for k, v in results.items() if v[1] is not None]
    good = [k for k, v in shown if match_word(v[0], v[1]) == "yes"]
    summary = [f"{len(files)} files with a Script, {len(TIMES)} times each ({', '.join(f'{t:g} s' for t in TIMES)})",
               f"X_ITE shows {len(shown)} of the {len(results)} pictures; vrmlray matches {len(good)} of them "
               f"(IoU >= {IOU_MATCH}), {len(shown) - len(good)} with a reason below"]
    for t in TIMES:
        st = [k for k, _ in shown if k[1] == t]
        summary.append(f"at {t:g} s: {sum(1 for k in good if k[1] == t)} of {len(st)} match")
    out = ["# Scripts against X_ITE", "",
           "Every file of `../shared/corpus` and `../shared/conformance` that has a Script, framed as",
           "[conformance.md](conformance.md) frames it, drawn at 160x120 by X_ITE 15 (npm `x_ite`, headless",
           "Chromium) with its clock made virtual, so that its picture is of the world at the same seconds after",
           "the load as vrmlray's `--time` (tools/xite_screens.mjs). X_ITE's silhouettes are stored in",
           "`tests/scripts/xite.tsv`; the CTest `script_xite` renders the files with vrmlray and compares them with",
           "`tests/scripts/expected.tsv`. `tools/script_check.py --update` rewrites that table and this page,",
           "`tools/script_check.py --browser --xite NODE_MODULES` X_ITE's pictures. A file matches at a time when",
           f"the silhouettes' intersection over union (each grown by a pixel) is at least {IOU_MATCH}.", "",
           "## Counts", ""] + [f"- {line}" for line in summary] + [
           "", "## Every picture X_ITE shows that vrmlray does not match", "",
           "| file | time | vrmlray | IoU | reason |", "|---|---|---|---|---|"]
    for (key, t), (outcome, iou, why) in sorted(results.items()):
        if match_word(outcome, iou) == "no":
            out.append(f"| `{key}` | {t:g} | {outcome} | {iou:.2f} | {why.replace('|', '/')} |")
    open(DOC, "w", encoding="utf-8").write("\n".join(out) + "\n")
    return summary


def check(results):
    expected = {(row[0], float(row[1])): row for row in conf.read_tsv(os.path.join(DATA, "expected.tsv"))[1:]}
    fails = []
    for job, (outcome, iou, _) in sorted(results.items()):
        row = expected.get(job)
        if row is None:
            fails.append(f"{job[0]} at {job[1]:g} s: not in expected.tsv")
            continue
        want, want_match, reason = row[2], row[4], (row + [""] * 6)[5]
        got = match_word(outcome, iou)
        if (outcome, got) != (want, want_match):
            fails.append(f"{job[0]} at {job[1]:g} s: {outcome}, IoU {'-' if iou is None else f'{iou:.3f}'} "
                         f"(match {got}); the table says {want} (match {want_match})")
        elif want_match == "no" and not reason.strip():
            fails.append(f"{job[0]} at {job[1]:g} s: X_ITE shows it and vrmlray does not, with no reason")
    return fails


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vrmlray", default=os.path.join(ROOT, "build", "vrmlray"))
    ap.add_argument("--work", help="scratch folder (default: a temporary one)")
    ap.add_argument("--update", action="store_true", help="rewrite expected.tsv and docs/scripts_xite.md")
    ap.add_argument("--browser", action="store_true", help="re-take X_ITE's pictures (needs --xite)")
    ap.add_argument("--xite", help="node_modules holding x_ite and puppeteer-core")
    args = ap.parse_args()
    suites = suites_beside()
    vrmlray = os.path.abspath(args.vrmlray)
    work = args.work or tempfile.mkdtemp(prefix="script_check.")
    try:
        files = script_files(suites)
        if args.browser:
            if not args.xite:
                ap.error("--browser needs --xite NODE_MODULES")
            take_xite(os.path.abspath(args.xite), vrmlray, files, work)
            return 0
        results = measure(vrmlray, files, work)
        if args.update:
            print("\n".join(write_tables(results, files)))
            return 0
        fails = check(results)
        for line in fails:
            print("FAIL: " + line)
        print(f"script_xite: {len(results) - len(fails)} passed, {len(fails)} failed" +
              ("; a change that is right: tools/script_check.py --update, and commit the tables" if fails else ""))
        return 1 if fails else 0
    finally:
        if not args.work:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

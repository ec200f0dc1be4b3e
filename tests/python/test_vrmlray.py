"""The Python module (python/vrmlray.cpp) against the command line it wraps.

Run by CTest (test `python_module`) with PYTHONPATH at build/python and VRMLRAY_BINARY naming the
vrmlray program; VRMLRAY_CORPUS as in tests/unit/corpus.h."""
import os
import pathlib
import re
import shutil
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import vrmlray

SOURCE = pathlib.Path(__file__).resolve().parents[2]
SEEDS = SOURCE / "scenes" / "seeds"
SPHERE = SEEDS / "001_sphere.wrl"
BINARY = os.environ.get("VRMLRAY_BINARY", str(SOURCE / "build" / "vrmlray"))


def molecular_corpus():
    """The corpus's molecular/ folder, or a skip (a failure when the corpus was asked for)."""
    setting = os.environ.get("VRMLRAY_CORPUS")
    required = os.environ.get("VRMLRAY_REQUIRE_CORPUS") == "1"
    if setting == "none":
        pytest.skip("corpus skipped: VRMLRAY_CORPUS=none")
    root = pathlib.Path(setting) if setting else SOURCE.parent / "shared" / "corpus"
    if not root.is_dir():
        message = f"corpus not found at {root}; set VRMLRAY_CORPUS=DIR to run this test"
        if setting or required:
            pytest.fail(message)
        pytest.skip(message)
    folder = root / "molecular"
    if not folder.is_dir():
        pytest.fail(f"the corpus at {root} has no folder molecular")
    return folder


def cli(*args, check=True):
    run = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True)
    if check:
        assert run.returncode == 0, run.stderr
    return run


def cli_render_bytes(tmp_path, scene, name, *options):
    out = tmp_path / name
    cli("render", scene, "-q", "-o", out, *options)
    return out.read_bytes()


def module_render_bytes(tmp_path, scene, name, width, height, **options):
    out = tmp_path / name
    vrmlray.write_image(out, scene.render(width, height, **options))
    return out.read_bytes()


# --- load and what a scene tells ------------------------------------------------------------


def info_line(text, key):
    match = re.search(rf"^{key}\s+(.*)$", text, re.M)
    assert match, f"no '{key}' line in:\n{text}"
    return match.group(1)


@pytest.mark.parametrize("name", ["001_sphere.wrl", "000_scene1_glass_bubbles.wrl",
                                  "003_particles_gas.wrl"])
def test_info_has_the_figures_vrmlray_info_prints(name):
    path = SEEDS / name
    figures = vrmlray.load(str(path)).info()
    text = cli("info", path).stdout
    assert info_line(text, "encoding") == figures["encoding"]
    nodes = re.match(r"(\d+) read .*, (\d+) top-level", info_line(text, "nodes"))
    assert (int(nodes[1]), int(nodes[2])) == (figures["nodes"], figures["top_level"])
    tracer = re.match(r"(\d+) spheres, (\d+) quadrics .*, (\d+) meshes with (\d+) triangles",
                      info_line(text, "tracer"))
    assert tuple(map(int, tracer.groups())) == (figures["spheres"], figures["quadrics"],
                                                figures["meshes"], figures["triangles"])
    lights = re.match(r"(\d+), headlight (on|off)", info_line(text, "lights"))
    assert (int(lights[1]), lights[2] == "on") == (figures["lights"], figures["headlight"])
    assert int(info_line(text, "viewpoints")) == figures["viewpoints"]
    assert info_line(text, "camera") == figures["camera"]
    assert int(info_line(text, "warnings")) == figures["warnings"]
    bounds = [float(v) for v in info_line(text, "bounds").replace("(", " ").replace(")", " ").replace("..", " ").split()]
    # info prints %g, six significant digits: the dict holds the doubles themselves.
    assert np.allclose(bounds, np.ravel(figures["bounds"]), rtol=1e-5, atol=1e-9)
    for type_name, count in figures["node_types"].items():
        assert re.search(rf"^  {type_name}\s+{count}$", text, re.M), type_name


def test_scene_lists_bounds_viewpoints_and_lights_as_info_does():
    path = SEEDS / "000_scene1_glass_bubbles.wrl"
    scene = vrmlray.load(path)  # an os.PathLike
    text = cli("info", path).stdout
    assert scene.path == str(path)
    assert scene.bounds == tuple(map(tuple, scene.info()["bounds"]))
    assert len(scene.lights) == scene.info()["lights"] > 0
    for light in scene.lights:
        assert re.search(rf"^  {light['kind']}\s+colour \({' '.join('%g' % c for c in light['color'])}\)",
                         text, re.M), light
    assert len(scene.viewpoints) == scene.info()["viewpoints"]
    for view in scene.viewpoints:
        line = f"position ({' '.join('%g' % c for c in view['position'])}) fieldOfView {view['field_of_view']:g}"
        assert line in text, view
        assert abs(np.linalg.norm(view["direction"]) - 1) < 1e-12  # a unit vector


def test_load_takes_scene_text_and_bytes():
    text = SPHERE.read_text()
    for source in (text, text.encode()):
        scene = vrmlray.load(source)
        assert scene.path == "<string>.wrl"
        assert scene.info()["spheres"] == vrmlray.load(SPHERE).info()["spheres"]
    assert vrmlray.load("#X3D V3.0 utf8\nShape { geometry Sphere {} }", encoding="x3dv").info()["spheres"] == 1


def test_encoding_insists_on_the_files_encoding():
    with pytest.raises(vrmlray.InputError, match="VRML97.*not X3D XML"):
        vrmlray.load(SPHERE, encoding="x3d")
    with pytest.raises(vrmlray.UsageError, match="one of vrml97"):
        vrmlray.load(SPHERE, encoding="wrl")
    assert vrmlray.load(SPHERE, encoding="vrml97").info()["encoding"] == "VRML97 (classic)"


def test_warnings_are_diagnostics_and_strict_makes_them_errors():
    text = "#VRML V2.0 utf8\nShape { geometry Sphere {} }\nFrobnicator { }\n"
    scene = vrmlray.load(text)
    warnings = [d for d in scene.diagnostics if d[3] == "warning"]
    assert warnings, scene.diagnostics
    file, line, column, severity, message = warnings[0]
    assert (file, line) == ("<string>.wrl", 3) and column >= 1 and "Frobnicator" in message
    with pytest.raises(vrmlray.InputError, match="strict") as raised:
        vrmlray.load(text, strict=True)
    assert raised.value.diagnostics == scene.diagnostics


def test_read_errors_raise_with_their_diagnostics():
    bad = SOURCE / "tests" / "corpus" / "bad" / "bad_number_two_dots.wrl"
    run = cli("info", bad, check=False)
    with pytest.raises(vrmlray.InputError) as raised:
        vrmlray.load(bad)
    error = raised.value
    assert error.exit_code == run.returncode == 3
    file, line, column, severity, message = next(d for d in error.diagnostics if d[3] == "error")
    assert f"{file}:{line}:{column}: error: {message}" in run.stderr
    assert str(error).startswith(f"{file}:{line}:{column}: error: ")
    with pytest.raises(vrmlray.InputError, match="missing.wrl"):
        vrmlray.load("missing.wrl")
    assert issubclass(vrmlray.InputError, vrmlray.Error)


def test_load_limits_are_the_command_lines():
    with pytest.raises(vrmlray.InputError, match="nodes"):
        vrmlray.load(SEEDS / "000_scene1_glass_bubbles.wrl", limit=["nodes=3"])
    with pytest.raises(vrmlray.UsageError, match="frobs"):
        vrmlray.load(SPHERE, limit=["frobs=3"])


# --- render ---------------------------------------------------------------------------------


def test_render_gives_linear_float_arrays():
    scene = vrmlray.load(SPHERE)
    rgb = scene.render(64, 48)
    assert rgb.shape == (48, 64, 3) and rgb.dtype == np.float32
    rgba = scene.render(64, 48, alpha=True)
    assert rgba.shape == (48, 64, 4)
    assert np.isfinite(rgba).all() and 0 < rgba[..., 3].mean() < 1  # the sphere and background
    # Premultiplied: where nothing is hit (alpha 0) the colour is 0, not the background.
    assert np.all(rgba[rgba[..., 3] == 0][:, :3] == 0)


@pytest.mark.parametrize("options", [
    {},
    {"spp": 4, "sampler": "grid"},
    {"spp": 9, "sampler": "jitter", "seed": 3, "background": (0.1, 0.2, 0.3)},
    {"alpha": True, "fit": True, "camera": "ortho"},
])
def test_render_writes_the_bytes_the_command_line_writes(tmp_path, options):
    words = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            words.append(flag)
        else:
            words += [flag, ",".join(map(str, value)) if isinstance(value, tuple) else str(value)]
    scene = vrmlray.load(SEEDS / "000_scene2_metal_glass.wrl")
    ours = module_render_bytes(tmp_path, scene, "module.png", 80, 60, **options)
    theirs = cli_render_bytes(tmp_path, SEEDS / "000_scene2_metal_glass.wrl", "cli.png",
                              "-W", 80, "-H", 60, *words)
    assert ours == theirs


def test_a_loaded_scene_renders_again_without_its_file(tmp_path):
    copy = tmp_path / "scene.wrl"
    shutil.copy(SEEDS / "000_scene1_glass_bubbles.wrl", copy)
    scene = vrmlray.load(copy)
    first = scene.render(40, 30)
    copy.unlink()
    assert np.array_equal(scene.render(40, 30), first)  # deterministic, nothing re-read
    other = scene.render(40, 30, background=(1, 0, 0))
    assert not np.array_equal(other, first)
    assert scene.render(40, 30, spp=4, sampler="rgss").shape == (30, 40, 3)


def test_bad_keywords_raise_usage_errors_as_the_command_line_exits_2(tmp_path):
    scene = vrmlray.load(SPHERE)
    for options, pattern in [({"spp": 0}, "spp"), ({"sampler": "best"}, "sampler"),
                             ({"frobnicate": 1}, "frobnicate"), ({"background": (1, 2)}, "R,G,B"),
                             ({"output": "x.png"}, "write_image"), ({"srgb": True}, "write_image")]:
        with pytest.raises(vrmlray.UsageError, match=pattern) as raised:
            scene.render(8, 8, **options)
        assert raised.value.exit_code == 2 and isinstance(raised.value, ValueError)
    with pytest.raises(vrmlray.UsageError, match="width"):
        scene.render(0, 8)
    # An unknown viewpoint is found only once the scene is flattened, without the GIL.
    run = cli("render", SPHERE, "--viewpoint", "nowhere", "-o", tmp_path / "x.png", check=False)
    with pytest.raises(vrmlray.UsageError, match="nowhere") as raised:
        scene.render(8, 8, viewpoint="nowhere")
    assert raised.value.exit_code == run.returncode


def test_progress_is_reported_and_its_exceptions_raised():
    scene = vrmlray.load(SEEDS / "000_scene1_glass_bubbles.wrl")
    seen = []
    scene.render(64, 48, progress=lambda fraction, rays: seen.append((fraction, rays)))
    assert seen and seen[-1][0] == 1.0
    assert [f for f, _ in seen] == sorted(f for f, _ in seen)

    def broken(fraction, rays):
        raise KeyError("stop")
    with pytest.raises(KeyError, match="stop"):
        scene.render(16, 16, progress=broken)


def test_render_releases_the_gil(tmp_path):
    """The main thread keeps running Python while another thread renders: were the GIL held,
    it would make no step between the render's start and end."""
    scene = vrmlray.load(SEEDS / "000_scene1_glass_bubbles.wrl")
    span = {}

    def work():
        span["start"] = time.perf_counter()
        scene.render(320, 240, spp=16, sampler="grid", threads=1)
        span["end"] = time.perf_counter()

    thread = threading.Thread(target=work)
    steps = []
    thread.start()
    while thread.is_alive():
        steps.append(time.perf_counter())
        sum(range(100))
    thread.join()
    start, end = span["start"], span["end"]
    inside = [t for t in steps if start + 0.05 < t < end - 0.05]
    assert end - start > 0.3, "the render is too short to measure"
    # A render holding the GIL lets the main thread make no step until it returns (Python's
    # switch interval does not interrupt C++); beside the render it makes ~10^5 a second, and
    # 1,000 a second leaves room for a machine busy with other work.
    assert len(inside) > 1000 * (end - start), (len(inside), end - start)


def test_renders_run_on_several_threads_at_once():
    scene = vrmlray.load(SEEDS / "000_scene3_checkerboard.wrl")
    alone = scene.render(48, 36, spp=4, sampler="grid")
    results = [None] * 4

    def work(k):
        results[k] = scene.render(48, 36, spp=4, sampler="grid", threads=1)
    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(r, alone) for r in results)  # renders are deterministic


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_a_thousand_loads_do_not_grow_memory():
    path = SEEDS / "003_particles_gas.wrl"  # 107 kB of text, a few hundred kB of scene each
    for _ in range(100):  # the allocator's pools and pybind11's tables settle
        vrmlray.load(path)
    before = rss_bytes()
    for _ in range(1000):
        scene = vrmlray.load(path)
        del scene
    grown = rss_bytes() - before
    # One leaked scene is at least its 107 kB source text: 1,000 would be over 100 MB; 16 MB
    # leaves room for the allocator's arenas on a busy machine.
    assert grown < 16 << 20, f"RSS grew by {grown / 1e6:.1f} MB over 1,000 loads"


# --- images ---------------------------------------------------------------------------------


def test_compare_gives_the_command_lines_figures(tmp_path):
    scene = vrmlray.load(SPHERE)
    a = scene.render(64, 48)
    b = scene.render(64, 48, spp=4, sampler="grid")
    vrmlray.write_image(tmp_path / "a.png", a)
    vrmlray.write_image(tmp_path / "b.png", b)
    ours = vrmlray.compare(tmp_path / "a.png", str(tmp_path / "b.png"), max_rmse=0.5)
    run = cli("compare", tmp_path / "a.png", tmp_path / "b.png", "--max-rmse", "0.5", "--json")
    import json
    assert ours == json.loads(run.stdout)
    same = vrmlray.compare(a, a)
    assert same["pass"] and same["psnr"] == float("inf") and same["rmse"] == 0
    strict = vrmlray.compare(a, b, max_abs=1e-9, diff=str(tmp_path / "heat.png"))
    assert not strict["pass"] and strict["failures"]
    assert vrmlray.read_image(tmp_path / "heat.png").shape == (48, 64, 3)
    on_arrays = vrmlray.compare(a, b, max_rmse=0.5)
    assert on_arrays["rmse"] > 0  # floats, not the files' 8-bit codes: close to the files'
    assert abs(on_arrays["rmse"] - ours["rmse"]) < 1 / 255


def test_compare_errors():
    a = np.zeros((4, 4, 3), np.float32)
    with pytest.raises(vrmlray.InputError, match="size"):
        vrmlray.compare(a, np.zeros((4, 5, 3), np.float32))
    with pytest.raises(vrmlray.UsageError, match="frob"):
        vrmlray.compare(a, a, frob=1)
    with pytest.raises(vrmlray.InputError):
        vrmlray.compare(a, "missing.png")
    with pytest.raises(vrmlray.UsageError, match="floats"):
        vrmlray.compare(a, np.zeros((4, 4, 3), np.uint8))


def test_write_image_and_read_image_round_trip(tmp_path):
    rgba = vrmlray.load(SPHERE).render(32, 24, alpha=True)
    vrmlray.write_image(tmp_path / "a.png", rgba)
    back = vrmlray.read_image(tmp_path / "a.png")
    assert back.shape == (24, 32, 4)
    # PNG stores straight colour in 8 bits: alpha comes back within half a code.
    assert np.abs(back[..., 3] - rgba[..., 3]).max() <= 0.5 / 255 + 1e-7
    vrmlray.write_image(tmp_path / "a.exr", rgba)
    assert np.array_equal(vrmlray.read_image(tmp_path / "a.exr"), rgba)  # float EXR: exact


def test_write_image_errors():
    rgb = np.zeros((4, 4, 3), np.float32)
    with pytest.raises(vrmlray.OutputError) as raised:
        vrmlray.write_image("/nonexistent/folder/a.png", rgb)
    assert raised.value.exit_code == 4 and isinstance(raised.value, OSError)
    with pytest.raises(vrmlray.UsageError, match="alpha"):
        vrmlray.write_image("a.ppm", np.zeros((4, 4, 4), np.float32))
    with pytest.raises(vrmlray.UsageError, match="H x W x 3"):
        vrmlray.write_image("a.png", np.zeros((4, 4), np.float32))


# --- a real molecule ------------------------------------------------------------------------


def test_a_jmol_molecule_opaque_and_as_gas_as_the_command_line(tmp_path):
    path = molecular_corpus() / "jmol" / "pept_spacefill.wrl"
    scene = vrmlray.load(path)
    recovery = scene.info()["recovery"]
    assert recovery["spheres"] > 0  # Jmol's atoms are meshes on spheres
    line = info_line(cli("info", path).stdout, "recovery")
    assert line.startswith(f"{recovery['spheres'] + recovery['ellipsoids'] + recovery['cylinders']} "
                           f"of {recovery['candidates']} mesh placements"), line
    opaque = module_render_bytes(tmp_path, scene, "opaque.png", 96, 72)
    assert opaque == cli_render_bytes(tmp_path, path, "opaque_cli.png", "-W", 96, "-H", 72)
    gas = module_render_bytes(tmp_path, scene, "gas.png", 96, 72, spheres="gas", density=0.03)
    assert gas == cli_render_bytes(tmp_path, path, "gas_cli.png", "-W", 96, "-H", 72,
                                   "--spheres", "gas", "--density", "0.03")
    assert gas != opaque


def test_the_documented_example_runs(tmp_path):
    """docs/python.md's example, as docs/python_example.py runs it: it writes its figure."""
    corpus = molecular_corpus().parent
    run = subprocess.run([sys.executable, SOURCE / "docs" / "python_example.py", corpus, tmp_path],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "1216 of 1216 meshes are exact spheres" in run.stdout and (tmp_path / "python_c551.png").stat().st_size > 10000


ANIMATED = """#VRML V2.0 utf8
Viewpoint { position 0 0 10 }
DEF Mover Transform { children Shape { appearance Appearance { material Material {} }
                                       geometry Sphere { radius 1 } } }
DEF Clock TimeSensor { cycleInterval 2 loop TRUE }
DEF Path PositionInterpolator { key [0 1] keyValue [-2 0 0, 2 0 0] }
ROUTE Clock.fraction_changed TO Path.set_fraction
ROUTE Path.value_changed TO Mover.set_translation
"""


def test_time_renders_the_world_at_t_as_the_command_line(tmp_path):
    # docs/animation.md: render(time=T) is `vrmlray render --time T`, byte for byte, and the world moves: the
    # sphere starts at the first key (-2 0 0), not at the Transform's file value (0 0 0).
    scene_file = tmp_path / "animated.wrl"
    scene_file.write_text(ANIMATED)
    scene = vrmlray.load(scene_file)
    images = {}
    for t in (0.0, 0.5, 1.0):
        ours = module_render_bytes(tmp_path, scene, f"module_{t}.png", 64, 48, time=t)
        theirs = cli_render_bytes(tmp_path, scene_file, f"cli_{t}.png", "-W", 64, "-H", 48,
                                  "--time", t)
        assert ours == theirs, t
        images[t] = ours
    assert images[0.0] != images[0.5] != images[1.0]
    # Rendering t = 0 again after other times gives the first image: each evaluation starts from
    # the file's values.
    assert module_render_bytes(tmp_path, scene, "again.png", 64, 48) == images[0.0]
    left = scene.render(64, 48)
    lit = np.argwhere(left.sum(axis=2) > 0.05)
    assert lit[:, 1].mean() < 32  # the sphere is left of centre at t = 0


def test_sequences_are_loops_over_render(tmp_path):
    scene = vrmlray.load(SEEDS / "001_sphere.wrl")
    for keyword in ("frames", "fps", "orbit"):
        with pytest.raises(vrmlray.UsageError, match="one image"):
            scene.render(16, 16, **{keyword: 2})


def test_without_numpy_the_import_says_what_is_missing():
    """A Python without NumPy (here: NumPy blocked) is told at import what to install, not a bare
    "No module named 'numpy'" at the first render."""
    code = "import sys; sys.modules['numpy'] = None\nimport vrmlray"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ))
    assert run.returncode != 0
    assert "needs NumPy" in run.stderr and "python3-numpy" in run.stderr, run.stderr

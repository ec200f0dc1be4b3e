#!/usr/bin/env python3
"""docs/python.md as a script: load a real molecule, render it opaque and as gas, show both with
matplotlib and compare them. Cells (# %%) run one by one in Jupyter or VS Code as well.

    PYTHONPATH=build/python /usr/bin/python3 docs/python_example.py [CORPUS_DIR [OUT_DIR]]

CORPUS_DIR defaults to ../shared/corpus, OUT_DIR (where the figure goes) to docs/images."""
# %% Load a real molecule: cytochrome c551 exported by Jmol 14 ("spacefill only; color chain")
import pathlib
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")  # a file, no window; drop this line in a notebook
import matplotlib.pyplot as plt
import numpy as np

import vrmlray

corpus = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "../shared/corpus")
out = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "docs/images")
scene = vrmlray.load(corpus / "molecular" / "jmol" / "c551_spacefill.wrl")
info = scene.info()
print(f"{info['nodes']} nodes, {info['instances']} placements of {info['instanced_meshes']} mesh; "
      f"{info['recovery']['spheres']} of {info['recovery']['candidates']} meshes are exact spheres")
print("bounds", scene.bounds, "warnings", len(scene.diagnostics))

# %% Render it twice from the one load: opaque, then the atoms as gas
started = time.perf_counter()
opaque = scene.render(480, 360, spp=4, sampler="rgss")
middle = time.perf_counter()
gas = scene.render(480, 360, spheres="gas", density=0.003,
                   progress=lambda done, rays: print(f"\rgas {done:4.0%}", end="", flush=True))
print(f"\nopaque {middle - started:.2f} s, gas {time.perf_counter() - middle:.2f} s")
print(opaque.shape, opaque.dtype)


# %% Show both with matplotlib: the arrays are linear RGB, the screen wants sRGB
def srgb(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)


# %% Compare them: the figures of `vrmlray compare --json`, and its heat-map of the difference
heat_path = pathlib.Path(tempfile.mkdtemp()) / "difference.png"
result = vrmlray.compare(opaque, gas, min_ssim=0.9, diff=str(heat_path))
print({k: result[k] for k in ("rmse", "psnr", "ssim", "pass", "failures")})
heat = vrmlray.read_image(heat_path)

figure, axes = plt.subplots(1, 3, figsize=(13.5, 3.6))
for ax, image, title in [(axes[0], srgb(opaque), "opaque, spp=4 rgss"),
                         (axes[1], srgb(gas), "spheres='gas', density=0.003"),
                         (axes[2], heat, f"difference (SSIM {result['ssim']:.3f})")]:
    ax.imshow(image)
    ax.set_title(title)
    ax.set_axis_off()
figure.tight_layout()
figure.savefig(out / "python_c551.png", dpi=80, bbox_inches="tight")
print("wrote", out / "python_c551.png")

#!/usr/bin/env python3
"""Writes a synthetic protein-sized molecule the way PyMOL exports VRML97: every atom a Transform with its
own Shape, Appearance and Material, every bond a Cylinder under a Transform. The chain is a self-avoiding
random walk (1.5 A steps) in a ball, with an H/C/N/O/S mix and CPK colours, so its size and structure
match a real export without shipping someone else's data.

With --vmd the same molecule is written in the layout of VMD 1.9's VRML 2.0 export instead (no VMD
export is in ../shared/corpus; tests/unit/test_vmd_export.cpp describes the layout): two PROTOs first
(VMDCyl, an open Cylinder; VMDMat, an Appearance), everything in one Group, every atom a Transform whose
Appearance is a VMDMat instance, every bond a VMDCyl turned about its first end, numbers as %g prints them.

tools/gen_molecule.cpp writes the default layout (not --vmd) at the disk's pace, about a hundred times
faster than this script's ~35 us an atom, with its own random numbers: bench/scale.sh uses it, so its
100M-atom file takes minutes instead of an hour. The tests keep using this script.

Usage: gen_molecule.py N_ATOMS OUT.wrl [--seed S] [--no-bonds] [--vmd]
"""
import math
import random
import sys

ELEMENTS = [  # name, fraction, radius (A), colour
    ("H", 0.20, 0.30, (0.95, 0.95, 0.95)),
    ("C", 0.45, 0.60, (0.50, 0.50, 0.50)),
    ("N", 0.14, 0.58, (0.20, 0.30, 1.00)),
    ("O", 0.18, 0.55, (1.00, 0.15, 0.10)),
    ("S", 0.03, 0.90, (1.00, 0.85, 0.15)),
]


def walk(n, seed):
    """The atoms one at a time, (position, radius, colour): the same seed gives the same walk, so the
    writers walk it twice (atoms, then bonds) instead of holding it, which at 10^8 atoms would take
    more memory than the file it writes."""
    rng = random.Random(seed)
    ball = 1.6 * n ** (1 / 3) + 5
    p = [0.0, 0.0, 0.0]
    for _ in range(n):
        for _ in range(50):
            d = [rng.gauss(0, 1) for _ in range(3)]
            s = math.sqrt(sum(x * x for x in d))
            q = [p[i] + 1.5 * d[i] / s for i in range(3)]
            if math.sqrt(sum(x * x for x in q)) < ball:
                break
        p = q
        r = rng.random()
        for name, frac, rad, col in ELEMENTS:
            r -= frac
            if r <= 0:
                break
        yield p, rad, col


def pairs(atoms):
    """Consecutive atoms' positions: the chain's bonds."""
    prev = None
    for p, _, _ in atoms:
        if prev is not None:
            yield prev, p
        prev = p


def main():
    n = int(sys.argv[1])
    out = sys.argv[2]
    seed = int(sys.argv[sys.argv.index("--seed") + 1]) if "--seed" in sys.argv else 1
    bonds = "--no-bonds" not in sys.argv
    ball = 1.6 * n ** (1 / 3) + 5
    if "--vmd" in sys.argv:
        write_vmd(out, lambda: walk(n, seed), bonds)
        return
    with open(out, "w") as f:
        f.write("#VRML V2.0 utf8\n# Synthetic %d-atom molecule in PyMOL's VRML97 export style (tools/gen_molecule.py,"
                " seed %d)\n" % (n, seed))
        f.write("Viewpoint { position 0 0 %.3f fieldOfView 0.785398 description \"front\" }\n" % (ball * 3.2))
        f.write("NavigationInfo { headlight FALSE }\n")
        f.write("DirectionalLight { direction 0.6 -0.7 -0.4 intensity 1 ambientIntensity 0.2 }\n")
        f.write("Background { skyColor [ 0.1 0.1 0.15 ] }\n")
        for (x, y, z), rad, (r, g, b) in walk(n, seed):
            f.write("Transform {\n translation %.4f %.4f %.4f\n children [\n  Shape {\n   appearance Appearance {\n"
                    "    material Material {\n     diffuseColor %.3f %.3f %.3f\n     specularColor 0.3 0.3 0.3\n"
                    "     shininess 0.2\n     ambientIntensity 0.2\n    }\n   }\n   geometry Sphere { radius %.2f }\n"
                    "  }\n ]\n}\n" % (x, y, z, r, g, b, rad))
        if bonds:
            for a, b in pairs(walk(n, seed)):
                mid = [(a[k] + b[k]) / 2 for k in range(3)]
                d = [b[k] - a[k] for k in range(3)]
                length = math.sqrt(sum(x * x for x in d))
                # rotation taking +y onto the bond: axis = y x d, angle = acos(d.y / |d|)
                axis = [d[2], 0.0, -d[0]]
                al = math.sqrt(axis[0] ** 2 + axis[2] ** 2)
                angle = math.acos(max(-1.0, min(1.0, d[1] / length)))
                if al < 1e-9:
                    axis, angle = [1.0, 0.0, 0.0], (0.0 if d[1] > 0 else math.pi)
                else:
                    axis = [axis[0] / al, 0.0, axis[2] / al]
                f.write("Transform { translation %.4f %.4f %.4f rotation %.5f %.5f %.5f %.5f children Shape {"
                        " appearance Appearance { material Material { diffuseColor 0.65 0.65 0.65 } }"
                        " geometry Cylinder { radius 0.15 height %.4f top FALSE bottom FALSE } } }\n"
                        % (mid[0], mid[1], mid[2], axis[0], axis[1], axis[2], angle, length))


VMD_HEADER = """#VRML V2.0 utf8
# Synthetic molecule in the layout of VMD 1.9's VRML 2.0 export (tools/gen_molecule.py --vmd)
PROTO VMDCyl [
  field SFBool  bottom FALSE
  field SFFloat h      2    
  field SFFloat r      1    
  field SFBool  side   TRUE 
  field SFBool  top    FALSE
  ] {
  Cylinder {
    bottom IS bottom
    height IS h     
    radius IS r     
    top    IS top   
  }
}

PROTO VMDMat [
  field SFFloat Ka               0.0
  field SFColor Kd               0.8 0.8 0.8
  field SFColor emissiveColor    0.0 0.0 0.0
  field SFFloat Ksx              0.0
  field SFColor Ks               0.0 0.0 0.0
  field SFFloat Kt               0.0
  ] {
  Appearance {
    material Material {
      ambientIntensity IS Ka           
      diffuseColor     IS Kd           
      emissiveColor    IS emissiveColor
      shininess        IS Ksx          
      specularColor    IS Ks           
      transparency     IS Kt           
    }
  }
}

Group {
  children [
Background { skyColor [ 0.1 0.1 0.15 ] }
"""


def write_vmd(out, atoms, bonds):
    """`atoms`: a function that starts the walk afresh."""
    def material(rgb):
        return "appearance VMDMat { Kd %g %g %g Ksx 0.53 Ks 0.5 0.5 0.5  }\n" % tuple(0.65 * c for c in rgb)

    with open(out, "w") as f:
        f.write(VMD_HEADER)
        for (x, y, z), rad, col in atoms():
            f.write("Transform {\n  translation %g %g %g\n  children [ Shape {\n    " % (x, y, z) + material(col)
                    + "    geometry Sphere { radius %g }\n  }]\n}\n" % rad)
        for a, b in pairs(atoms()) if bonds else ():
            h = math.dist(a, b)
            d = [(b[k] - a[k]) / h for k in range(3)]
            # The writer's rotation: axis = d x (0 1 0), angle -acos(d.y), about the bottom end.
            axis = [-d[2], 0.0, d[0]]
            n = math.sqrt(axis[0] ** 2 + axis[2] ** 2)
            f.write("Transform {\n  translation %g %g %g\n" % (a[0], a[1] + h / 2, a[2]))
            if n > 1e-12:  # the writer's normalised axis has length 1 unless the cross product is 0
                f.write("  center 0.0 %g 0.0\n  rotation %g %g %g  %g\n"
                        % (-h / 2, axis[0] / n, 0.0, axis[2] / n, -math.acos(d[1])))
            elif d[1] < -0.98:
                f.write("  center 0.0 %g 0.0\n  rotation 0 0 -1  -3.14159\n" % (-h / 2))
            f.write("  children [ Shape {\n    " + material((1.0, 1.0, 1.0))
                    + "    geometry VMDCyl { h %g r %g }\n  }]\n}\n" % (h, 0.15))
        f.write("  ]\n}\n")


if __name__ == "__main__":
    main()

// Writers of files in the layouts of two molecular exporters whose output no public file holds,
// for tests/unit/test_generated_exporters.cpp. Each writes a small molecule (atoms on a zig-zag
// chain, a bond between neighbours) the way its exporter structures it:
//
// - UCSF ChimeraX `save file.x3d`, after issue 43's account of its exporter: one unit sphere
//   (an IndexedTriangleSet, DEF'd once and USEd by every atom) under a Transform whose scale is
//   the atom radius; one unit cylinder along z, uncapped (radius 1, z from -0.5 to 0.5), under a
//   Transform turning z onto the bond with scale (r, r, length); `UNIT length angstrom 1e-10`;
//   `headlight true` and no lights; an OrthoViewpoint; `solid false`; per-vertex ColorRGBA where
//   a surface is partly transparent. The number format (6 decimals) is this generator's choice.
// - VMD `render VRML2 file.wrl`, after VMD's Vrml2DisplayDevice.C (revision 1.17, 2009): its
//   header's `PROTO VMDCyl` (a Cylinder whose fields are IS'd, `side` declared and left unused)
//   and `PROTO VMDMat` (an Appearance; Kd is the diffuse colour premultiplied by the material's
//   diffuse factor, Kt the transparency), spheres as Sphere nodes under a translation, open
//   cylinders as VMDCyl under a Transform with `center 0 -h/2 0` and a rotation by -acos of the
//   axis' y component about (axis x y); the whole scene in one Group. The gradient Background
//   (skyColor and skyAngle) stands for VMD's gradient background mode.
#pragma once
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace vr::test {

struct LayoutAtom {
    double x, y, z, radius;
    double r, g, b;
};

// Atoms on a zig-zag in the z = 0 plane, alternately carbon-grey and oxygen-red.
inline std::vector<LayoutAtom> zigzag_atoms(int count) {
    std::vector<LayoutAtom> atoms;
    for (int i = 0; i < count; ++i) {
        const bool oxygen = i % 2 == 1;
        atoms.push_back({1.3 * (i - (count - 1) / 2.0), oxygen ? 0.75 : -0.75, 0.0,
                         oxygen ? 0.5 : 0.6, oxygen ? 1.0 : 0.55, oxygen ? 0.05 : 0.55,
                         oxygen ? 0.05 : 0.55});
    }
    return atoms;
}

inline std::string fixed6(double v) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.6f", v);
    return buf;
}

// A unit sphere of `rings` x `segments` (poles shared) as IndexedTriangleSet index and points.
inline void unit_sphere(int rings, int segments, std::string& index, std::string& points) {
    for (int i = 0; i <= rings; ++i) {
        if (i == 0 || i == rings) {
            points += "0.000000 0.000000 " + fixed6(i == 0 ? 1.0 : -1.0) + " ";
            continue;
        }
        for (int j = 0; j < segments; ++j) {
            const double t = M_PI * i / rings, p = 2.0 * M_PI * j / segments;
            points += fixed6(std::sin(t) * std::cos(p)) + " " + fixed6(std::sin(t) * std::sin(p)) +
                      " " + fixed6(std::cos(t)) + " ";
        }
    }
    const int last = 1 + (rings - 1) * segments;
    auto at = [&](int i, int j) { return 1 + (i - 1) * segments + j % segments; };
    auto tri = [&](int a, int b, int c) {
        index += std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + " ";
    };
    for (int j = 0; j < segments; ++j) tri(0, at(1, j), at(1, j + 1));
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            tri(at(i, j), at(i + 1, j), at(i + 1, j + 1));
            tri(at(i, j), at(i + 1, j + 1), at(i, j + 1));
        }
    for (int j = 0; j < segments; ++j) tri(last, at(rings - 1, j + 1), at(rings - 1, j));
}

// A unit tube along z (radius 1, z from -0.5 to 0.5), uncapped.
inline void unit_tube_z(int segments, std::string& index, std::string& points) {
    for (int end = 0; end < 2; ++end)
        for (int j = 0; j < segments; ++j) {
            const double p = 2.0 * M_PI * j / segments;
            points += fixed6(std::cos(p)) + " " + fixed6(std::sin(p)) + " " +
                      fixed6(end ? 0.5 : -0.5) + " ";
        }
    for (int j = 0; j < segments; ++j) {
        const int a = j, b = (j + 1) % segments;
        index += std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(segments + b) +
                 " " + std::to_string(a) + " " + std::to_string(segments + b) + " " +
                 std::to_string(segments + a) + " ";
    }
}

// The rotation turning +z onto the unit vector d: about z x d by acos(d.z).
inline std::string rotation_from_z(double dx, double dy, double dz) {
    const double ax = -dy, ay = dx, len = std::hypot(ax, ay);
    if (len == 0.0) return "0 0 1 0";
    return fixed6(ax / len) + " " + fixed6(ay / len) + " 0 " + fixed6(std::acos(dz));
}

// ChimeraX-style X3D: `atoms.size()` atoms, one of them (the last) squashed by a non-uniform
// scale (ChimeraX writes none; it shows what recovery makes of one: an ellipsoid), bonds between
// neighbours, and one partly transparent surface patch with per-vertex ColorRGBA.
inline std::string chimerax_x3d(const std::vector<LayoutAtom>& atoms) {
    std::string sphere_index, sphere_points, tube_index, tube_points;
    unit_sphere(10, 20, sphere_index, sphere_points);
    unit_tube_z(20, tube_index, tube_points);
    std::string x = R"x3d(<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 3.3//EN" "http://www.web3d.org/specifications/x3d-3.3.dtd">
<X3D profile="Interchange" version="3.3" xmlns:xsd="http://www.w3.org/2001/XMLSchema-instance">
<head>
<meta name="generator" content="UCSF ChimeraX (layout)"/>
<unit category="length" name="angstrom" conversionFactor="1e-10"/>
</head>
<Scene>
<NavigationInfo headlight="true" type='"EXAMINE" "ANY"'/>
<Background skyColor="1 1 1"/>
<OrthoViewpoint position="0 0 30" fieldOfView="-6 -4.5 6 4.5" centerOfRotation="0 0 0"/>
)x3d";
    for (size_t i = 0; i < atoms.size(); ++i) {
        const LayoutAtom& a = atoms[i];
        const std::string r = fixed6(a.radius);
        const std::string scale = i + 1 == atoms.size() ? r + " " + fixed6(0.5 * a.radius) + " " + r
                                                        : r + " " + r + " " + r;
        x += "<Transform translation=\"" + fixed6(a.x) + " " + fixed6(a.y) + " " + fixed6(a.z) +
             "\" scale=\"" + scale + "\"><Shape><Appearance><Material diffuseColor=\"" +
             fixed6(a.r) + " " + fixed6(a.g) + " " + fixed6(a.b) + "\"/></Appearance>";
        x += i == 0 ? "<IndexedTriangleSet DEF=\"sphere\" solid=\"false\" index=\"" + sphere_index +
                          "\"><Coordinate point=\"" + sphere_points + "\"/></IndexedTriangleSet>"
                    : "<IndexedTriangleSet USE=\"sphere\"/>";
        x += "</Shape></Transform>\n";
    }
    for (size_t i = 0; i + 1 < atoms.size(); ++i) {
        const LayoutAtom &a = atoms[i], &b = atoms[i + 1];
        const double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
        const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
        x += "<Transform translation=\"" + fixed6((a.x + b.x) / 2) + " " + fixed6((a.y + b.y) / 2) +
             " " + fixed6((a.z + b.z) / 2) + "\" rotation=\"" +
             rotation_from_z(dx / length, dy / length, dz / length) +
             "\" scale=\"0.200000 0.200000 " + fixed6(length) +
             "\"><Shape><Appearance><Material diffuseColor=\"0.7 0.7 0.7\"/>"
             "</Appearance>";
        x += i == 0 ? "<IndexedTriangleSet DEF=\"cylinder\" solid=\"false\" index=\"" + tube_index +
                          "\"><Coordinate point=\"" + tube_points + "\"/></IndexedTriangleSet>"
                    : "<IndexedTriangleSet USE=\"cylinder\"/>";
        x += "</Shape></Transform>\n";
    }
    // A transparent surface patch: a quad behind the chain, alpha per vertex.
    x +=
        R"(<Shape><Appearance><Material/></Appearance><IndexedTriangleSet solid="false" index="0 1 2 0 2 3"><Coordinate point="-5 -3 -2 5 -3 -2 5 3 -2 -5 3 -2"/><ColorRGBA color="0.2 0.4 1 0.5 0.2 0.4 1 0.5 0.2 0.4 1 0.8 0.2 0.4 1 0.8"/></IndexedTriangleSet></Shape>
</Scene>
</X3D>
)";
    return x;
}

// Atoms as a PDB file places them (3 decimals, inside a 40 angstrom box) with the elements of a
// protein in its proportions (C, N, O, S: 63, 17, 19, 1 per 100) and their van der Waals radii
// and ChimeraX's element colours: a spacefill picture.
inline std::vector<LayoutAtom> protein_atoms(int count, unsigned seed) {
    std::vector<LayoutAtom> atoms;
    unsigned state = seed;
    auto next = [&state] {  // a small LCG: the same atoms on every platform
        state = state * 1664525u + 1013904223u;
        return double(state >> 8) / double(1u << 24);
    };
    for (int i = 0; i < count; ++i) {
        const double pick = next();
        LayoutAtom a{};
        a.x = std::round(40000.0 * next()) / 1000.0 - 20.0;
        a.y = std::round(40000.0 * next()) / 1000.0 - 20.0;
        a.z = std::round(40000.0 * next()) / 1000.0 - 20.0;
        if (pick < 0.63)
            a = {a.x, a.y, a.z, 1.7, 0.565, 0.565, 0.565};
        else if (pick < 0.80)
            a = {a.x, a.y, a.z, 1.55, 0.188, 0.314, 0.973};
        else if (pick < 0.99)
            a = {a.x, a.y, a.z, 1.52, 1.0, 0.051, 0.051};
        else
            a = {a.x, a.y, a.z, 1.8, 1.0, 1.0, 0.188};
        atoms.push_back(a);
    }
    return atoms;
}

// ChimeraX-style X3D of atoms alone (a spacefill picture): as chimerax_x3d, without the bonds, the
// squashed atom and the surface patch.
inline std::string chimerax_spacefill_x3d(const std::vector<LayoutAtom>& atoms) {
    std::string sphere_index, sphere_points;
    unit_sphere(10, 20, sphere_index, sphere_points);
    std::string x = R"x3d(<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 3.3//EN" "http://www.web3d.org/specifications/x3d-3.3.dtd">
<X3D profile="Interchange" version="3.3" xmlns:xsd="http://www.w3.org/2001/XMLSchema-instance">
<head>
<meta name="generator" content="UCSF ChimeraX (layout)"/>
<unit category="length" name="angstrom" conversionFactor="1e-10"/>
</head>
<Scene>
<NavigationInfo headlight="true" type='"EXAMINE" "ANY"'/>
<Background skyColor="1 1 1"/>
<OrthoViewpoint position="0 0 80" fieldOfView="-25 -20 25 20" centerOfRotation="0 0 0"/>
)x3d";
    for (size_t i = 0; i < atoms.size(); ++i) {
        const LayoutAtom& a = atoms[i];
        const std::string r = fixed6(a.radius);
        x += "<Transform translation=\"" + fixed6(a.x) + " " + fixed6(a.y) + " " + fixed6(a.z) +
             "\" scale=\"" + r + " " + r + " " + r +
             "\"><Shape><Appearance><Material diffuseColor=\"" + fixed6(a.r) + " " + fixed6(a.g) +
             " " + fixed6(a.b) + "\"/></Appearance>";
        x += i == 0 ? "<IndexedTriangleSet DEF=\"sphere\" solid=\"false\" index=\"" + sphere_index +
                          "\"><Coordinate point=\"" + sphere_points + "\"/></IndexedTriangleSet>"
                    : "<IndexedTriangleSet USE=\"sphere\"/>";
        x += "</Shape></Transform>\n";
    }
    return x + "</Scene>\n</X3D>\n";
}

// Bonds as tube meshes baked into world coordinates: each bond an IndexedFaceSet of two rings of
// `segments` vertices about the line between its atoms (radius 0.2, uncapped; every third bond
// capped at both ends by a polygon), computed in single precision and printed with 6 decimals,
// as an exporter that bakes a bond's placement into its vertices writes them. The atoms are
// Sphere nodes; the chain is lifted out of its plane (z = 0.4 i) so that no bond runs along an
// axis.
inline std::string world_tubes_wrl(const std::vector<LayoutAtom>& atoms, int segments) {
    std::string w = "#VRML V2.0 utf8\nViewpoint { position 0 0 30 fieldOfView 0.4 }\n";
    auto lifted = [&](size_t i) {
        return std::array<double, 3>{atoms[i].x, atoms[i].y, 0.4 * double(i)};
    };
    for (size_t i = 0; i < atoms.size(); ++i) {
        const auto p = lifted(i);
        w += "Transform { translation " + fixed6(p[0]) + " " + fixed6(p[1]) + " " + fixed6(p[2]) +
             " children Shape { appearance Appearance { material Material { diffuseColor " +
             fixed6(atoms[i].r) + " " + fixed6(atoms[i].g) + " " + fixed6(atoms[i].b) +
             " } } geometry Sphere { radius " + fixed6(0.5 * atoms[i].radius) + " } } }\n";
    }
    for (size_t i = 0; i + 1 < atoms.size(); ++i) {
        const auto a = lifted(i), b = lifted(i + 1);
        float d[3] = {float(b[0] - a[0]), float(b[1] - a[1]), float(b[2] - a[2])};
        const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (float& c : d) c /= len;
        // u across d (d x z, normalised), v = d x u.
        float u[3] = {d[1], -d[0], 0.0f};
        const float ulen = std::sqrt(u[0] * u[0] + u[1] * u[1]);
        for (float& c : u) c /= ulen;
        const float v[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2],
                            d[0] * u[1] - d[1] * u[0]};
        std::string points, faces;
        for (int end = 0; end < 2; ++end)
            for (int j = 0; j < segments; ++j) {
                const float phi = float(2.0 * M_PI * j / segments);
                const float cr = 0.2f * std::cos(phi), sr = 0.2f * std::sin(phi);
                for (int k = 0; k < 3; ++k)
                    points +=
                        fixed6(double(float(end ? b[k] : a[k]) + cr * u[k] + sr * v[k])) + " ";
                points += ", ";
            }
        for (int j = 0; j < segments; ++j) {
            const int p = j, q = (j + 1) % segments;
            faces += std::to_string(p) + " " + std::to_string(q) + " " +
                     std::to_string(segments + q) + " " + std::to_string(segments + p) + " -1 ";
        }
        if (i % 3 == 2)
            for (int end = 0; end < 2; ++end) {
                for (int j = 0; j < segments; ++j)
                    faces += std::to_string(end ? segments + j : segments - 1 - j) + " ";
                faces += "-1 ";
            }
        w += "Shape { appearance Appearance { material Material { diffuseColor 0.7 0.7 0.7 } } "
             "geometry IndexedFaceSet { solid FALSE coord Coordinate { point [ " +
             points + "] } coordIndex [ " + faces + "] } }\n";
    }
    return w;
}

// VMD-style VRML97: its header PROTOs, spheres, open VMDCyl bonds, a gradient Background.
inline std::string vmd_wrl(const std::vector<LayoutAtom>& atoms) {
    std::string w = R"(#VRML V2.0 utf8
# Created with VMD: http://www.ks.uiuc.edu/Research/vmd/
# Define some custom nodes VMD to decrease file size
# custom VMD cylinder node
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

# custom VMD materials node
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

Background { skyColor [0.1 0.1 0.3, 0.9 0.9 1.0] skyAngle [1.5708] }
Viewpoint { position 0 0 30 fieldOfView 0.4 }

# begin the actual scene
Group {
  children [
)";
    const double diffuse = 0.65;  // VMD's default material: Kd = 0.65 x the colour
    for (size_t i = 0; i < atoms.size(); ++i) {
        const LayoutAtom& a = atoms[i];
        w += "    Transform {\n      translation " + fixed6(a.x) + " " + fixed6(a.y) + " " +
             fixed6(a.z) +
             "\n      children [ Shape {\n        appearance VMDMat { Ka 0.000000 Kd " +
             fixed6(diffuse * a.r) + " " + fixed6(diffuse * a.g) + " " + fixed6(diffuse * a.b) +
             " Ksx 0.530000 Ks 0.500000 0.500000 0.500000 " + (i == 0 ? "Kt 0.300000 " : "") +
             " }\n        geometry Sphere { radius " + fixed6(a.radius) + " }\n      }]\n    }\n";
    }
    for (size_t i = 0; i + 1 < atoms.size(); ++i) {
        const LayoutAtom &a = atoms[i], &b = atoms[i + 1];
        const double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
        const double h = std::sqrt(dx * dx + dy * dy + dz * dz);
        // Vrml2DisplayDevice::cylinder: rotation axis (d x y), normalised, angle -acos(d.y).
        const double ax = -dz / h, az = dx / h, len = std::hypot(ax, az);
        w += "    Transform {\n      translation " + fixed6(a.x) + " " + fixed6(a.y + h / 2) + " " +
             fixed6(a.z) + "\n      center 0.0 " + fixed6(-h / 2) + " 0.0\n      rotation " +
             fixed6(ax / len) + " 0.000000 " + fixed6(az / len) + "  " +
             fixed6(-std::acos(dy / h)) +
             "\n      children [ Shape {\n        appearance VMDMat { Kd 0.455000 0.455000 "
             "0.455000  }\n"
             "        geometry VMDCyl { h " +
             fixed6(h) + " r 0.200000 }\n      }]\n    }\n";
    }
    w += "  ]\n}\n";
    return w;
}

}  // namespace vr::test

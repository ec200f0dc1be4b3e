// VMD's VRML 2.0, VRML 1.0 and X3D exports. VMD is not in Debian and ../shared/corpus holds no
// export of it, so the scene below is written by hand in the layout of VMD 1.9's writer
// (Vrml2DisplayDevice): two PROTOs declared first (VMDCyl, an open Cylinder; VMDMat, an Appearance
// whose Material takes the fields Ka Kd Ksx Ks Kt), the whole scene in one top-level Group, every
// sphere a Transform with a translation, every cylinder and cone a Transform that puts the
// primitive's centre at the first end's height plus h/2 and turns it about its bottom with `center
// 0 -h/2 0` and `rotation axis -acos(dp)` (or `0 0 -1 -3.14159` for an axis near -y), numbers with
// %g's 6 significant digits. What a user relies on: atoms and bonds land where VMD drew them, with
// VMD's material.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scene_text.h"

namespace vr {
namespace {

// The exporter's header, as VMD writes it (whitespace included).
const char* const kVmdHeader = R"(#VRML V2.0 utf8
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


# begin the actual scene
Group {
  children [
Background { skyColor [0 0 0.2, 0.05 0.05 0.25, 0.1 0.1 0.3] skyAngle [ 1.5, 3.0] }
)";

// Atoms at (1 2 3) and (4 6 3), joined by a filled bond (Cylinder) and an open one (VMDCyl), a bond
// pointing down -y (the writer's special case), a cone, a triangle with normals, a coloured line
// and a point. The cylinders' translation, center and rotation are what the writer prints for
// those ends: a = (1 2 3), b = (4 6 3), h = 5: translation (1, 2 + 2.5, 3); axis (b - a)/h =
// (0.6 0.8 0); rotation axis = axis x (0 1 0) = (0 0 0.6), normalised (0 0 1); angle -acos(0.8).
const char* const kVmdBody = R"(Transform {
  translation 1 2 3
  children [ Shape {
    appearance VMDMat { Kd 0.65 0 0 Ksx 0.53 Ks 0.5 0.5 0.5  }
    geometry Sphere { radius 0.5 }
  }]
}
Transform {
  translation 4 6 3
  children [ Shape {
    appearance VMDMat { Ka 0.1 Kd 0 0 0.65 Kt 0.25  }
    geometry Sphere { radius 0.25 }
  }]
}
Transform {
  translation 1 4.5 3
  center 0.0 -2.5 0.0
  rotation 0 0 1  -0.643501
  children [ Shape {
    appearance VMDMat { Kd 0.65 0.65 0.65  }
    geometry Cylinder { height 5 radius 0.2 }
  }]
}
Transform {
  translation 1 4.5 3
  center 0.0 -2.5 0.0
  rotation 0 0 1  -0.643501
  children [ Shape {
    appearance VMDMat { Kd 0.65 0.65 0.65  }
    geometry VMDCyl { h 5 r 0.1 }
  }]
}
Transform {
  translation 0 7 0
  center 0.0 -2 0.0
  rotation 0 0 -1  -3.14159
  children [ Shape {
    appearance VMDMat { Kd 0.65 0.65 0.65  }
    geometry Cylinder { height 4 radius 0.3 }
  }]
}
Transform {
  translation 1 4.5 3
  center 0.0 -2.5 0.0
  rotation 0 0 1  -0.643501
  children [ Shape {
    appearance VMDMat { Kd 0.65 0.65 0  }
    geometry Cone { bottomRadius 0.4 height 5 }
  }]
}
Shape {
  appearance VMDMat { Kd 0 0.65 0  }
  geometry IndexedFaceSet { 
    solid FALSE coordIndex [ 0, 1, 2, -1 ]
    coord Coordinate { point [ 0 0 0,  1 0 0,  0 1 0 ] }
    normal Normal { vector [ 0 0 1, 0 0 1, 0 0 1 ] }
  }
}
Shape {
  appearance VMDMat { Kd 0.65 0.65 0.65  }
  geometry IndexedLineSet { 
    coordIndex [ 0, 1, -1 ]
    coord Coordinate { point [ 1 2 3,  4 6 3 ] }
    color Color { color [ 1.000 1.000 0.000, 1.000 1.000 0.000 ] }
  }
}
Shape {
  appearance VMDMat { Kd 0.65 0.65 0.65  }
  geometry PointSet { 
    coord Coordinate { point [2 2 2] }
    color Color { color [1.000 0.000 1.000] }
  }
}
  ]
}
)";

// A primitive's object-space point in world space.
Vec3 world(const Quadric& q, const Vec3& p) { return Vec3(q.world_from_object * Vec4(p, 1.0)); }

// The ends of a cylinder's or cone's axis in world space: object (0, -h/2, 0) and (0, h/2, 0).
void expect_axis(const Quadric& q, const Vec3& from, const Vec3& to, double tolerance) {
    const double h = q.size.y;
    EXPECT_NEAR(glm::length(world(q, Vec3(0, -h / 2, 0)) - from), 0.0, tolerance);
    EXPECT_NEAR(glm::length(world(q, Vec3(0, h / 2, 0)) - to), 0.0, tolerance);
}

const Material& material_of(const FlatScene& flat, uint32_t shading) {
    return flat.materials[flat.shadings[shading].material];
}

TEST(VmdExport, AtomsBondsAndMaterialsLandWhereVmdDrewThem) {
    const testing::FlattenedText f =
        testing::flatten_scene_text(std::string(kVmdHeader) + kVmdBody, "vmdscene.wrl");
    EXPECT_EQ(f.build_warnings, 0u) << f.messages;
    const FlatScene& flat = f.flat;

    // Atoms: exact positions and radii (decimal inputs, translation only).
    ASSERT_EQ(flat.spheres.size(), 2u);
    EXPECT_EQ(flat.spheres[0].center, Vec3(1, 2, 3));
    EXPECT_EQ(flat.spheres[0].radius, 0.5);
    EXPECT_EQ(flat.spheres[1].center, Vec3(4, 6, 3));
    EXPECT_EQ(flat.spheres[1].radius, 0.25);

    // VMDMat's fields reach the Material: Ka -> ambientIntensity, Kd -> diffuseColor, Ksx ->
    // shininess, Ks -> specularColor, Kt -> transparency; fields left out keep the PROTO's
    // defaults (Ka 0, Ksx 0, Ks 0, Kt 0), not Material's own (0.2 ambient, 0.2 shininess).
    const Material& red = material_of(flat, flat.spheres[0].shading);
    EXPECT_EQ(red.diffuse, Vec3(0.65, 0, 0));
    EXPECT_EQ(red.ambient_intensity, 0.0);
    EXPECT_EQ(red.shininess, 0.53);
    EXPECT_EQ(red.specular, Vec3(0.5));
    EXPECT_EQ(red.transparency, 0.0);
    const Material& blue = material_of(flat, flat.spheres[1].shading);
    EXPECT_EQ(blue.diffuse, Vec3(0, 0, 0.65));
    EXPECT_EQ(blue.ambient_intensity, 0.1);
    EXPECT_EQ(blue.shininess, 0.0);
    EXPECT_EQ(blue.specular, Vec3(0.0));
    EXPECT_EQ(blue.transparency, 0.25);

    // Bonds and the cone run from one atom's centre to the other's. The rotation angle is
    // printed with 6 digits (0.643501 for acos(0.8) = 0.6435011...): 1e-6 radians turn a 5-long
    // axis by 5e-6, so the ends are checked to 1e-5.
    ASSERT_EQ(flat.quadrics.size(), 4u);
    const Quadric& bond = flat.quadrics[0];
    EXPECT_EQ(bond.kind, QuadricKind::Cylinder);
    EXPECT_EQ(bond.size, Vec3(0.4, 5, 0.4));
    EXPECT_TRUE(bond.side && bond.top && bond.bottom);
    expect_axis(bond, Vec3(1, 2, 3), Vec3(4, 6, 3), 1e-5);

    // VMDCyl: the open tube of VMD's unfilled cylinders (no caps), its h and r the Cylinder's.
    const Quadric& tube = flat.quadrics[1];
    EXPECT_EQ(tube.kind, QuadricKind::Cylinder);
    EXPECT_EQ(tube.size, Vec3(0.2, 5, 0.2));
    EXPECT_TRUE(tube.side);
    EXPECT_FALSE(tube.top);
    EXPECT_FALSE(tube.bottom);
    expect_axis(tube, Vec3(1, 2, 3), Vec3(4, 6, 3), 1e-5);

    // Near -y the writer turns by 3.14159 about -z instead, pi to 2.65e-6: the turn's pivot is
    // the first end, so the other end of the 4-long bond moves sideways by 1.06e-5.
    const Quadric& down = flat.quadrics[2];
    EXPECT_EQ(down.kind, QuadricKind::Cylinder);
    expect_axis(down, Vec3(0, 5, 0), Vec3(0, 1, 0), 1.1e-5);

    // A cone's base at the first end, its apex at the second.
    const Quadric& cone = flat.quadrics[3];
    EXPECT_EQ(cone.kind, QuadricKind::Cone);
    EXPECT_EQ(cone.size, Vec3(0.8, 5, 0.8));
    expect_axis(cone, Vec3(1, 2, 3), Vec3(4, 6, 3), 1e-5);

    // The two-sided triangle with its normals, the line and the point with their colours.
    ASSERT_EQ(flat.meshes.size(), 1u);
    EXPECT_FALSE(flat.meshes[0].solid);
    EXPECT_EQ(flat.meshes[0].triangle_count(), 1u);
    EXPECT_EQ(flat.meshes[0].normals.size(), 3u);
    ASSERT_EQ(flat.segments.size(), 1u);
    EXPECT_EQ(flat.segments[0].a, Vec3(1, 2, 3));
    EXPECT_EQ(flat.segments[0].b, Vec3(4, 6, 3));
    EXPECT_EQ(flat.segments[0].color_a, Vec3(1, 1, 0));
    ASSERT_EQ(flat.points.size(), 1u);
    EXPECT_EQ(flat.points[0].color, Vec3(1, 0, 1));

    // The gradient background inside the Group is bound.
    EXPECT_TRUE(flat.background.present);
    ASSERT_EQ(flat.background.sky_colors.size(), 3u);
    EXPECT_EQ(flat.background.sky_angles.size(), 2u);
}

// VMD's VRML 1.0 export (VrmlDisplayDevice): one Separator; a Material before the shapes it colours
// (VRML 1.0 state: it holds until the next); an atom a Separator with a Translation and a Sphere; a
// bond a Separator with a MatrixTransform that maps the unit axis onto the bond (VMD's 4x4 printed
// column by column: the translation is the last four numbers) and a Cylinder with `parts SIDES`
// when open; lines and triangles as Coordinate3 + IndexedLineSet / IndexedFaceSet. The matrix is
// the one the writer makes for a = (1 2 3), b = (4 6 3), with float rounding's -2.62268e-08 in the
// row the cylinder's axis takes.
const char* const kVmdVrml1 = R"(#VRML V1.0 ascii
# Created with VMD: http://www.ks.uiuc.edu/Research/vmd/
Separator {
Material { 
diffuseColor 0.650000 0.000000 0.000000
ambientColor 0.000000 0.000000 0.000000
specularColor 0.500000 0.000000 0.000000
shininess 0.530000
transparency 0.000000
}
Separator {
Translation { translation 1.000000 2.000000 3.000000 }
Sphere { radius 0.500000 }
}
Separator {
Translation { translation 4.000000 6.000000 3.000000 }
Sphere { radius 0.250000 }
}
Material { 
diffuseColor 0.650000 0.650000 0.650000
ambientColor 0.000000 0.000000 0.000000
specularColor 0.500000 0.500000 0.500000
shininess 0.530000
transparency 0.000000
}
#push matrix
Separator {
MatrixTransform {
  matrix 0.8 -0.6 0 0
         0.6 0.8 -2.62268e-08 0
         0 0 1 0
         2.5 4 3 1
}
Cylinder { 
radius 0.200000
height 5.000000
parts SIDES}
#pop matrix
}
Coordinate3 {point [ 1.000000 2.000000 3.000000, 4.000000 6.000000 3.000000 ] }
IndexedLineSet { coordIndex [0, 1, -1] }
# That's all, folks
}
)";

TEST(VmdExport, Vrml1LayoutToo) {
    const testing::FlattenedText f = testing::flatten_scene_text(kVmdVrml1, "vmdscene.wrl");
    const FlatScene& flat = f.flat;
    ASSERT_EQ(flat.spheres.size(), 2u);
    EXPECT_EQ(flat.spheres[0].center, Vec3(1, 2, 3));
    EXPECT_EQ(flat.spheres[1].radius, 0.25);
    // The first Material colours both atoms; the second the bond.
    EXPECT_EQ(material_of(flat, flat.spheres[1].shading).diffuse, Vec3(0.65, 0, 0));
    ASSERT_EQ(flat.quadrics.size(), 1u);
    const Quadric& bond = flat.quadrics[0];
    EXPECT_EQ(material_of(flat, bond.shading).diffuse, Vec3(0.65));
    EXPECT_EQ(bond.kind, QuadricKind::Cylinder);
    EXPECT_TRUE(bond.side);
    EXPECT_FALSE(bond.top);
    EXPECT_FALSE(bond.bottom);
    // The matrix entries are exact decimals but for the 2.6e-8 term, which moves an end 2.5 from
    // the centre by 6.6e-8 along z.
    expect_axis(bond, Vec3(1, 2, 3), Vec3(4, 6, 3), 1e-7);
    ASSERT_EQ(flat.segments.size(), 1u);
    EXPECT_EQ(flat.segments[0].b, Vec3(4, 6, 3));
}

// VMD's X3D export (X3DDisplayDevice): an OrthoViewpoint with its four-number fieldOfView for an
// orthographic view, each atom and bond a Transform with the Appearance inline, bonds as a Cylinder
// turned about its first end as in the VRML 2.0 export, surfaces as an IndexedTriangleStripSet
// whose strips end at -1, normals printed with two decimals (not unit: 0.58 0.58 0.58), lines as a
// LineSet with LineProperties.
const char* const kVmdX3d = R"(<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 3.0//EN"
  "http://www.web3d.org/specifications/x3d-3.0.dtd">

<X3D version='3.2' profile='Interchange'>
<head>
  <meta name='description' content='VMD Molecular Graphics'/>
</head>
<Scene>
<!-- Created with VMD: -->
<!-- http://www.ks.uiuc.edu/Research/vmd/ -->
<OrthoViewpoint description="VMD Orthographic View" fieldOfView="-2.66667 -2 2.66667 2" orientation="0 0 -1 0" position="0 0 2" centerOfRotation="0 0 0" />
<Background skyColor='1 1 1'/>
<Transform translation='1 2 3'>
  <Shape>
  <Appearance><Material ambientIntensity='0' diffuseColor='0.65 0 0' shininess='0.53' specularColor='0.5 0.5 0.5' transparency='0' /></Appearance>
  <Sphere radius='0.5'/>
  </Shape>
</Transform>
<Transform translation='1 4.5 3' center='0.0 -2.5 0.0' rotation='0 0 1  -0.643501'>
  <Shape>
  <Appearance><Material ambientIntensity='0' diffuseColor='0.65 0.65 0.65' shininess='0.53' specularColor='0.5 0.5 0.5' transparency='0' /></Appearance>
    <Cylinder bottom='false' height='5' radius='0.2' side='true' top='false' />
  </Shape>
</Transform>
<Shape>
  <Appearance><Material ambientIntensity='0' diffuseColor='0.65 0.65 0.65' shininess='0.53' specularColor='0.5 0.5 0.5' transparency='0' /></Appearance>
  <IndexedTriangleStripSet solid='false' index='0 1 2 3 -1 4 5 6 -1 '>
    <Coordinate point=' 0 0 0, 1 0 0, 0 1 0, 1 1 0, 3 0 0, 4 0 0, 3 1 0'/>
    <Color color=' 0.000 0.000 1.000, 0.000 0.000 1.000, 0.000 0.000 1.000, 0.000 0.000 1.000, 0.000 1.000 0.000, 0.000 1.000 0.000, 0.000 1.000 0.000'/>
    <Normal vector=' 0.00 0.00 1.00, 0.00 0.00 1.00, 0.00 0.00 1.00, 0.58 0.58 0.58, 0.00 0.00 1.00, 0.00 0.00 1.00, 0.00 0.00 1.00'/>
  </IndexedTriangleStripSet>
</Shape>
<Shape>
  <Appearance><Material ambientIntensity='0' diffuseColor='0 0 0' emissiveColor='0 0 0' /><LineProperties linewidthScaleFactor="3" containerField="lineProperties"/>
</Appearance>
  <LineSet vertexCount='3'>    <Coordinate point=' -2 1.5 0, -1.5 1.8 0, -1 1.5 0'/>
  </LineSet>
</Shape>
</Scene>
</X3D>
)";

TEST(VmdExport, X3dLayoutToo) {
    const testing::FlattenedText f = testing::flatten_scene_text(kVmdX3d, "vmdscene.x3d");
    const FlatScene& flat = f.flat;
    ASSERT_EQ(flat.viewpoints.size(), 1u);
    EXPECT_TRUE(flat.viewpoints[0].ortho);
    EXPECT_EQ(flat.viewpoints[0].ortho_extent[0], -2.66667);
    EXPECT_EQ(flat.viewpoints[0].ortho_extent[3], 2.0);
    ASSERT_EQ(flat.spheres.size(), 1u);
    EXPECT_EQ(flat.spheres[0].center, Vec3(1, 2, 3));
    ASSERT_EQ(flat.quadrics.size(), 1u);
    EXPECT_FALSE(flat.quadrics[0].top);
    expect_axis(flat.quadrics[0], Vec3(1, 2, 3), Vec3(4, 6, 3), 1e-5);  // as in the VRML 2.0 test
    // Strips of 4 and 3 indices: 2 + 1 triangles, every corner with its colour and its normal made
    // unit (0.58 0.58 0.58 is 1.0046 long).
    ASSERT_EQ(flat.meshes.size(), 1u);
    const Mesh& strip = flat.meshes[0];
    EXPECT_EQ(strip.triangle_count(), 3u);
    EXPECT_FALSE(strip.solid);
    ASSERT_EQ(strip.colors.size(), 9u);
    ASSERT_EQ(strip.normals.size(), 9u);
    for (const Vec3& n : strip.normals) EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
    EXPECT_EQ(flat.segments.size(), 2u);  // the LineSet's three points
}

}  // namespace
}  // namespace vr

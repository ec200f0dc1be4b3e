// The field objects a Script sees (VRML97 Annex C, ISO/IEC 19777-1; docs/scripts.md): each
// method's result, sent out of initialize() as an MFFloat into a ScalarInterpolator's key, against
// values worked out by hand in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "parser/load.h"

namespace vr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// What `body` (the inside of initialize(), which assigns the MFFloat eventOut `out`) sends.
std::vector<double> numbers_of(const std::string& body) {
    LoadedScene scene = load_scene_text(
        "#VRML V2.0 utf8\n"
        "DEF SI ScalarInterpolator {}\n"
        "DEF S Script { eventOut MFFloat out url \"javascript: function initialize() { " +
            body +
            " }\" }\n"
            "ROUTE S.out TO SI.set_key\n",
        "fields.wrl");
    EXPECT_TRUE(scene.ok());
    Diagnostics diagnostics;
    Animator animator(scene.tree, diagnostics);
    EXPECT_EQ(diagnostics.warning_count(), 0u)
        << (diagnostics.all().empty() ? "" : diagnostics.all()[0].message);
    const FieldView key = scene.tree.get(scene.tree.roots[0], "key");
    return {key.numbers.begin(), key.numbers.end()};
}

void expect_near(const std::vector<double>& got, const std::vector<double>& want, double tol) {
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], tol) << "at " << i;
}

TEST(ScriptFields, Vec3fArithmetic) {
    // Small integers and halves: every result is exact in double precision.
    EXPECT_EQ(numbers_of("var a = new SFVec3f(1, 2, 3), b = new SFVec3f(4, 5, 6);"
                         "var s = a.add(b), d = a.subtract(b), m = a.multiply(2), q = a.divide(2),"
                         "    n = a.negate(), c = a.cross(b);"
                         "out = new MFFloat(s.x, s.y, s.z, d.x, d.y, d.z, m.x, m.y, m.z, q.x, q.y, "
                         "q.z, n.x, n.y, n.z, c.x, c.y, c.z, a.dot(b));"),
              // (5 7 9) (-3 -3 -3) (2 4 6) (.5 1 1.5) (-1 -2 -3);
              // cross: (2*6 - 3*5, 3*4 - 1*6, 1*5 - 2*4) = (-3, 6, -3); dot: 4 + 10 + 18 = 32.
              (std::vector<double>{5, 7, 9, -3, -3, -3, 2, 4, 6, 0.5, 1, 1.5, -1, -2, -3, -3, 6, -3,
                                   32}));
}

TEST(ScriptFields, LengthNormalizeAndIndexing) {
    // (3, 4, 0): length 5, unit (0.6, 0.8, 0); SFVec2f (3, 4) the same. Tolerance: one division
    // each, half an ulp of 0.8.
    expect_near(numbers_of("var v = new SFVec3f(3, 4, 0), u = v.normalize(), w = new SFVec2f(3, "
                           "4), wu = w.normalize();"
                           "v[2] = 7;"
                           "out = new MFFloat(v.length(), u.x, u.y, u.z, w.length(), wu[0], wu[1], "
                           "v.z, w.dot(new SFVec2f(1, 2)));"),
                // v[2] = 7 sets z; then v.length() is still computed before? No: after, so
                // sqrt(9 + 16 + 49) = sqrt(74).
                {std::sqrt(74.0), 0.6, 0.8, 0.0, 5.0, 0.6, 0.8, 7.0, 11.0}, 1e-15);
}

TEST(ScriptFields, RotationMethods) {
    // A quarter turn about +Z takes +X to +Y; its inverse takes +Y back to +X. r1.multiply(r2) is
    // r1 then r2: +X -> +Y (about Z), then +Y -> +Z (a quarter turn about +X). The halfway slerp
    // from no turn to a quarter turn about Z is an eighth turn: +X -> (cos pi/4, sin pi/4, 0). The
    // rotation from +X to +Y takes +X to +Y. Tolerance: sin and cos of pi/4 round, a few ulps.
    expect_near(
        numbers_of("var r = new SFRotation(0, 0, 1, Math.PI / 2), x = new SFVec3f(1, 0, 0);"
                   "var a = r.multVec(x), b = r.inverse().multVec(new SFVec3f(0, 1, 0));"
                   "var c = r.multiply(new SFRotation(1, 0, 0, Math.PI / 2)).multVec(x);"
                   "var d = new SFRotation(0, 0, 1, 0).slerp(r, 0.5).multVec(x);"
                   "var e = new SFRotation(x, new SFVec3f(0, 1, 0)).multVec(x);"
                   "var ax = new SFRotation(0, 0, 2, 1).getAxis();"
                   "out = new MFFloat(a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, "
                   "e.x, e.y, e.z, ax.x, ax.y, ax.z, r.angle, r[3]);"),
        {0, 1, 0, 1, 0, 0, 0, 0,       1,      std::cos(kPi / 4), std::sin(kPi / 4),
         0, 0, 1, 0, 0, 0, 2, kPi / 2, kPi / 2},
        1e-15);
}

TEST(ScriptFields, ColorHsv) {
    // setHSV(120, 1, 1) is pure green. (0.2, 0.4, 0.8): max 0.8 (blue), min 0.2, d 0.6; hue
    // 60 * ((r - g) / d + 4) = 60 * (4 - 1/3) = 220, saturation d / max = 0.75, value 0.8.
    expect_near(numbers_of("var c = new SFColor(0, 0, 0); c.setHSV(120, 1, 1);"
                           "var h = new SFColor(0.2, 0.4, 0.8).getHSV();"
                           "out = new MFFloat(c.r, c.g, c.b, h[0], h[1], h[2]);"),
                {0, 1, 0, 220, 0.75, 0.8}, 1e-13);  // the hue's division by 0.6 rounds
}

TEST(ScriptFields, ImageAndArrays) {
    // SFImage 2x1, one component: width, height, comp and the pixels; MF arrays index, grow by
    // push, and their length counts values (an MFVec3f of two vectors has length 2).
    EXPECT_EQ(numbers_of("var i = new SFImage(2, 1, 1, new MFInt32(255, 7));"
                         "var m = new MFVec3f(new SFVec3f(1, 2, 3));"
                         "m.push(new SFVec3f(4, 5, 6));"
                         "var f = new MFFloat(1.5, 2.5); f[2] = 3;"
                         "out = new MFFloat(i.width, i.height, i.comp, i.array[0], i.array[1], "
                         "m.length, m[1].y, f.length, f[2]);"),
              (std::vector<double>{2, 1, 1, 255, 7, 2, 5, 3, 3}));
}

TEST(ScriptFields, NodeFieldsAndBrowser) {
    // A node made from a string reads its fields; Browser names vrmlray; an SFNode's type name.
    EXPECT_EQ(numbers_of("var n = Browser.createVrmlFromString('Transform { translation 1 2 3 "
                         "}')[0];"
                         "var t = n.translation;"
                         "out = new MFFloat(t.x, t.y, t.z, Browser.getName() == 'vrmlray' ? 1 : 0,"
                         " n.getTypeName() == 'Transform' ? 1 : 0, n.scale.y,"
                         " Browser.createX3DFromString(\\\"<Transform translation='4 5 6'/>\\\")[0]"
                         ".translation.z);"),
              (std::vector<double>{1, 2, 3, 1, 1, 1, 6}));
}

TEST(ScriptFields, CurrentSceneReadsTheWorld) {
    // Titania's units.x3dv prints Browser.currentScene.toXMLString(): the scene's root nodes, a
    // node by its DEF name, and the world written out as `vrmlray convert` writes it.
    EXPECT_EQ(
        numbers_of("var s = Browser.currentScene, r = s.rootNodes;"
                   "var x = s.toXMLString(), v = s.toVRMLString();"
                   "out = new MFFloat(r.length, r[0].getTypeName() == 'ScalarInterpolator',"
                   " s.getNamedNode('SI').getTypeName() == 'ScalarInterpolator',"
                   " x.indexOf('<ScalarInterpolator DEF=') > 0, v.indexOf('DEF S Script') > 0,"
                   " s.worldURL == Browser.getWorldURL());"),
        (std::vector<double>{2, 1, 1, 1, 1, 1}));
}

}  // namespace
}  // namespace vr

// Recognising tessellated spheres (Jmol writes atoms as a USE'd IndexedFaceSet).
#include <gtest/gtest.h>

#include <cmath>

#include "flatten/flatten.h"
#include "geometry/sphere_fit.h"
#include "parser/load.h"
#include "scene/build.h"

namespace vr {
namespace {

// A latitude-longitude sphere with coordinates rounded to `decimals` places, as an exporter writes
// them.
std::vector<Vec3> uv_sphere(const Vec3& c, double r, int decimals, bool upper_half_only = false) {
    std::vector<Vec3> pts;
    const double q = std::pow(10.0, decimals);
    for (int i = 0; i <= 8; ++i) {
        const double theta = kPi * i / 8;
        if (upper_half_only && theta > kPi / 2) break;
        for (int j = 0; j < 12; ++j) {
            const double phi = 2 * kPi * j / 12;
            Vec3 p = c + r * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                  std::sin(theta) * std::sin(phi));
            for (int k = 0; k < 3; ++k) p[k] = std::nearbyint(p[k] * q) / q;
            pts.push_back(p);
        }
    }
    return pts;
}

TEST(SphereFit, RecognisesRoundedTessellations) {
    auto fit = fit_tessellated_sphere(uv_sphere(Vec3(1.5, -2.0, 0.25), 1.7, 4));
    ASSERT_TRUE(fit.has_value());
    // Rounding to 4 decimals moves points by <= 0.87e-4: the fitted centre and radius are that
    // close.
    EXPECT_NEAR(fit->radius, 1.7, 1e-4);
    EXPECT_NEAR(glm::length(fit->center - Vec3(1.5, -2.0, 0.25)), 0.0, 1e-4);
    EXPECT_EQ(written_decimals(uv_sphere(Vec3(0.0), 1.0, 3)), 3);
}

TEST(SphereFit, RejectsWhatIsNotAWholeSphere) {
    EXPECT_FALSE(
        fit_tessellated_sphere(uv_sphere(Vec3(0.0), 1.0, 6, true)).has_value());  // a hemisphere
    auto bumped = uv_sphere(Vec3(0.0), 1.0, 6);
    bumped[40].x +=
        0.01;  // one vertex off the sphere by far more than its 6 written decimals explain
    EXPECT_FALSE(fit_tessellated_sphere(bumped).has_value());
    std::vector<Vec3> cube;
    for (int i = 0; i < 8; ++i)
        cube.push_back(Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
    EXPECT_FALSE(fit_tessellated_sphere(cube).has_value());  // too few points to say
}

TEST(SphereFit, GasModeRendersJmolStyleAtomsAsSpheres) {
    std::string points;
    for (const Vec3& p : uv_sphere(Vec3(0.0), 1.0, 4))
        points +=
            std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + ", ";
    std::string faces;  // quads between neighbouring rings, so that every vertex is used
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 12; ++j)
            faces += std::to_string(i * 12 + j) + " " + std::to_string((i + 1) * 12 + j) + " " +
                     std::to_string((i + 1) * 12 + (j + 1) % 12) + " " +
                     std::to_string(i * 12 + (j + 1) % 12) + " -1 ";
    std::string text =
        "#VRML V2.0 utf8\nDEF A Shape { geometry IndexedFaceSet { coord Coordinate { point [" +
        points + "] } coordIndex [" + faces +
        "] } }\n"
        "Transform { translation 5 0 0 scale 2 2 2 children USE A }\n"
        "Transform { scale 1 2 1 children USE A }\n";
    LoadedScene loaded = load_scene_text(text, "jmol.wrl");
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics d;
    Scene scene = build_scene(loaded, d);
    FlattenOptions fo;
    fo.spheres = SpheresOption::Gas;
    FlattenStats stats;
    FlatScene flat = flatten_scene(scene, fo, d, stats);
    EXPECT_EQ(stats.recovered_spheres, 2u);  // the non-uniformly scaled one stays a mesh
    ASSERT_EQ(flat.spheres.size(), 2u);
    EXPECT_NEAR(flat.spheres[1].radius, 2.0, 2e-4);  // scale 2, rounding of 4 decimals
    EXPECT_NEAR(flat.spheres[1].center.x, 5.0, 2e-4);
    EXPECT_TRUE(flat.spheres[1].gas);
    fo.spheres = SpheresOption::Opaque;  // off by default outside gas mode
    FlattenStats opaque;
    (void)flatten_scene(scene, fo, d, opaque);
    EXPECT_EQ(opaque.recovered_spheres, 0u);
}

}  // namespace
}  // namespace vr

// Recognising tessellated cylinders along any axis (geometry/cylinder_fit.h): meshes generated at
// random orientations, written as exporters write them (rounded to a few decimals, or computed in
// single precision and printed), checked against the cylinder they were made from in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "flatten/flatten.h"
#include "geometry/cylinder_fit.h"
#include "geometry/shape_fit_util.h"
#include "parser/load.h"
#include "scene/build.h"
#include "scene/transform.h"

namespace vr {
namespace {

struct Spec {
    Vec3 centre{0.0};
    Vec3 direction{0.0, 1.0, 0.0};  // unit
    double radius = 1.0, height = 1.0;
    int segments = 20;
    bool bottom = false, top = false;
};

struct Mesh {
    std::vector<Vec3> points;
    std::vector<uint32_t> triangles;
};

// How the vertices are written: rounded to `decimals` places, or (decimals < 0) computed in single
// precision and printed with 6 decimals, as a float32 exporter baking world coordinates does.
Vec3 written(const Vec3& p, int decimals) {
    if (decimals < 0) {
        Vec3 out;
        for (int k = 0; k < 3; ++k) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.6f", double(float(p[k])));
            out[k] = std::strtod(buf, nullptr);
        }
        return out;
    }
    return round_to(p, decimals);
}

// Two rings of `segments` vertices (the first one at -direction), the side as quads split in two,
// and each closed end as a fan about a centre vertex. The frame across the axis is built from a
// different helper than the recogniser's, so that nothing lines up by construction.
Mesh cylinder_mesh(const Spec& s, int decimals) {
    const Vec3 d = s.direction;
    const Vec3 helper = std::abs(d.z) < 0.9 ? Vec3(0.0, 0.0, 1.0) : Vec3(1.0, 0.0, 0.0);
    const Vec3 u = glm::normalize(glm::cross(d, helper)), v = glm::cross(d, u);
    Mesh m;
    const uint32_t n = uint32_t(s.segments);
    for (int end = 0; end < 2; ++end)
        for (uint32_t j = 0; j < n; ++j) {
            const double phi = 2.0 * kPi * j / n;
            const Vec3 p = s.centre + (end ? 0.5 : -0.5) * s.height * d +
                           s.radius * (std::cos(phi) * u + std::sin(phi) * v);
            m.points.push_back(written(p, decimals));
        }
    for (uint32_t j = 0; j < n; ++j) {
        const uint32_t a = j, b = (j + 1) % n;
        m.triangles.insert(m.triangles.end(), {a, b, n + b, a, n + b, n + a});
    }
    for (int end = 0; end < 2; ++end) {
        if (!(end ? s.top : s.bottom)) continue;
        const uint32_t c = uint32_t(m.points.size());
        m.points.push_back(written(s.centre + (end ? 0.5 : -0.5) * s.height * d, decimals));
        for (uint32_t j = 0; j < n; ++j)
            m.triangles.insert(m.triangles.end(), {c, end * n + (j + 1) % n, end * n + j});
    }
    return m;
}

Vec3 random_direction(std::mt19937& rng) {
    std::normal_distribution<double> normal;
    Vec3 d;
    do d = Vec3(normal(rng), normal(rng), normal(rng));
    while (glm::length(d) < 1e-3);
    return glm::normalize(d);
}

// The error bound the recogniser allows a vertex (cylinder_fit.h): half a unit of the last
// decimal plus four float roundings, on three coordinates.
double vertex_error(const Mesh& m, int decimals) {
    double largest = 0.0;
    for (const Vec3& p : m.points)
        largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    const double half_unit = 0.5 * std::pow(10.0, -(decimals < 0 ? 6 : decimals));
    return std::sqrt(3.0) * (half_unit + std::ldexp(largest, -22));
}

void expect_matches(const CylinderFit& fit, const Spec& s, double error) {
    // The fitted axis may point either way; its top is then the spec's bottom.
    const double cos_angle = glm::dot(fit.direction, s.direction);
    const bool flipped = cos_angle < 0.0;
    // The ring centres are each within `error` of the true ones (a least-squares circle through
    // vertices that are), so the axis turns by at most 2 error / height.
    EXPECT_GE(std::abs(cos_angle), std::cos(4.0 * error / s.height));
    EXPECT_NEAR(fit.radius, s.radius, 2.0 * error);
    EXPECT_NEAR(fit.height, s.height, 4.0 * error);
    EXPECT_LE(glm::length(fit.center - s.centre), 2.0 * error);
    EXPECT_EQ(fit.top, flipped ? s.bottom : s.top);
    EXPECT_EQ(fit.bottom, flipped ? s.top : s.bottom);
    EXPECT_NEAR(glm::length(fit.direction), 1.0, 1e-12);
}

TEST(CylinderFit, SymmetricEigenvectorsDiagonalise) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> any(-3.0, 3.0);
    for (int trial = 0; trial < 50; ++trial) {
        Mat3 a;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j <= i; ++j) a[i][j] = a[j][i] = any(rng);
        const Mat3 v = symmetric_eigenvectors(a);
        const Mat3 d = glm::transpose(v) * a * v;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                EXPECT_NEAR(glm::dot(v[i], v[j]), i == j ? 1.0 : 0.0, 1e-12);
                if (i != j) {
                    EXPECT_NEAR(d[i][j], 0.0, 1e-12);
                }
            }
    }
}

// 300 cylinders at random orientations, proportions, tessellations, end caps and precisions,
// including the proportions where one source of axis candidates is ambiguous (capped with height
// 2r; height r*sqrt(2)).
TEST(CylinderFit, RandomOrientationsGiveTheCylinderTheyWereMadeFrom) {
    std::mt19937 rng(43);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int precisions[] = {4, 5, 6, -1};
    for (int trial = 0; trial < 300; ++trial) {
        Spec s;
        s.direction = random_direction(rng);
        s.radius = 0.2 + 1.8 * unit(rng);
        s.height = trial % 10 == 0   ? 2.0 * s.radius
                   : trial % 10 == 1 ? std::sqrt(2.0) * s.radius
                                     : 0.3 + 5.0 * unit(rng);
        s.segments = 12 + 4 * int(unit(rng) * 6);
        s.bottom = unit(rng) < 0.5, s.top = unit(rng) < 0.5;
        const int decimals = precisions[trial % 4];
        // Baked into world coordinates for the float32 case: far from the origin.
        s.centre = decimals < 0 ? Vec3(40.0 * unit(rng) - 20.0, 30.0 * unit(rng), -25.0)
                                : Vec3(unit(rng), unit(rng), unit(rng)) - 0.5;
        const Mesh m = cylinder_mesh(s, decimals);
        SCOPED_TRACE("trial " + std::to_string(trial));
        FitFailure why = FitFailure::OffSurface;
        const std::optional<CylinderFit> fit =
            fit_tessellated_cylinder(m.points, m.triangles, &why);
        EXPECT_TRUE(fit.has_value()) << fit_failure_label(why);
        if (!fit) continue;
        EXPECT_EQ(fit->axis, -1);  // a random direction is never one of the mesh's axes
        expect_matches(*fit, s, vertex_error(m, decimals));
    }
}

TEST(CylinderFit, ObliqueMeshesThatAreNotCylindersAreRefused) {
    Spec s;
    s.direction = glm::normalize(Vec3(1.0, 2.0, -0.5));
    s.radius = 0.4, s.height = 3.0, s.segments = 24, s.top = true;
    const Mesh good = cylinder_mesh(s, 5);
    ASSERT_TRUE(fit_tessellated_cylinder(good.points, good.triangles).has_value());
    FitFailure why;
    // One vertex off the side by ten times what its decimals explain.
    Mesh off = good;
    off.points[3] += 10.0 * vertex_error(good, 5) * glm::normalize(off.points[3] - s.centre);
    EXPECT_FALSE(fit_tessellated_cylinder(off.points, off.triangles, &why));
    EXPECT_EQ(why, FitFailure::OffSurface);
    // A cone frustum: the top ring 2% narrower.
    Mesh cone = good;
    const Vec3 top_centre = s.centre + 0.5 * s.height * s.direction;
    for (int j = 0; j < s.segments; ++j) {
        Vec3& p = cone.points[size_t(s.segments + j)];
        p = round_to(top_centre + 0.98 * (p - top_centre), 5);
    }
    EXPECT_FALSE(fit_tessellated_cylinder(cone.points, cone.triangles));
    // An elliptic tube: squashed by 1% across the axis.
    Mesh squashed = good;
    const Vec3 across = glm::normalize(glm::cross(s.direction, Vec3(0.0, 0.0, 1.0)));
    for (Vec3& p : squashed.points)
        p = round_to(p - 0.01 * glm::dot(p - s.centre, across) * across, 5);
    EXPECT_FALSE(fit_tessellated_cylinder(squashed.points, squashed.triangles));
    // A side with every other quad missing.
    Mesh gaps = good;
    for (size_t q = 0; q < size_t(s.segments); q += 2)
        for (size_t k = 0; k < 6; ++k) gaps.triangles[6 * q + k] = 0;
    EXPECT_FALSE(fit_tessellated_cylinder(gaps.points, gaps.triangles, &why));
    EXPECT_EQ(why, FitFailure::NotAllAround);
    // Written with too few decimals for a thin tube.
    Spec thin = s;
    thin.radius = 0.05;
    const Mesh coarse = cylinder_mesh(thin, 4);
    EXPECT_FALSE(fit_tessellated_cylinder(coarse.points, coarse.triangles, &why));
    EXPECT_EQ(why, FitFailure::CoarselyWritten);
}

// The renderer's recovery places an oblique cylinder with its top disc where the mesh's is: the
// quadric's object (0, height/2, 0) maps onto the top ring's centre, by a turn (no mirror).
TEST(CylinderFit, RendererPlacesAnObliqueCylinderWhereTheMeshIs) {
    Spec s;
    s.direction = glm::normalize(Vec3(-0.3, 0.8, 0.52));
    s.centre = Vec3(1.5, -2.0, 0.25);
    s.radius = 0.3, s.height = 2.5, s.segments = 16, s.top = true;
    const Mesh m = cylinder_mesh(s, 6);
    std::string points, faces;
    char buf[96];
    for (const Vec3& p : m.points) {
        std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f, ", p.x, p.y, p.z);
        points += buf;
    }
    for (size_t t = 0; t < m.triangles.size(); t += 3)
        faces += std::to_string(m.triangles[t]) + " " + std::to_string(m.triangles[t + 1]) + " " +
                 std::to_string(m.triangles[t + 2]) + " -1 ";
    const std::string text =
        "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord Coordinate { point [" + points +
        "] } coordIndex [" + faces + "] } }\n";
    LoadedScene loaded = load_scene_text(text, "oblique.wrl");
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions options;
    options.spheres = SpheresOption::Opaque;
    options.recover_spheres = true;
    FlattenStats stats;
    const FlatScene flat = flatten_scene(scene, options, diagnostics, stats);
    ASSERT_EQ(stats.recovered_cylinders, 1u);
    const Quadric& q = flat.quadrics.at(0);
    EXPECT_TRUE(q.top);
    EXPECT_FALSE(q.bottom);
    const double error = vertex_error(m, 6);
    // Object space holds the cylinder of q.size: (2 radius, height, 2 radius).
    const Vec3 top = Vec3(q.world_from_object * Vec4(0.0, 0.5 * q.size.y, 0.0, 1.0));
    EXPECT_LE(glm::length(top - (s.centre + 0.5 * s.height * s.direction)), 4.0 * error);
    const Vec3 rim = Vec3(q.world_from_object * Vec4(0.5 * q.size.x, 0.0, 0.0, 1.0));
    EXPECT_NEAR(glm::length(rim - s.centre), s.radius, 4.0 * error);
    EXPECT_GT(glm::determinant(Mat3(q.world_from_object)), 0.0);
}

}  // namespace
}  // namespace vr

// Transform arithmetic: the VRML Transform matrix against a hand-computed one, rotations,
// TextureTransform.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "scene/transform.h"

namespace vr {
namespace {

// Entries are sums of a few products of small exact numbers and sin/cos of 90 degrees, which differ
// from 0 and 1 by about 1e-16: 1e-12 leaves room for that and nothing else.
constexpr double kTight = 1e-12;

void expect_near(const Mat4& a, const Mat4& b, double tolerance) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            EXPECT_NEAR(a[c][r], b[c][r], tolerance) << "column " << c << " row " << r;
}

TEST(SceneTransform, ComposesTCRSRSInverseSRInverseC) {
    TransformFields f;
    f.translation = Vec3(1, 2, 3);
    f.center = Vec3(1, 0, 0);
    f.rotation = Vec4(0, 0, 1, kPi / 2);
    f.scale = Vec3(2, 1, 1);
    f.scale_orientation = Vec4(0, 0, 1, kPi / 2);
    // By hand: p - C = (x-1, y, z); SR^-1 turns -90 deg about z, S doubles x, SR turns back:
    // together they double y -> (x-1, 2y, z); R turns +90 deg about z -> (-2y, x-1, z); + C ->
    // (1-2y, x-1, z); + T -> (2-2y, x+1, z+3).
    Mat4 expected(0.0);
    // glm is column-major: expected[column][row]
    expected[0] = Vec4(0, 1, 0, 0);   // d/dx
    expected[1] = Vec4(-2, 0, 0, 0);  // d/dy
    expected[2] = Vec4(0, 0, 1, 0);   // d/dz
    expected[3] = Vec4(2, 1, 3, 1);   // image of the origin
    expect_near(transform_matrix(f), expected, kTight);
}

// transform_matrix skips the products for a Transform that only translates: its result must be
// the products' bit for bit, zeros' signs included, for any translation.
TEST(SceneTransform, TranslationOnlyShortcutMatchesTheProductsExactly) {
    auto by_products = [](const TransformFields& f) {
        auto translation4 = [](const Vec3& t) {
            Mat4 m(1.0);
            m[3] = Vec4(t, 1.0);
            return m;
        };
        const Mat3 sr = rotation_matrix(f.scale_orientation);
        Mat4 S(1.0);
        S[0][0] = f.scale.x;
        S[1][1] = f.scale.y;
        S[2][2] = f.scale.z;
        return translation4(f.translation) * translation4(f.center) *
               Mat4(rotation_matrix(f.rotation)) * Mat4(sr) * S * Mat4(glm::transpose(sr)) *
               translation4(-f.center);
    };
    uint64_t state = 12345;
    auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        const double u = double(state >> 11) * 0x1.0p-53;
        return (u - 0.5) * std::pow(10.0, double(int(state % 13)) - 6.0);
    };
    const double specials[] = {0.0, -0.0, 1.0, -1.0, 1e-300, -1e300, 3.0e-320};
    for (int i = 0; i < 2000; ++i) {
        TransformFields f;
        f.translation = Vec3(next(), next(), next());
        if (i < 343)
            f.translation = Vec3(specials[i % 7], specials[i / 7 % 7], specials[i / 49 % 7]);
        const Mat4 fast = transform_matrix(f), slow = by_products(f);
        ASSERT_EQ(std::memcmp(&fast, &slow, sizeof(Mat4)), 0)
            << f.translation.x << " " << f.translation.y << " " << f.translation.z;
    }
}

TEST(SceneTransform, RotationAxisNeedNotBeUnitAndZeroAxisIsIdentity) {
    const Mat3 a = rotation_matrix(Vec3(0, 0, 5), kPi / 2);
    const Vec3 x = a * Vec3(1, 0, 0);
    EXPECT_NEAR(x.x, 0.0, kTight);
    EXPECT_NEAR(x.y, 1.0, kTight);
    const Mat3 identity = rotation_matrix(Vec3(0, 0, 0), 1.0);
    EXPECT_EQ(identity, Mat3(1.0));
    const Mat3 nan_axis = rotation_matrix(Vec3(std::nan(""), 0, 1), 1.0);
    EXPECT_EQ(nan_axis, Mat3(1.0));
}

TEST(SceneTransform, TextureTransformOrder) {
    // Tc' = -C * S * R * C * T * Tc: T first. With C = 0, R = 0, S = 2, T = (0.5, 0): (0,0) -> (1,
    // 0).
    const Mat3 m = texture_transform_matrix(Vec2(0.0), 0.0, Vec2(2.0), Vec2(0.5, 0.0));
    const Vec3 p = m * Vec3(0, 0, 1);
    EXPECT_NEAR(p.x, 1.0, kTight);
    EXPECT_NEAR(p.y, 0.0, kTight);
    // Rotation 90 deg about centre (0.5, 0.5): the corner (1, 0.5) goes to (0.5, 1).
    const Mat3 r = texture_transform_matrix(Vec2(0.5), kPi / 2, Vec2(1.0), Vec2(0.0));
    const Vec3 q = r * Vec3(1, 0.5, 1);
    EXPECT_NEAR(q.x, 0.5, kTight);
    EXPECT_NEAR(q.y, 1.0, kTight);
}

TEST(SceneTransform, UniformScaleAndSingularity) {
    TransformFields f;
    f.rotation = Vec4(1, 2, 3, 0.7);
    f.scale = Vec3(3.0);
    const Mat4 m = transform_matrix(f);
    EXPECT_NEAR(uniform_scale(linear_part(m)), 3.0, kTight);
    f.scale = Vec3(3, 3, 1);
    EXPECT_EQ(uniform_scale(linear_part(transform_matrix(f))), 0.0);
    EXPECT_FALSE(is_singular(transform_matrix(f)));
    f.scale = Vec3(1, 0, 1);
    EXPECT_TRUE(is_singular(transform_matrix(f)));
    f.scale = Vec3(1e-9, 1e-9, 1e-9);  // tiny but not singular: the test is scale-free
    EXPECT_FALSE(is_singular(transform_matrix(f)));
    Mat4 bad(1.0);
    bad[3][0] = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(is_singular(bad));
}

}  // namespace
}  // namespace vr

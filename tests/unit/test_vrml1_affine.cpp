// The VRML 1.0 upgrade's matrix decomposition: any affine matrix is one VRML97 Transform.
#include <gtest/gtest.h>

#include <random>

#include "parser/vrml1_affine.h"
#include "test_vrml1_support.h"

using namespace vr::vrml1;

namespace {

double max_difference(const Affine& a, const Affine& b) {
    double d = 0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(a.m[r][c] - b.m[r][c]));
    return d;
}

Affine random_affine(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-3, 3);
    Affine a;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a.m[r][c] = u(rng);
    return a;
}

}  // namespace

TEST(Vrml1Affine, ComposeMatchesIndependentTransform) {
    TransformFields f;
    f.translation = {1, 2, 3};
    f.rotation = {0, 1, 0, 0.7};
    f.scale = {2, 3, 0.5};
    f.scale_orientation = {1, 0, 0, 0.4};
    const Vec3d c{0.5, -1, 2};
    const Affine a = compose(f, c);
    using namespace vrml1_test;
    const Mat m =
        mul(mul(mul(mul(mul(mul(translate(1, 2, 3), translate(0.5, -1, 2)), rotate(0, 1, 0, 0.7)),
                        rotate(1, 0, 0, 0.4)),
                    scale(2, 3, 0.5)),
                rotate(1, 0, 0, -0.4)),
            translate(-0.5, 1, -2));
    for (int r = 0; r < 3; ++r)
        for (int col = 0; col < 4; ++col) EXPECT_NEAR(a.m[r][col], m[r][col], 1e-14);
}

// Random matrices have shear and, half the time, a mirror: decompose then compose gives them back.
TEST(Vrml1Affine, DecomposeRoundTripsGeneralMatrices) {
    std::mt19937 rng(12345);
    for (int i = 0; i < 2000; ++i) {
        const Affine a = random_affine(rng);
        const TransformFields f = decompose(a);
        EXPECT_LT(max_difference(compose(f), a), 1e-12) << "matrix " << i;
        const double axis =
            std::sqrt(f.rotation[0] * f.rotation[0] + f.rotation[1] * f.rotation[1] +
                      f.rotation[2] * f.rotation[2]);
        EXPECT_NEAR(axis, 1.0, 1e-12);
        // A mirror keeps its sign in the scale.
        EXPECT_EQ(a.determinant() < 0, f.scale[0] * f.scale[1] * f.scale[2] < 0);
    }
}

TEST(Vrml1Affine, SimpleMatricesStaySimple) {
    // A rotation gets no scale; a rotation with a uniform or axis-aligned scale gets no
    // scaleOrientation.
    const double r[4] = {1, 2, 3, 0.9};
    TransformFields f = decompose(rotation(r));
    EXPECT_EQ(f.scale, (Vec3d{1, 1, 1}));
    EXPECT_EQ(f.scale_orientation[3], 0);
    f = decompose(rotation(r) * scaling(2, 2, 2));
    EXPECT_NEAR(f.scale[0], 2, 1e-12);
    EXPECT_EQ(f.scale_orientation[3], 0);
    f = decompose(translation(1, 2, 3) * scaling(1, 2, 3));
    EXPECT_NEAR(f.scale[0], 1, 1e-12);
    EXPECT_NEAR(f.scale[1], 2, 1e-12);
    EXPECT_NEAR(f.scale[2], 3, 1e-12);
    EXPECT_EQ(f.rotation[3], 0);
    EXPECT_EQ(f.scale_orientation[3], 0);
    EXPECT_EQ(f.translation, (Vec3d{1, 2, 3}));
    // A mirror.
    f = decompose(scaling(1, -1, 1));
    EXPECT_LT(max_difference(compose(f), scaling(1, -1, 1)), 1e-12);
}

TEST(Vrml1Affine, SingularMatricesGiveAZeroScale) {
    Affine flat = scaling(2, 0, 1) * rotation(std::array<double, 4>{0, 0, 1, 0.3}.data());
    TransformFields f = decompose(flat);
    EXPECT_LT(max_difference(compose(f), flat), 1e-12);
    EXPECT_EQ(std::min({std::abs(f.scale[0]), std::abs(f.scale[1]), std::abs(f.scale[2])}), 0.0);
    Affine zero = scaling(0, 0, 0);
    f = decompose(zero);
    EXPECT_EQ(f.scale, (Vec3d{0, 0, 0}));
}

TEST(Vrml1Affine, AxisAngleOfHalfTurn) {
    const double r[4] = {0, 1, 0, 3.141592653589793};
    const Affine a = rotation(r);
    double m[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m[i][j] = a.m[i][j];
    auto aa = axis_angle(m);
    EXPECT_NEAR(std::abs(aa[1]), 1, 1e-12);
    EXPECT_NEAR(aa[3], 3.141592653589793, 1e-12);
}

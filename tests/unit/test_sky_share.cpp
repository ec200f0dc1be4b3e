// The sky light shared between neighbouring pixels (docs/rendering.md, "Sharing the sky light
// between pixels"): the lattice's interpolation and its refusals, and whole renders whose pixels
// keep the --light-tolerance bound against the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/render.h"
#include "render/sampling.h"
#include "render/sky_share.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

// A 2 x 2 lattice of spacing 4 on the plane z = 0 (world x, y = image x, y), normals +z, one
// surface, A = a00, a10, a01, a11 at the corners.
SkyShareTile square(double a00, double a10, double a01, double a11) {
    SkyShareTile t;
    t.spacing = 4;
    t.cols = t.rows = 2;
    const double a[4] = {a00, a10, a01, a11};
    for (int k = 0; k < 4; ++k) {
        SkyShareNode n;
        n.valid = true;
        n.surface = 7;
        n.p = Vec3(4.0 * (k % 2), 4.0 * (k / 2), 0.0);
        n.ns = Vec3(0.0, 0.0, 1.0);
        n.a = a[k];
        t.nodes.push_back(n);
    }
    return t;
}

TEST(SkyShare, InterpolatesBilinearlyBetweenCornersOnOneSurface) {
    const SkyShareTile t = square(0.50, 0.51, 0.52, 0.53);
    double a = -1.0;
    // (1, 3): u = 1/4, v = 3/4; 0.25 (0.75 0.50 + 0.25 0.51) + 0.75 (0.75 0.52 + 0.25 0.53).
    ASSERT_TRUE(sky_share_interpolate(t, 1.0, 3.0, 7, Vec3(1.0, 3.0, 0.0), Vec3(0, 0, 1), 0.05, a));
    EXPECT_NEAR(a, 0.5175, 1e-15);
    ASSERT_TRUE(sky_share_interpolate(t, 4.0, 4.0, 7, Vec3(4.0, 4.0, 0.0), Vec3(0, 0, 1), 0.05, a));
    EXPECT_NEAR(a, 0.53, 1e-15);
}

TEST(SkyShare, RefusesWhereTheCornersOrTheSampleDisagree) {
    const Vec3 up(0.0, 0.0, 1.0), p(2.0, 2.0, 0.0);
    double a = 0.0;
    // Estimates further apart than the spread allowed.
    EXPECT_FALSE(sky_share_interpolate(square(0.50, 0.60, 0.50, 0.50), 2, 2, 7, p, up, 0.05, a));
    // Another surface than the sample's.
    EXPECT_FALSE(sky_share_interpolate(square(0.5, 0.5, 0.5, 0.5), 2, 2, 8, p, up, 0.05, a));
    // Two corners off the sample's surface, or two that met nothing lit: a silhouette across the
    // square's middle leaves too little to interpolate from.
    SkyShareTile t = square(0.5, 0.5, 0.5, 0.5);
    t.nodes[2].surface = t.nodes[3].surface = 8;
    EXPECT_FALSE(sky_share_interpolate(t, 2, 2, 7, p, up, 0.05, a));
    t = square(0.5, 0.5, 0.5, 0.5);
    t.nodes[0].valid = t.nodes[3].valid = false;
    EXPECT_FALSE(sky_share_interpolate(t, 2, 2, 7, p, up, 0.05, a));
    // A crease: the sample's normal 70 degrees off the corners' (cos 0.342 < 0.5).
    const Vec3 tilted(std::sin(70.0 * kPi / 180.0), 0.0, std::cos(70.0 * kPi / 180.0));
    EXPECT_FALSE(sky_share_interpolate(square(0.5, 0.5, 0.5, 0.5), 2, 2, 7, p, tilted, 0.05, a));
    // A fold: the sample 1 above the corners' plane at 2.8 from each (slope 0.35 > 0.3).
    EXPECT_FALSE(
        sky_share_interpolate(square(0.5, 0.5, 0.5, 0.5), 2, 2, 7, Vec3(2, 2, 1), up, 0.05, a));
    // The same sample on the plane is shared.
    EXPECT_TRUE(sky_share_interpolate(square(0.5, 0.5, 0.5, 0.5), 2, 2, 7, p, up, 0.05, a));
}

// One corner off the sample's surface (a silhouette or a ribbon's edge crossing the square), lit
// by nothing, or across a crease: the other three corners' bilinear weights, scaled to add up to
// 1, where they add up to at least 3/4.
TEST(SkyShare, InterpolatesBetweenThreeCornersWhereTheFourthIsElsewhere) {
    const Vec3 up(0.0, 0.0, 1.0);
    const Vec3 tilted(std::sin(70.0 * kPi / 180.0), 0.0, std::cos(70.0 * kPi / 180.0));
    for (int how = 0; how < 3; ++how) {
        SkyShareTile t = square(0.50, 0.51, 0.52, 0.90);
        if (how == 0) t.nodes[3].surface = 8;
        if (how == 1) t.nodes[3].valid = false;
        if (how == 2) t.nodes[3].ns = tilted;
        EXPECT_EQ(sky_share_square_corners(t, 0, 0), 7u) << how;
        EXPECT_FALSE(sky_share_square_may_share(t, 0, 0)) << how;
        double a = -1.0;
        // (1, 1): u = v = 1/4; weights 9/16, 3/16, 3/16 of 15/16.
        ASSERT_TRUE(sky_share_interpolate(t, 1.0, 1.0, 7, Vec3(1, 1, 0), up, 0.05, a)) << how;
        EXPECT_NEAR(a, (9.0 * 0.50 + 3.0 * 0.51 + 3.0 * 0.52) / 15.0, 1e-15) << how;
        // (2, 2): the three corners' weights add up to 3/4 (the least allowed), equal.
        ASSERT_TRUE(sky_share_interpolate(t, 2.0, 2.0, 7, Vec3(2, 2, 0), up, 0.05, a)) << how;
        EXPECT_NEAR(a, (0.50 + 0.51 + 0.52) / 3.0, 1e-15) << how;
        // (3, 3): the corner left out weighs 9/16 > 1/4: not interpolated.
        EXPECT_FALSE(sky_share_interpolate(t, 3.0, 3.0, 7, Vec3(3, 3, 0), up, 0.05, a)) << how;
    }
    // Four corners on one surface but one across a crease from two others: the sample takes the
    // three that agree with each other and with it.
    SkyShareTile t = square(0.50, 0.51, 0.52, 0.53);
    const double s40 = std::sin(40.0 * kPi / 180.0), c40 = std::cos(40.0 * kPi / 180.0);
    t.nodes[0].ns = Vec3(0.0, -s40, c40);  // 80 degrees from corner 1's: corners 0 and 1 disagree
    t.nodes[1].ns = Vec3(0.0, s40, c40);
    EXPECT_EQ(sky_share_square_corners(t, 0, 0), 15u);  // both triples agree
    double a = -1.0;
    // (3, 0.3), nearer corner 1 than corner 0: corner 0 is left out. u = 0.75, v = 0.075:
    // weights 0.69375 (corner 1), 0.01875 (corner 2), 0.05625 (corner 3), 0.76875 in all.
    ASSERT_TRUE(sky_share_interpolate(t, 3.0, 0.3, 7, Vec3(3.0, 0.3, 0), up, 0.05, a));
    EXPECT_NEAR(a, (0.69375 * 0.51 + 0.01875 * 0.52 + 0.05625 * 0.53) / 0.76875, 1e-15);
    // (2.5, 0.3): the three weigh 0.653125 in all, less than 3/4: not interpolated.
    EXPECT_FALSE(sky_share_interpolate(t, 2.5, 0.3, 7, Vec3(2.5, 0.3, 0), up, 0.05, a));
}

// A plane of triangles (the sampling path) z = 0 under a sphere of radius r resting on it at
// (x, 0, r), seen from above by an orthographic camera with rgss: each pixel shows the mean of A
// over its 4 samples (diffuse 1, sky 1, no other light).
struct RestingSphere {
    FlatScene scene = empty_scene();
    Camera camera;
    RenderOptions options;
    double r = 0.6, x = 0.4;
    int width = 64, height = 48;
    RestingSphere(double tolerance, int share) {
        Material white;
        white.diffuse = Vec3(1.0);
        const uint32_t shading = add_shading(scene, white);
        testing::add_quad(scene, Vec3(-20, -20, 0), Vec3(20, -20, 0), Vec3(20, 20, 0),
                          Vec3(-20, 20, 0), shading);
        add_sphere(scene, Vec3(x, 0.0, r), r, shading);
        camera.ortho = true;
        camera.position = Vec3(0.0, 0.0, 10.0);
        camera.ortho_size = 3.0;
        camera.sampler.kind = SamplerKind::Rgss;
        options.width = width;
        options.height = height;
        options.sky = Vec3(1.0);
        options.light_tolerance = tolerance;
        options.sampler = SamplerKind::Rgss;
        options.spp = 4;
        options.threads = 2;
        options.sky_share = share;
    }
    // The pixel's exact mean of A, or a negative value when a sample of it sees the sphere.
    double exact_pixel(int px, int py) const {
        const CameraRays rays(camera, width, height);
        PixelSampler sampler = camera.sampler;
        std::vector<Vec2> offsets;
        fixed_offsets(sampler, px, py, offsets);
        double sum = 0.0;
        for (const Vec2& o : offsets) {
            const Ray ray = rays(px + o.x, py + o.y);
            const Vec3 p = ray.o + (-ray.o.z / ray.d.z) * ray.d;  // on z = 0
            const Vec3 c(x, 0.0, r), to_c = c - p;
            if (std::hypot(p.x - x, p.y) <= r * 1.05) return -1.0;  // under the sphere
            const double d = glm::length(to_c);
            // docs/rendering.md, Soft light with error bounds: 1 - (r/d)^2 cos(theta).
            sum += 1.0 - (r / d) * (r / d) * (to_c.z / d);
        }
        return sum / double(offsets.size());
    }
};

TEST(SkyShare, SharedPixelsKeepTheBoundAgainstTheClosedFormOnAContactShadow) {
    for (double e : {3e-2, 1e-2}) {
        RestingSphere shared(e, RenderOptions().sky_share), alone(e, 1);  // the default
        RenderStats s_shared, s_alone;
        const Image image =
            render_image(shared.scene, shared.camera, shared.options, nullptr, s_shared);
        render_image(alone.scene, alone.camera, alone.options, nullptr, s_alone);
        int plane_pixels = 0, within = 0;
        double worst = 0.0;
        for (int y = 0; y < shared.height; ++y)
            for (int x = 0; x < shared.width; ++x) {
                const double exact = shared.exact_pixel(x, y);
                if (exact < 0.0) continue;
                ++plane_pixels;
                const double err = std::abs(image.pixel(x, y)[0] - exact);
                worst = std::max(worst, err);
                within += err <= e ? 1 : 0;
            }
        ASSERT_GT(plane_pixels, shared.width * shared.height / 2);
        // The pixel rule's confidence is 99% a pixel; the interpolation holds its half of E where
        // it is allowed (at most one pixel in 50 outside E, against the closed form).
        EXPECT_GE(within, plane_pixels - plane_pixels / 50) << "E " << e << " worst " << worst;
        // Sharing did happen (on the open plane; not by the contact, where the corners' A differ
        // by more than E), and it saved rays, lattice points included.
        EXPECT_GT(s_shared.soft.shared_points, uint64_t(plane_pixels / 2)) << "E " << e;
        EXPECT_LT(s_shared.soft.rays, s_alone.soft.rays) << "E " << e;
        EXPECT_EQ(s_shared.soft.unconverged, 0u);
    }
}

TEST(SkyShare, SharedRenderIsTheSameForEveryThreadCount) {
    RestingSphere one(3e-2, 4);
    one.options.threads = 1;
    RestingSphere three = one;
    three.options.threads = 3;
    RenderStats s1, s3;
    const Image a = render_image(one.scene, one.camera, one.options, nullptr, s1);
    const Image b = render_image(three.scene, three.camera, three.options, nullptr, s3);
    ASSERT_GT(s1.soft.shared_points, 0u);
    EXPECT_EQ(s1.soft.shared_points, s3.soft.shared_points);
    EXPECT_EQ(a.rgba, b.rgba);
}

}  // namespace
}  // namespace vr

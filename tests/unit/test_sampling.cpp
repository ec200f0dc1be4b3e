// The pixel samplers (docs/manual.md, Samplers): where each puts its samples, how it weighs them,
// and how fast its error falls on pixels whose exact value is known (a half-plane edge through the
// pixel, a disc of known area).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "render/render.h"
#include "render/sampling.h"
#include "test_render_util.h"

namespace vr {
namespace {

PixelSampler sampler_for(const std::string& name, int spp, uint64_t seed = 0) {
    RenderOptions o;
    o.sampler = *sampler_kind(name);
    o.spp = spp;
    o.seed = seed;
    PixelSampler s;
    std::string error;
    EXPECT_TRUE(make_sampler(o, s, error)) << name << " " << spp << ": " << error;
    return s;
}

SampleValue value(double v) {
    SampleValue s;
    s.color = Vec3(v);
    s.alpha = v;
    return s;
}

// One pixel (0, 0) through the tile interface; counts the traced rays.
template <class F>
SampleValue one_pixel(const PixelSampler& s, F f, int* rays = nullptr, int px = 0, int py = 0) {
    SamplerScratch scratch;
    SampleValue out;
    int count = 0;
    sample_tile(
        s, px, py, px + 1, py + 1, scratch,
        [&](double x, double y) {
            ++count;
            return value(f(x - px, y - py));
        },
        [&](int, int, const SampleValue& v) { out = v; });
    if (rays) *rays = count;
    return out;
}

TEST(Sampling, Options) {
    RenderOptions o;
    PixelSampler s;
    std::string error;
    auto ok = [&](const char* name, int spp) {
        o.sampler = *sampler_kind(name);
        o.spp = spp;
        return make_sampler(o, s, error);
    };
    EXPECT_TRUE(ok("center", 1));
    EXPECT_EQ(s.kind, SamplerKind::Center);
    EXPECT_TRUE(ok("center", 4));  // center with spp > 1 is the grid
    EXPECT_EQ(s.kind, SamplerKind::Grid);
    EXPECT_FALSE(ok("grid", 5));
    EXPECT_NE(error.find("square number"), std::string::npos);
    EXPECT_FALSE(ok("jitter", 8));
    EXPECT_TRUE(ok("rgss", 1));
    EXPECT_EQ(s.fixed_samples_per_pixel(), 4);
    EXPECT_TRUE(ok("rgss", 36));
    EXPECT_EQ(s.n, 3);
    EXPECT_FALSE(ok("rgss", 8));
    EXPECT_TRUE(ok("rooks8", 32));
    EXPECT_EQ(s.fixed_samples_per_pixel(), 32);
    EXPECT_FALSE(ok("rooks8", 16));
    EXPECT_FALSE(ok("quincunx", 4));
    EXPECT_TRUE(ok("adaptive", 1));
    EXPECT_TRUE(ok("statistical", 1));
    EXPECT_EQ(s.max_samples, 256);
    EXPECT_TRUE(ok("statistical", 64));
    EXPECT_EQ(s.max_samples, 64);
    EXPECT_FALSE(ok("statistical", 8));   // below the stratified first set
    EXPECT_FALSE(sampler_kind("bogus"));  // the command line refuses it before make_sampler
}

TEST(Sampling, FixedPatternsCountAndPlace) {
    std::vector<Vec2> p;
    fixed_offsets(sampler_for("center", 1), 0, 0, p);
    ASSERT_EQ(p.size(), 1u);
    EXPECT_EQ(p[0], Vec2(0.5, 0.5));

    fixed_offsets(sampler_for("grid", 9), 0, 0, p);
    ASSERT_EQ(p.size(), 9u);
    EXPECT_DOUBLE_EQ(p[0].x, 1.0 / 6.0);
    EXPECT_DOUBLE_EQ(p[8].y, 5.0 / 6.0);

    for (auto [name, spp] :
         {std::pair{"rgss", 4}, {"rgss", 16}, {"rooks8", 8}, {"rooks8", 72}, {"jitter", 64}}) {
        const PixelSampler s = sampler_for(name, spp, 7);
        fixed_offsets(s, 3, 5, p);
        ASSERT_EQ(int(p.size()), spp) << name;
        for (const Vec2& o : p) {
            EXPECT_GE(o.x, 0.0);
            EXPECT_LT(o.x, 1.0);
            EXPECT_GE(o.y, 0.0);
            EXPECT_LT(o.y, 1.0);
        }
    }
}

// rgss and rooks8: inside every tile cell each row and each column of the pattern's lattice (4 x 4
// and 8 x 8) holds exactly one sample -- the property that smooths near-horizontal and
// near-vertical edges as well as a 4 x 4 (8 x 8) grid would with a quarter (an eighth) of the
// samples.
TEST(Sampling, RooksPatternsHaveOneSamplePerRowAndColumn) {
    for (auto [name, base] : {std::pair{"rgss", 4}, {"rooks8", 8}}) {
        for (int m : {1, 2, 3}) {
            const PixelSampler s = sampler_for(name, base * m * m);
            std::vector<Vec2> p;
            fixed_offsets(s, 0, 0, p);
            const int lattice = base * m;  // rows across the pixel
            std::set<int> rows, cols;
            for (const Vec2& o : p) {
                rows.insert(int(std::floor(o.y * lattice)) + lattice * int(std::floor(o.x * m)));
                cols.insert(int(std::floor(o.x * lattice)) + lattice * int(std::floor(o.y * m)));
            }
            EXPECT_EQ(int(rows.size()), base * m * m) << name << " m=" << m;
            EXPECT_EQ(int(cols.size()), base * m * m) << name << " m=" << m;
        }
    }
}

// Jitter: one sample in each of the n x n cells, placed differently in every pixel and for every
// seed, the same for the same (seed, pixel).
TEST(Sampling, JitterIsStratifiedAndDeterministic) {
    const PixelSampler s = sampler_for("jitter", 16, 42);
    std::vector<Vec2> a, b, c, d;
    fixed_offsets(s, 10, 20, a);
    fixed_offsets(s, 10, 20, b);
    fixed_offsets(s, 11, 20, c);
    fixed_offsets(sampler_for("jitter", 16, 43), 10, 20, d);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    EXPECT_NE(a, d);
    for (int k = 0; k < 16; ++k) {
        const int col = k % 4, row = k / 4;
        EXPECT_GE(a[k].x, col / 4.0);
        EXPECT_LE(a[k].x, (col + 1) / 4.0);
        EXPECT_GE(a[k].y, row / 4.0);
        EXPECT_LE(a[k].y, (row + 1) / 4.0);
    }
}

// Quincunx: centre 1/2, corners 1/8 each; over a tile the corners are traced once and shared, so a
// 16 x 16 tile costs 256 + 17 x 17 rays, about 2.1 per pixel.
TEST(Sampling, QuincunxSharesCornersWithWeightsOneEighth) {
    const PixelSampler s = sampler_for("quincunx", 1);
    int rays = 0;
    // f = 1 only at the top-left corner tap, 3 at the centre
    SampleValue v = one_pixel(
        s,
        [](double x, double y) {
            return x == 0 && y == 0 ? 1.0 : (x == 0.5 && y == 0.5 ? 3.0 : 0.0);
        },
        &rays);
    EXPECT_EQ(rays, 5);
    EXPECT_DOUBLE_EQ(v.color.x, 0.125 + 1.5);

    SamplerScratch scratch;
    int count = 0;
    sample_tile(
        s, 0, 0, 16, 16, scratch,
        [&](double, double) {
            ++count;
            return value(0.25);
        },
        [&](int, int, const SampleValue& p) { EXPECT_DOUBLE_EQ(p.color.x, 0.25); });
    EXPECT_EQ(count, 256 + 17 * 17);
}

// Adaptive: flat pixels cost the five quincunx taps; with an infinite threshold it is quincunx;
// an edge makes it subdivide towards the edge and get much closer to the true coverage.
TEST(Sampling, AdaptiveSubdividesOnlyWhereTapsDiffer) {
    RenderOptions o;
    o.sampler = SamplerKind::Adaptive;
    PixelSampler s;
    std::string error;
    ASSERT_TRUE(make_sampler(o, s, error));
    int rays = 0;
    SampleValue flat = one_pixel(
        s, [](double, double) { return 0.7; }, &rays);
    EXPECT_EQ(rays, 5);
    EXPECT_DOUBLE_EQ(flat.color.x, 0.7);

    // A vertical edge at x = 0.3: coverage of the left side 0.3.
    auto edge = [](double x, double) { return x < 0.3 ? 1.0 : 0.0; };
    const SampleValue q = one_pixel(sampler_for("quincunx", 1), edge);
    const SampleValue a = one_pixel(s, edge, &rays);
    EXPECT_GT(rays, 5);
    EXPECT_LT(std::abs(a.color.x - 0.3), std::abs(q.color.x - 0.3));
    // Exactly: after three subdivisions only the column of squares 1/8 wide at [1/4, 3/8] straddles
    // the edge; each of its squares sees its left corners (weight 1/8 each) inside and its right
    // corners and centre (weight 1/2) outside, so it counts 1/4 of its area where 2/5 is covered.
    // Everything left of it is covered, right of it not: 1/4 + (1/8) (1/4) = 9/32, an error of
    // 0.01875 (all exact binary).
    EXPECT_DOUBLE_EQ(a.color.x, 9.0 / 32.0);

    o.adaptive_threshold = 1e300;
    ASSERT_TRUE(make_sampler(o, s, error));
    EXPECT_DOUBLE_EQ(one_pixel(s, edge, &rays).color.x, q.color.x);
    EXPECT_EQ(rays, 5);
}

// The area of the unit square on the side n.p < c of a line (Sutherland-Hodgman clip + shoelace).
double covered_area(const Vec2& n, double c) {
    std::vector<Vec2> poly = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, out;
    for (size_t i = 0; i < poly.size(); ++i) {
        const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
        const double da = glm::dot(n, a) - c, db = glm::dot(n, b) - c;
        if (da < 0) out.push_back(a);
        if ((da < 0) != (db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
    }
    double area = 0;
    for (size_t i = 0; i < out.size(); ++i) {
        const Vec2 a = out[i], b = out[(i + 1) % out.size()];
        area += a.x * b.y - a.y * b.x;
    }
    return std::abs(area) / 2;
}

struct Edge {
    Vec2 n;
    double c;
};

// Random lines through the pixel, offset so that the line crosses the square; direction uniform, or
// within `spread` radians of the axes (the near-horizontal and near-vertical edges that
// stair-step).
std::vector<Edge> random_edges(int count, double spread = kPi) {
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Edge> edges;
    while (int(edges.size()) < count) {
        const double phi = std::floor(4 * u(rng)) * kPi / 2 + spread * (2 * u(rng) - 1);
        const Vec2 n(std::cos(phi), std::sin(phi));
        const Vec2 through(u(rng), u(rng));
        edges.push_back({n, glm::dot(n, through)});
    }
    return edges;
}

// RMS and mean (signed) error of a sampler's pixel value over the edges, each pixel at another
// position so that random samplers draw fresh numbers.
std::pair<double, double> edge_errors(const PixelSampler& s, const std::vector<Edge>& edges) {
    double sum2 = 0, sum = 0;
    for (size_t i = 0; i < edges.size(); ++i) {
        const Edge& e = edges[i];
        const SampleValue v = one_pixel(
            s, [&](double x, double y) { return glm::dot(e.n, Vec2(x, y)) < e.c ? 1.0 : 0.0; },
            nullptr, int(i), 3);
        const double err = v.color.x - covered_area(e.n, e.c);
        sum2 += err * err;
        sum += err;
    }
    return {std::sqrt(sum2 / edges.size()), sum / edges.size()};
}

TEST(Sampling, EdgeCoverageConvergesAsExpected) {
    const std::vector<Edge> edges = random_edges(2000);
    ASSERT_NEAR(covered_area(Vec2(1, 0), 0.3), 0.3, 1e-15);
    ASSERT_NEAR(covered_area(glm::normalize(Vec2(1, 1)), 0.0), 0.0, 1e-15);

    // Grid: each of the n rows of samples misjudges its strip's covered length by at most 1/n, so
    // the error is O(1/n): quadrupling n must cut the RMS error at least by 2.5 (theory: 4).
    const double g2 = edge_errors(sampler_for("grid", 4), edges).first;
    const double g8 = edge_errors(sampler_for("grid", 64), edges).first;
    EXPECT_LT(g8, g2 / 2.5);
    EXPECT_LT(g2, 0.25 / 2);  // 2 x 2 grid: at most a quarter per misjudged row

    // Jitter: unbiased, and for an edge its variance falls as N^-1.5 (N = n^2 samples; only the
    // O(n) cells the edge crosses are uncertain), so RMS falls as N^-0.75: from N = 4 to 256,
    // 64^-0.75 = 1/22.6. Asserted: better than 1/10, leaving room for the 2000-edge estimate.
    const auto [j4, bias4] = edge_errors(sampler_for("jitter", 4), edges);
    const auto [j256, bias256] = edge_errors(sampler_for("jitter", 256), edges);
    EXPECT_LT(j256, j4 / 10);
    // The mean of 2000 errors of RMS j4 has a standard deviation of j4/sqrt(2000) = j4/45: 4 sigma.
    EXPECT_LT(std::abs(bias4), 4 * j4 / std::sqrt(2000.0));
    EXPECT_LT(std::abs(bias256), 4 * j256 / std::sqrt(2000.0));

    // The seed's claim for RGSS and 8 rooks: on near-horizontal and near-vertical edges they beat a
    // grid of as many or more samples, because every sample has its own row and column (a 2 x 2
    // grid can only say 0, 1/2 or 1 for a vertical edge, RGSS quarters). Measured on edges within
    // 10 degrees of the axes: rgss (4) against the 2 x 2 grid, the 8 rooks against the 3 x 3 grid
    // (9).
    const std::vector<Edge> axis_edges = random_edges(2000, 10.0 * kPi / 180.0);
    EXPECT_LT(edge_errors(sampler_for("rgss", 4), axis_edges).first,
              0.75 * edge_errors(sampler_for("grid", 4), axis_edges).first);
    EXPECT_LT(edge_errors(sampler_for("rooks8", 8), axis_edges).first,
              0.75 * edge_errors(sampler_for("grid", 9), axis_edges).first);
}

// Statistical: stops once the standard error of the mean is below the threshold. A pixel cut in
// half by an edge gives Bernoulli(0.5) samples, standard deviation 0.5: it needs about (0.5 / t)^2
// samples, and its mean lies within a few standard errors of 0.5 (the first 16 samples are
// stratified over a 4 x 4 grid, so the edge is always seen). A flat pixel stops after the minimum;
// an unreachable threshold stops at the cap.
TEST(Sampling, StatisticalStopsAtItsThreshold) {
    RenderOptions o;
    o.sampler = SamplerKind::Statistical;
    o.noise_threshold = 0.02;
    PixelSampler s;
    std::string error;
    ASSERT_TRUE(make_sampler(o, s, error));
    auto half = [](double x, double) { return x < 0.5 ? 1.0 : 0.0; };
    double worst = 0;
    for (int p = 0; p < 50; ++p) {
        int rays = 0;
        const SampleValue v = one_pixel(s, half, &rays, p, 0);
        // (0.5 / 0.02)^2 = 625 > the cap 256: every pixel runs to the cap
        EXPECT_EQ(rays, 256);
        worst = std::max(worst, std::abs(v.color.x - 0.5));
    }
    EXPECT_LT(worst, 4 * 0.5 / std::sqrt(256.0));  // 4 standard errors at the cap

    o.noise_threshold = 0.05;  // needs about (0.5/0.05)^2 = 100 samples
    ASSERT_TRUE(make_sampler(o, s, error));
    double total = 0;
    for (int p = 0; p < 50; ++p) {
        int rays = 0;
        const SampleValue v = one_pixel(s, half, &rays, p, 1);
        total += rays;
        const double mean = v.color.x;
        // the stopping rule itself: the estimated standard error of the final mean is below 0.05
        EXPECT_LE(std::sqrt(mean * (1 - mean) / (rays - 1)), 0.05 + 1e-12);
        EXPECT_LT(rays, 256);
    }
    EXPECT_NEAR(total / 50, 100.0, 25.0);  // the rule estimates the variance, so the count scatters

    int rays = 0;
    one_pixel(
        s, [](double, double) { return 0.3; }, &rays);
    EXPECT_EQ(rays, s.min_samples);
}

// A disc of known area: an emissive unit sphere seen orthographically fills pi/(pixel area) pixels'
// worth of value; the image sum converges to it as the grid refines, and every sampler lands near
// it.
TEST(Sampling, DiscAreaConverges) {
    FlatScene scene = testing::empty_scene();
    Material m;
    m.diffuse = Vec3(0.0);
    m.emissive = Vec3(1.0);
    m.ambient_intensity = 0.0;
    testing::add_sphere(scene, Vec3(0.0), 1.0, testing::add_shading(scene, m));
    Viewpoint vp;
    vp.ortho = true;
    vp.position = Vec3(0.0, 0.0, 10.0);
    vp.ortho_extent[0] = -1.25;
    vp.ortho_extent[1] = -1.25;
    vp.ortho_extent[2] = 1.25;
    vp.ortho_extent[3] = 1.25;
    scene.viewpoints.push_back(vp);
    auto area_error = [&](const char* sampler, int spp) {
        RenderOptions o;
        o.width = o.height = 40;  // pixel side 2.5 / 40 = 1/16
        o.sampler = *sampler_kind(sampler);
        o.spp = spp;
        o.threads = 2;
        Camera camera;
        std::string error;
        EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
        RenderStats stats;
        const Image img = render_image(scene, camera, o, nullptr, stats);
        double sum = 0;
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) sum += img.pixel(x, y)[0];
        return std::abs(sum / (16.0 * 16.0) - kPi) / kPi;
    };
    const double e1 = area_error("grid", 1), e16 = area_error("grid", 16),
                 e256 = area_error("grid", 256);
    EXPECT_LT(e16, e1);
    EXPECT_LT(e256, 2e-3);  // about 2 pi r / pixel edge pixels, each off by far less than 1/16
    for (auto [name, spp] : {std::pair{"rgss", 16},
                             {"rooks8", 32},
                             {"jitter", 64},
                             {"quincunx", 1},
                             {"adaptive", 1},
                             {"statistical", 1}})
        EXPECT_LT(area_error(name, spp), 1e-2) << name;
}

// Every sampler gives the same image for 1 and 2 threads (positions depend on the pixel, not on
// the order in which tiles are rendered).
TEST(Sampling, SameImageForAnyThreadCount) {
    FlatScene scene = testing::empty_scene();
    Material m;
    m.emissive = Vec3(0.5, 0.2, 0.9);
    testing::add_sphere(scene, Vec3(0.3, 0.1, 0.0), 1.0, testing::add_shading(scene, m));
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 6.0), 0.6));
    for (auto [name, spp] :
         {std::pair{"jitter", 16}, {"statistical", 1}, {"adaptive", 1}, {"quincunx", 1}}) {
        Image img[2];
        for (int t = 0; t < 2; ++t) {
            RenderOptions o;
            o.width = 37;
            o.height = 29;
            o.sampler = *sampler_kind(name);
            o.spp = spp;
            o.seed = 9;
            o.threads = t + 1;
            Camera camera;
            std::string error;
            ASSERT_TRUE(make_camera(scene, o, camera, error)) << error;
            RenderStats stats;
            img[t] = render_image(scene, camera, o, nullptr, stats);
        }
        EXPECT_TRUE(img[0].rgba == img[1].rgba) << name;
    }
}

}  // namespace
}  // namespace vr

#include "render/gas.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

#include "render/lights.h"

namespace vr {

double one_minus_exp_over_x(double x) {
    if (x < 1e-300) return 1.0;  // x -> 0: the limit; also x = 0 exactly
    return -std::expm1(-x) / x;
}

namespace {

// The part of the line o + t d inside the sphere: t in [t0, t1]. The discriminant is formed from
// the closest-approach vector (the b'-form), which stays exact for far tiny spheres.
bool sphere_interval(const Vec3& o, const Vec3& d, const Vec3& c, double r, double& t0,
                     double& t1) {
    const double a = glm::dot(d, d);
    const Vec3 oc = o - c;
    const double tca = -glm::dot(oc, d) / a;
    const Vec3 l = oc + tca * d;
    const double disc = std::fma(r, r, -glm::dot(l, l));
    if (!(disc > 0.0)) return false;
    const double thc = std::sqrt(disc / a);
    t0 = tca - thc;
    t1 = tca + thc;
    return true;
}

// Real roots of alpha s^2 + beta s + gamma = 0 (the numerically stable pair).
int quadratic_roots(double alpha, double beta, double gamma, double* s) {
    if (alpha == 0.0) {
        if (beta == 0.0) return 0;
        s[0] = -gamma / beta;
        return 1;
    }
    const double disc = beta * beta - 4.0 * alpha * gamma;
    if (disc < 0.0) return 0;
    const double q = -0.5 * (beta + std::copysign(std::sqrt(disc), beta));
    if (q == 0.0) {
        s[0] = 0.0;
        return 1;
    }
    s[0] = q / alpha;
    s[1] = gamma / q;
    return 2;
}

// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    const Vec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
    const Vec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Quadrature on a panel [x0, x1] of an interval's unit parameter (see gas.h for the substitution).
// A new panel gets the 5-point Gauss-Lobatto rule (exact for degree 7) with Simpson's rule on its
// end and centre values as the error estimate: three evaluations, since the end values are known (0
// at the ends of the interval, where the substitution's derivative vanishes; the parent's values
// after a bisection). When that is not enough, the panel gets Gauss-Kronrod 7/15 (QUADPACK's qk15;
// 15 evaluations, an error estimate of a degree-13 rule: the substituted integrand is smooth, so
// this usually settles it), and a Gauss-Kronrod panel that is still not enough is halved into two
// Lobatto panels (a jump inside: an opaque surface's shadow edge). Every estimate is the difference
// to a lower-order rule on the same nodes, which overstates the error of the value used.
constexpr double kLobattoX = 0.654653670707977143798292456246859;  // sqrt(3/7)
constexpr double kX15[7] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245};
constexpr double kW15[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kW7[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                           0.381830050505118944950369775488975,
                           0.417959183673469387755102040816327};

struct Panel {
    double x0, x1, f0, fc, f1;  // ends, end and centre values
    double value, error;
    uint32_t interval;
    bool kronrod;  // false: Lobatto
};

template <class F>
Panel lobatto(F&& f, double x0, double x1, double f0, double f1, uint32_t interval) {
    const double centre = 0.5 * (x0 + x1), half = 0.5 * (x1 - x0);
    const double fc = f(centre);
    const double inner = f(centre - half * kLobattoX) + f(centre + half * kLobattoX);
    const double lob = (f0 + f1) * (1.0 / 10.0) + inner * (49.0 / 90.0) + fc * (32.0 / 45.0);
    const double simpson = (f0 + f1) * (1.0 / 3.0) + fc * (4.0 / 3.0);
    return {x0, x1, f0, fc, f1, lob * half, std::abs((lob - simpson) * half), interval, false};
}

// The panel again by Gauss-Kronrod 7/15 (its centre value is known).
template <class F>
Panel kronrod(F&& f, const Panel& p) {
    const double centre = 0.5 * (p.x0 + p.x1), half = 0.5 * (p.x1 - p.x0);
    double k15 = p.fc * kW15[7], g7 = p.fc * kW7[3];
    for (int k = 0; k < 7; ++k) {
        const double dx = half * kX15[k];
        const double sum = f(centre - dx) + f(centre + dx);
        k15 += kW15[k] * sum;
        if (k & 1) g7 += kW7[k >> 1] * sum;
    }
    Panel out = p;
    out.value = k15 * half;
    out.error = std::abs((k15 - g7) * half);
    out.kronrod = true;
    return out;
}

// A sphere that may lie on the path from a point of a piece to one light, in a frame p(s) = point +
// s u along the ray (s = t - mid), so that the optical depth at a quadrature node is a plain loop
// over a list of these, with no BVH traversal.
//   Directional light (unit direction l towards it): the sphere's chord along the half-line p +
//   lambda l, lambda >= 0, has its centre at lambda = m(s) = c[3] + s c[4] and half length h(s)
//   with h^2 = c[0] - s (c[1] + s c[2]) (where positive): chord = max(0, (m + h) - max(0, m - h)).
//   Point and spot light: c[0..2] = point - centre, c[3] = r^2; the chord along the segment to the
//   light is found with the same closest-approach form as sphere_interval.
struct Shadower {
    double c[5];
    double sigma;
};

// The shadowing spheres of a window of pieces (a run of consecutive pieces sharing one frame): per
// sphere where (in s) the path to the light can cross it at all (lo, hi: the shadow cylinder's
// crossings; unbounded for point lights), where that path touches its silhouette with the sphere
// between the point and the light (cut[0], cut[1]; NaN for none), its radius and its index.
struct WindowSphere {
    Shadower shadower;
    double lo, hi, cut[2], radius;
    uint32_t id;
};

// The window's entry for sphere g (frame point + s u, s in [s0, s1]); false when the path from no
// point of the window to the light can cross it.
bool window_sphere(const GasSphere& g, uint32_t index, const Light& light, const Vec3& point,
                   const Vec3& u, double s0, double s1, WindowSphere& out) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Vec3 q0 = point - g.center;
    const double r2 = g.radius * g.radius;
    double roots[2];
    out.cut[0] = out.cut[1] = nan;
    out.lo = -kInf, out.hi = kInf;
    out.radius = g.radius;
    out.id = index;
    out.shadower.sigma = g.sigma;
    double* c = out.shadower.c;
    if (light.kind == LightKind::Directional) {
        const Vec3 to_light = -light.direction;
        const double z0 = glm::dot(q0, to_light), zu = glm::dot(u, to_light);
        const Vec3 q0p = q0 - z0 * to_light, up = u - zu * to_light;
        const double k0 = r2 - glm::dot(q0p, q0p), k1 = 2.0 * glm::dot(q0p, up),
                     k2 = glm::dot(up, up);
        c[0] = k0, c[1] = k1, c[2] = k2, c[3] = -z0, c[4] = -zu;
        // Ahead of the window somewhere: m + r > 0 at one of its ends (m is linear in s).
        if (!(std::max(-z0 - zu * s0, -z0 - zu * s1) + g.radius > 0.0)) return false;
        // h^2 is positive between its roots (everywhere or nowhere without them).
        const int n = quadratic_roots(k2, k1, -k0, roots);
        if (n == 2 && k2 > 0.0) {
            out.lo = std::min(roots[0], roots[1]);
            out.hi = std::max(roots[0], roots[1]);
            if (!(out.lo < s1 && out.hi > s0)) return false;
            for (int i = 0; i < 2; ++i)
                if (-z0 - zu * roots[i] > 0.0) out.cut[i] = roots[i];
            return true;
        }
        return k0 > 0.0 && k2 == 0.0;
    }
    c[0] = q0.x, c[1] = q0.y, c[2] = q0.z, c[3] = r2, c[4] = 0.0;
    const Vec3 m = g.center - light.position, w0 = point - light.position;
    const double k = glm::dot(m, m) - r2;
    if (k > 0.0) {  // else the light is inside: every path crosses the sphere
        const double mu = glm::dot(m, u), mw = glm::dot(m, w0);
        const int n =
            quadratic_roots(k * glm::dot(u, u) - mu * mu, 2.0 * (k * glm::dot(w0, u) - mw * mu),
                            k * glm::dot(w0, w0) - mw * mw, roots);
        for (int i = 0; i < n; ++i) {
            const Vec3 p = point + roots[i] * u, d = light.position - p;
            const double lambda = glm::dot(g.center - p, d);
            if (lambda > 0.0 && lambda < glm::dot(d, d)) out.cut[i] = roots[i];
        }
    }
    return true;
}

// Shadowers four side by side, one array per coefficient, so that the optical depth at a node is
// found for four spheres at once. Unused lanes have sigma = 0 and c[0] = c[3] = -1 (h^2 < 0, r^2 <
// 0: no chord).
struct ShadowBlock {
    double c[5][4];
    double sigma[4];
};

// Appends shadowers to a list of blocks: begin() starts a new list, push() fills lanes.
struct ShadowBlocks {
    std::vector<ShadowBlock> blocks;
    int lane = 4;
    uint32_t begin() {
        lane = 4;
        return uint32_t(blocks.size());
    }
    void push(const Shadower& s) {
        if (lane == 4) {
            ShadowBlock& b = blocks.emplace_back();
            for (int k = 0; k < 5; ++k)
                for (int l = 0; l < 4; ++l) b.c[k][l] = k == 0 || k == 3 ? -1.0 : 0.0;
            for (int l = 0; l < 4; ++l) b.sigma[l] = 0.0;
            lane = 0;
        }
        ShadowBlock& b = blocks.back();
        for (int k = 0; k < 5; ++k) b.c[k][lane] = s.c[k];
        b.sigma[lane] = s.sigma;
        ++lane;
    }
};

double directional_depth(const ShadowBlock* blocks, size_t n, double s) {
#if defined(__AVX2__) && defined(__FMA__)
    const __m256d S = _mm256_set1_pd(s), zero = _mm256_setzero_pd();
    __m256d depth = zero;
    for (size_t i = 0; i < n; ++i) {
        const ShadowBlock& b = blocks[i];
        const __m256d h2 = _mm256_fnmadd_pd(
            S, _mm256_fmadd_pd(S, _mm256_loadu_pd(b.c[2]), _mm256_loadu_pd(b.c[1])),
            _mm256_loadu_pd(b.c[0]));
        const __m256d h = _mm256_sqrt_pd(_mm256_max_pd(h2, zero));  // max(NaN, 0) = 0
        const __m256d m = _mm256_fmadd_pd(S, _mm256_loadu_pd(b.c[4]), _mm256_loadu_pd(b.c[3]));
        const __m256d chord = _mm256_max_pd(
            zero, _mm256_sub_pd(_mm256_add_pd(m, h), _mm256_max_pd(zero, _mm256_sub_pd(m, h))));
        depth = _mm256_fmadd_pd(_mm256_loadu_pd(b.sigma), chord, depth);
    }
    const __m128d pair = _mm_add_pd(_mm256_castpd256_pd128(depth), _mm256_extractf128_pd(depth, 1));
    return _mm_cvtsd_f64(_mm_add_sd(pair, _mm_unpackhi_pd(pair, pair)));
#else
    double depth = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int l = 0; l < 4; ++l) {
            const ShadowBlock& b = blocks[i];
            const double h2 = b.c[0][l] - s * (b.c[1][l] + s * b.c[2][l]);
            if (!(h2 > 0.0)) continue;
            const double h = std::sqrt(h2), m = b.c[3][l] + s * b.c[4][l];
            const double chord = (m + h) - std::max(0.0, m - h);
            if (chord > 0.0) depth += b.sigma[l] * chord;
        }
    return depth;
#endif
}

// `from` = p(s) - point is s u; `to_light` = light position - p(s), `len2` its squared length.
double point_depth(const ShadowBlock* blocks, size_t n, const Vec3& from, const Vec3& to_light,
                   double len2) {
    const double inv = 1.0 / len2;
    double depth = 0.0;  // in units of the segment's length
    for (size_t i = 0; i < n; ++i)
        for (int l = 0; l < 4; ++l) {
            const ShadowBlock& b = blocks[i];
            const Vec3 oc(b.c[0][l] + from.x, b.c[1][l] + from.y, b.c[2][l] + from.z);
            const double tca = -glm::dot(oc, to_light) * inv;
            const Vec3 q = oc + tca * to_light;
            const double disc = b.c[3][l] - glm::dot(q, q);
            if (!(disc > 0.0)) continue;
            const double thc = std::sqrt(disc * inv);
            const double t0 = std::max(tca - thc, 0.0), t1 = std::min(tca + thc, 1.0);
            if (t1 > t0) depth += b.sigma[l] * (t1 - t0);
        }
    return depth * std::sqrt(len2);
}

// Whether a ball (centre C, radius R) meets the triangle (light, A, B): the paths from the segment
// [A, B] to a point light.
bool meets_point_fan(const Vec3& light, const Vec3& A, const Vec3& B, const Vec3& C, double R) {
    const Vec3 q = closest_on_triangle(C, light, A, B) - C;
    return glm::dot(q, q) <= R * R * (1.0 + 1e-9);
}
}  // namespace

void GasVolume::build(const FlatScene& scene, const RenderOptions& options) {
    spheres_.clear();
    BuildBoxes boxes;
    for (const Sphere& s : scene.spheres) {
        if (!s.gas || !(s.radius > 0.0)) continue;
        const Shading& sh = scene.shadings[s.shading];
        const Material& m = scene.materials[sh.material];
        GasSphere g;
        g.center = s.center;
        g.radius = s.radius;
        g.sigma = m.density >= 0.0 ? m.density : options.density;
        const Vec3 albedo = m.albedo.x >= 0.0 ? m.albedo : m.diffuse;
        const Vec3 emission = m.emission.x >= 0.0 ? m.emission : m.emissive;
        g.sigma_rho = g.sigma * albedo;
        g.sigma_e = g.sigma * emission;
        g.light_set = sh.light_set;
        if (!(g.sigma > 0.0)) continue;  // no extinction: invisible and casting nothing
        const Vec3 r(s.radius);
        boxes.push_back(
            make_build_box(s.center - r, s.center + r, static_cast<uint32_t>(spheres_.size())));
        spheres_.push_back(g);
    }
    // Pieces are gathered into windows about a sphere diameter long for the search of shadowing
    // spheres.
    double radii = 0.0;
    for (const GasSphere& g : spheres_) radii += g.radius;
    window_length_ = spheres_.empty() ? 0.0 : 2.0 * radii / double(spheres_.size());
    BvhBuildOptions bo;
    bo.threads = options.threads > 0 ? options.threads : 2;
    bvh_ = spheres_.empty() ? Bvh{} : build_bvh(std::move(boxes), bo);
}

double GasVolume::optical_depth(const Ray& ray) const {
    if (spheres_.empty()) return 0.0;
    const double len = glm::length(ray.d);
    double depth = 0.0;
    double t_max = ray.t_max;
    traverse_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double&) {
        for (uint32_t i = first; i < first + count; ++i) {
            const GasSphere& g = spheres_[bvh_.order[i]];
            double t0, t1;
            if (!sphere_interval(ray.o, ray.d, g.center, g.radius, t0, t1)) continue;
            t0 = std::max(t0, 0.0);
            t1 = std::min(t1, ray.t_max);
            if (t1 > t0) depth += g.sigma * (t1 - t0) * len;
        }
        return false;
    });
    return depth;
}

void GasVolume::collect_events(const Ray& ray, double t_end, std::vector<Event>& events) const {
    events.clear();
    double t_max = t_end;
    traverse_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double&) {
        for (uint32_t i = first; i < first + count; ++i) {
            const uint32_t id = bvh_.order[i];
            const GasSphere& g = spheres_[id];
            double t0, t1;
            if (!sphere_interval(ray.o, ray.d, g.center, g.radius, t0, t1)) continue;
            t0 = std::max(t0, 0.0);
            t1 = std::min(t1, t_end);
            if (!(t1 > t0)) continue;
            events.push_back({t0, id, true});
            events.push_back({t1, id, false});
        }
        return false;
    });
    // Sorted by place, then sphere, so the order (and the result) never depends on the BVH's leaf
    // order.
    std::sort(events.begin(), events.end(), [](const Event& x, const Event& y) {
        if (x.t != y.t) return x.t < y.t;
        if (x.sphere != y.sphere) return x.sphere < y.sphere;
        return x.enter > y.enter;
    });
}

template <class Visit>
void GasVolume::spheres_in_fan(const Light& light, const Vec3& A, const Vec3& B,
                               Visit&& visit) const {
    if (bvh_.empty()) return;
    // The fan lies within rho = |B - A| / 2 of the line from the segment's midpoint M towards the
    // light (s in [-rho, inf) for a directional light, [0, 1] along M -> position for a point
    // light): nodes are culled by a slab test of that line against their boxes grown by rho;
    // spheres by their distance from the line (directional; window_sphere then looks closer) or by
    // the fan itself (point and spot).
    const Vec3 M = 0.5 * (A + B);
    const double rho = 0.5 * glm::length(B - A) * (1.0 + 1e-9);
    const bool directional = light.kind == LightKind::Directional;
    const Vec3 d = directional ? -light.direction : light.position - M;
    const double s_lo = directional ? -rho : 0.0, s_hi = directional ? kInf : 1.0;
    double inv[3], o[3];
    for (int k = 0; k < 3; ++k) inv[k] = 1.0 / d[k], o[k] = M[k];
    uint32_t stack[256];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& n = bvh_.nodes[stack[--top]];
        double t0 = s_lo, t1 = s_hi;
        for (int k = 0; k < 3; ++k) {
            double a = (double(n.lo[k]) - rho - o[k]) * inv[k],
                   b = (double(n.hi[k]) + rho - o[k]) * inv[k];
            if (inv[k] < 0.0) std::swap(a, b);
            // NaN (a line in a slab plane) keeps the node: the comparisons fail.
            if (a > t0) t0 = a;
            if (b < t1) t1 = b;
        }
        if (!(t0 <= t1 + 1e-9 * (std::abs(t0) + std::abs(t1)))) continue;
        if (n.count == 0) {
            stack[top++] = n.offset;
            stack[top++] = n.offset + 1;
            continue;
        }
        for (uint32_t i = n.offset; i < n.offset + n.count; ++i) {
            const uint32_t id = bvh_.order[i];
            const GasSphere& g = spheres_[id];
            if (directional) {  // within rho + r of the line and not behind its start
                const Vec3 x = g.center - M;
                const double z = glm::dot(x, d), reach = rho + g.radius;
                if (glm::dot(x, x) - z * z <= reach * reach * (1.0 + 1e-9) && z + reach >= 0.0)
                    visit(id);
            } else if (meets_point_fan(light.position, A, B, g.center, g.radius)) {
                visit(id);
            }
        }
    }
}

struct GasVolume::Piece {  // a stretch of the ray inside the same spheres
    double a, b, T, sigma;
};

GasVolume::Result GasVolume::march_pieces(const Ray& ray, double t_end, const Lighting& lighting,
                                          GasStats& stats, std::vector<Piece>& pieces,
                                          std::vector<Vec3>& coef) const {
    thread_local std::vector<Event> events;
    thread_local std::vector<uint32_t> active;
    collect_events(ray, t_end, events);
    const size_t n_lights = lighting.lights ? lighting.lights->size() : 0;
    active.clear();
    pieces.clear();
    coef.clear();
    double T = 1.0, tau = 0.0;
    Vec3 L(0.0);
    double prev = 0.0;
    for (const Event& e : events) {
        if (!active.empty() && e.t > prev && T > 0.0) {
            const double a = prev, b = e.t, width = b - a;
            double sigma = 0.0;
            Vec3 sigma_e(0.0), sigma_rho(0.0);
            const size_t base = coef.size();
            coef.resize(base + n_lights, Vec3(0.0));
            for (uint32_t id : active) {
                const GasSphere& g = spheres_[id];
                sigma += g.sigma;
                sigma_e += g.sigma_e;
                sigma_rho += g.sigma_rho;
                if (n_lights && (g.sigma_rho.x > 0.0 || g.sigma_rho.y > 0.0 || g.sigma_rho.z > 0.0))
                    for (uint32_t l : (*lighting.light_sets)[g.light_set])
                        coef[base + l] += g.sigma_rho;
            }
            const double x = sigma * width;
            const double exact =
                width * one_minus_exp_over_x(x);  // integral of exp(-sigma (t - a))
            // Emission, and every light term constant along the piece, in closed form.
            L += T * exact * sigma_e;
            if (lighting.headlight) {
                const Light& h = *lighting.headlight;
                L += T * exact * (h.ambient_intensity + h.intensity) * sigma_rho * h.color;
            }
            for (size_t li = 0; li < n_lights; ++li) {
                const Light& light = (*lighting.lights)[li];
                if (light.kind ==
                    LightKind::Directional)  // att = spot = 1: the ambient term is constant
                    L += T * exact * light.ambient_intensity * coef[base + li] * light.color;
            }
            ++stats.pieces;
            pieces.push_back({a, b, T, sigma});
            T *= std::exp(-x);
            tau += x;
        }
        if (e.enter) {
            active.push_back(e.sphere);
        } else {
            auto it = std::find(active.begin(), active.end(), e.sphere);
            if (it != active.end()) active.erase(it);
        }
        prev = std::max(prev, e.t);
    }
    Result result;
    result.transmittance = T;
    result.optical_depth = tau;
    result.radiance = L;
    return result;
}

// A LightPass's work space, kept per thread so that a ray allocates nothing.
struct GasVolume::LightScratch {
    struct Interval {
        double t0, width;
        uint32_t piece;
    };
    struct Frame {  // a piece's frame (its window's): p(s) = point + s u, s = t - mid; its shadow
                    // spheres in the pool
        Vec3 point;
        double mid;
        uint32_t begin, end;
    };
    struct Window {  // a run of consecutive pieces: its frame and its shadowing spheres in `window`
        Vec3 point;
        double mid;
        uint32_t begin, end;
    };
    static constexpr uint32_t kNoWindow = ~0u;
    std::vector<Panel> panels;
    std::vector<Interval> intervals;
    std::vector<Frame> frames;
    std::vector<WindowSphere> window;
    std::vector<Window> windows;
    std::vector<uint32_t> window_of;  // per piece: its window
    ShadowBlocks pool;
    std::vector<double> cuts;
    std::vector<std::pair<double, uint32_t>> order;
};

// The part of one light's term that varies along a piece (shadows, attenuation, spot): integrated
// over the whole ray at once, so that the error goes where the light is, to tolerance * the light's
// total.
struct GasVolume::LightPass {
    using Scratch = LightScratch;
    const GasVolume& gas;
    const Ray& ray;
    const Lighting& lighting;
    const Light& light;
    const size_t li, n_lights;
    const std::vector<Piece>& pieces;
    const std::vector<Vec3>& coef;  // [piece * n_lights + light]
    GasStats& stats;
    Scratch& k;
    const bool directional = light.kind == LightKind::Directional;
    const bool ambient_varies = !directional;
    const bool shadowed = light.intensity > 0.0 && !light.headlight;
    const bool area = lighting.is_area(light);  // V_l by its own integral: no sharp shadow edges
    const double w_max = (ambient_varies ? light.ambient_intensity : 0.0) + light.intensity;
    const Vec3& u = ray.d;

    // Scalar weight of a piece (its colour factor's largest channel), and a bound on its integral:
    // w <= w_max since att, spot and V are at most 1.
    double scale(size_t p) const {
        const Vec3 c = coef[p * n_lights + li] * light.color;
        return std::max(c.x, std::max(c.y, c.z));
    }

    // The integrand at t in piece p.
    double integrand(uint32_t p, double t) const {
        const Piece& pc = pieces[p];
        const Scratch::Frame& fr = k.frames[p];
        const double s = t - fr.mid;
        const Vec3 at = fr.point + s * u;
        double factor = 1.0;
        if (!directional) {
            factor = light_incidence(light, at).factor;
            if (!(factor > 0.0)) return 0.0;
        }
        double visibility = shadowed ? 1.0 : 0.0, depth = 0.0;  // V = visibility * exp(-depth)
        if (shadowed && area) {
            ++stats.visibility_rays;
            visibility = lighting.area_visibility(light, at);  // gas on the way included
        } else if (shadowed) {
            ++stats.visibility_rays;
            Ray shadow;
            shadow.o = at;
            if (directional) {
                shadow.d = -light.direction;
                shadow.t_max = kInf;
            } else {
                shadow.d = light.position - at;  // t = 1 at the light
                shadow.t_max = 1.0;
            }
            if (lighting.surfaces) visibility = lighting.surfaces(shadow);
            if (visibility > 0.0 && fr.end > fr.begin)
                depth =
                    directional
                        ? directional_depth(k.pool.blocks.data() + fr.begin, fr.end - fr.begin, s)
                        : point_depth(k.pool.blocks.data() + fr.begin, fr.end - fr.begin, s * u,
                                      shadow.d, glm::dot(shadow.d, shadow.d));
        }
        // T(0, t) * sigma rho * att * spot * (ambient + intensity * V), with one exp where
        // possible.
        const double camera = pc.sigma * (t - pc.a);
        const double weight = pc.T * scale(p) * factor;
        if (!ambient_varies || !(light.ambient_intensity > 0.0))
            return visibility > 0.0
                       ? weight * light.intensity * visibility * std::exp(-(camera + depth))
                       : 0.0;
        return weight * std::exp(-camera) *
               (light.ambient_intensity + light.intensity * visibility * std::exp(-depth));
    }

    // The integrand of interval i in its unit parameter x: t = t0 + w g(x), g(x) = x^2 (3 - 2x).
    auto mapped(uint32_t i) const {
        const Scratch::Interval& iv = k.intervals[i];
        return [this, iv](double x) {
            const double g = x * x * (3.0 - 2.0 * x), dg = 6.0 * x * (1.0 - x);
            return integrand(iv.piece, iv.t0 + iv.width * g) * (iv.width * dg);
        };
    }

    // The pieces this light reaches, largest bound first; the sum of the bounds.
    double order_pieces() {
        k.order.clear();
        double remaining = 0.0;
        for (size_t p = 0; p < pieces.size(); ++p) {
            const double s = scale(p);
            if (!(s > 0.0)) continue;
            const Piece& pc = pieces[p];
            const double bound =
                pc.T * s * w_max * (pc.b - pc.a) * one_minus_exp_over_x(pc.sigma * (pc.b - pc.a));
            k.order.push_back({bound, uint32_t(p)});
            remaining += bound;
        }
        std::sort(k.order.begin(), k.order.end(),
                  [](auto& x, auto& y) { return x.first > y.first; });
        return remaining;
    }

    // Where the light's radius ends (the weight jumps to 0) and a spot light's cones, solved about
    // the piece's midpoint so that a far camera costs no precision.
    void light_cuts(const Piece& pc) {
        double s[2];
        const double mid = 0.5 * (pc.a + pc.b), half = 0.5 * (pc.b - pc.a);
        auto keep = [&](int n) {
            for (int i = 0; i < n; ++i)
                if (std::abs(s[i]) < half) k.cuts.push_back(mid + s[i]);
        };
        const Vec3 w0 = ray.at(mid) - light.position;
        keep(quadratic_roots(glm::dot(u, u), 2.0 * glm::dot(w0, u),
                             glm::dot(w0, w0) - light.radius * light.radius, s));
        if (light.kind != LightKind::Spot) return;
        const Vec3& D = light.direction;
        for (double angle : {light.cutoff_angle, light.beam_width}) {
            if (!(angle > 0.0 && angle < kPi)) continue;
            const double c2 = std::cos(angle) * std::cos(angle);
            const double uD = glm::dot(u, D), wD = glm::dot(w0, D);
            keep(quadratic_roots(uD * uD - c2 * glm::dot(u, u),
                                 2.0 * (wD * uD - c2 * glm::dot(w0, u)),
                                 wD * wD - c2 * glm::dot(w0, w0), s));
        }
    }

    // A window: piece p and the next ones up to window_length_ further, whose shadowing spheres are
    // gathered from the BVH at once, with their coefficients in the window's frame and the places
    // where the path to the light touches their silhouettes.
    void open_window(size_t p) {
        const Piece& pc = pieces[p];
        size_t q = p;
        while (q + 1 < pieces.size() && pieces[q + 1].b - pc.a <= gas.window_length_) ++q;
        Scratch::Window w;
        w.mid = 0.5 * (pc.a + pieces[q].b);
        w.point = ray.at(w.mid);
        w.begin = uint32_t(k.window.size());
        const double s0 = pc.a - w.mid, s1 = pieces[q].b - w.mid;
        WindowSphere ws;
        gas.spheres_in_fan(light, ray.at(pc.a), ray.at(pieces[q].b), [&](uint32_t id) {
            if (window_sphere(gas.spheres_[id], id, light, w.point, u, s0, s1, ws))
                k.window.push_back(ws);
        });
        w.end = uint32_t(k.window.size());
        k.windows.push_back(w);
        for (size_t j = p; j <= q; ++j) k.window_of[j] = uint32_t(k.windows.size() - 1);
    }

    // Piece p's frame becomes its window's; the spheres that can shadow it go to the pool, and
    // their cuts inside it to `cuts`.
    void shadow_cuts(size_t p, Scratch::Frame& fr) {
        if (k.window_of[p] == Scratch::kNoWindow) open_window(p);
        const Piece& pc = pieces[p];
        const Scratch::Window& w = k.windows[k.window_of[p]];
        fr.point = w.point;
        fr.mid = w.mid;
        const double a = pc.a - w.mid, b = pc.b - w.mid;
        const Vec3 A = ray.at(pc.a), B = ray.at(pc.b);
        for (uint32_t i = w.begin; i < w.end; ++i) {
            const WindowSphere& ws = k.window[i];
            if (!(ws.lo < b && ws.hi > a)) continue;
            if (directional) {
                // Wholly behind the piece: the chord's centre is more than a radius behind it.
                const double* c = ws.shadower.c;
                if (!(std::max(c[3] + a * c[4], c[3] + b * c[4]) + ws.radius > 0.0)) continue;
            } else if (!meets_point_fan(light.position, A, B, gas.spheres_[ws.id].center,
                                        ws.radius)) {
                continue;
            }
            k.pool.push(ws.shadower);
            for (double c : ws.cut)
                if (c > a && c < b) k.cuts.push_back(w.mid + c);
        }
        fr.end = uint32_t(k.pool.blocks.size());
    }

    // Piece p cut where the integrand has kinks or jumps, one first-order panel per interval; adds
    // their values to `found`.
    void start_panels(uint32_t p, double& found) {
        const Piece& pc = pieces[p];
        k.cuts.clear();
        k.cuts.push_back(pc.a);
        if (!directional) light_cuts(pc);
        Scratch::Frame& fr = k.frames[p];
        fr.begin = fr.end = k.pool.begin();
        fr.mid = 0.5 * (pc.a + pc.b);
        fr.point = ray.at(fr.mid);
        if (shadowed && !area) shadow_cuts(p, fr);
        k.cuts.push_back(pc.b);
        std::sort(k.cuts.begin() + 1, k.cuts.end() - 1);
        for (size_t i = 0; i + 1 < k.cuts.size(); ++i) {
            if (!(k.cuts[i + 1] > k.cuts[i])) continue;
            k.intervals.push_back({k.cuts[i], k.cuts[i + 1] - k.cuts[i], p});
            const uint32_t id = uint32_t(k.intervals.size() - 1);
            k.panels.push_back(lobatto(mapped(id), 0.0, 1.0, 0.0, 0.0, id));
            found += k.panels.back().value;
        }
        ++stats.quadrature;
    }

    // Global adaptive refinement (QUADPACK's QAG idea) to three quarters of the tolerance: the
    // panel with the largest error estimate gets the higher-order rule or is halved (see Panel)
    // until the estimates add up to little enough.
    void refine(double tolerance, double floor) {
        std::vector<Panel>& panels = k.panels;
        auto by_error = [](const Panel& x, const Panel& y) { return x.error < y.error; };
        std::make_heap(panels.begin(), panels.end(), by_error);
        const size_t max_panels = panels.size() + 2000;
        double value = 0.0, error = 0.0;
        for (const Panel& pn : panels) value += pn.value, error += pn.error;
        for (;;) {
            if (error <= 0.75 * tolerance * std::abs(value) + floor ||
                panels.size() >= max_panels) {
                // The running sums drift by rounding: decide on fresh ones.
                value = error = 0.0;
                for (const Panel& pn : panels) value += pn.value, error += pn.error;
                if (error <= 0.75 * tolerance * std::abs(value) + floor ||
                    panels.size() >= max_panels)
                    break;
            }
            if (panels.empty() || panels.front().error == 0.0) break;
            std::pop_heap(panels.begin(), panels.end(), by_error);
            const Panel worst = panels.back();
            panels.pop_back();
            value -= worst.value, error -= worst.error;
            auto f = mapped(worst.interval);
            const double mid = 0.5 * (worst.x0 + worst.x1);
            if (!worst.kronrod) {
                panels.push_back(kronrod(f, worst));
            } else if (mid > worst.x0 && mid < worst.x1) {
                panels.push_back(lobatto(f, worst.x0, mid, worst.f0, worst.fc, worst.interval));
                value += panels.back().value, error += panels.back().error;
                std::push_heap(panels.begin(), panels.end(), by_error);
                panels.push_back(lobatto(f, mid, worst.x1, worst.fc, worst.f1, worst.interval));
            } else {  // cannot split further in double: keep it as it is
                panels.push_back(worst);
                panels.back().error = 0.0;
            }
            value += panels.back().value, error += panels.back().error;
            std::push_heap(panels.begin(), panels.end(), by_error);
        }
    }

    // Adds this light's varying term to L.
    void integrate(double tolerance, Vec3& L) {
        if (!(w_max > 0.0)) return;
        double remaining = order_pieces();
        if (k.order.empty()) return;
        // An area light's V_l is itself known to an absolute error (--light-tolerance): finer
        // quadrature than that error times the unshadowed integral would chase its noise.
        const double floor =
            area ? lighting.area_tolerance * (light.intensity / w_max) * remaining : 0.0;
        k.pool.blocks.clear();
        k.intervals.clear();
        k.panels.clear();
        k.frames.resize(pieces.size());
        k.window.clear();
        k.window_of.assign(pieces.size(), Scratch::kNoWindow);
        k.windows.clear();
        // Pieces in order of their bound; once the bounds of all the rest are below a quarter of
        // the tolerance times what has been found so far (a lower bound of the total), they are
        // left out.
        double found = 0.0;
        for (const auto& [bound, p] : k.order) {
            if (remaining <= 0.25 * tolerance * found) break;
            remaining -= bound;
            start_panels(p, found);
        }
        refine(tolerance, floor);
        for (const Panel& pn : k.panels) {
            const uint32_t p = k.intervals[pn.interval].piece;
            const double s = scale(p);
            if (s > 0.0) L += (pn.value / s) * coef[p * n_lights + li] * light.color;
        }
    }
};

GasVolume::Result GasVolume::integrate(const Ray& ray, double t_end, const Lighting& lighting,
                                       double tolerance, GasStats& stats) const {
    if (spheres_.empty()) return Result();
    thread_local std::vector<Piece> pieces;
    thread_local std::vector<Vec3>
        coef;  // [piece * n_lights + light]: sigma*rho of the spheres it reaches
    thread_local LightScratch scratch;
    Result result = march_pieces(ray, t_end, lighting, stats, pieces, coef);
    const size_t n_lights = lighting.lights ? lighting.lights->size() : 0;
    for (size_t li = 0; li < n_lights; ++li) {
        LightPass pass{*this, ray,   lighting, (*lighting.lights)[li], li, n_lights, pieces,
                       coef,  stats, scratch};
        pass.integrate(tolerance, result.radiance);
    }
    return result;
}

}  // namespace vr

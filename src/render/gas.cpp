#include "render/gas.h"

#include <algorithm>
#include <cmath>

#include "render/lights.h"

namespace vr {

double one_minus_exp_over_x(double x) {
    if (x < 1e-300) return 1.0;  // x -> 0: the limit; also x = 0 exactly
    return -std::expm1(-x) / x;
}

namespace {

// The part of the line o + t d inside the sphere: t in [t0, t1]. The discriminant is formed from the
// closest-approach vector (the b'-form), which stays exact for far tiny spheres.
bool sphere_interval(const Vec3& o, const Vec3& d, const Vec3& c, double r, double& t0, double& t1) {
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
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Separating-axis test of a triangle against a box (Akenine-Moeller), made conservative: the box is
// grown by a relative margin so that rounding never separates what touches.
bool triangle_overlaps_box(const Vec3 tri[3], const Vec3& lo, const Vec3& hi) {
    const Vec3 c = 0.5 * (lo + hi);
    const Vec3 h = 0.5 * (hi - lo) * (1.0 + 1e-9) + Vec3(1e-300);
    const Vec3 v[3] = {tri[0] - c, tri[1] - c, tri[2] - c};
    for (int k = 0; k < 3; ++k) {
        const double mn = std::min({v[0][k], v[1][k], v[2][k]}), mx = std::max({v[0][k], v[1][k], v[2][k]});
        if (mn > h[k] || mx < -h[k]) return false;
    }
    const Vec3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    const Vec3 n = glm::cross(e[0], e[1]);
    const double slack = 1e-9;
    {
        const double d = glm::dot(n, v[0]);
        const double r = glm::dot(h, glm::abs(n));
        if (std::abs(d) > r * (1.0 + slack) + 1e-300) return false;
    }
    for (const Vec3& edge : e) {
        for (int k = 0; k < 3; ++k) {
            Vec3 unit(0.0);
            unit[k] = 1.0;
            const Vec3 axis = glm::cross(unit, edge);
            const double p0 = glm::dot(axis, v[0]), p1 = glm::dot(axis, v[1]), p2 = glm::dot(axis, v[2]);
            const double r = glm::dot(h, glm::abs(axis));
            const double mn = std::min({p0, p1, p2}), mx = std::max({p0, p1, p2});
            const double tol = slack * (r + std::max(std::abs(mn), std::abs(mx))) + 1e-300;
            if (mn > r + tol || mx < -r - tol) return false;
        }
    }
    return true;
}

// The light paths from a segment [A, B] of a ray to a light form a flat fan: the triangle (L, A, B) for
// a point light, the strip {A..B} - s * direction (s >= 0) for a directional light, cut off beyond the
// gas. A sphere can shadow some point of the segment only if it meets the fan.
struct Fan {
    Vec3 tri[2][3];
    int count = 0;
};

Fan light_fan(const Light& light, const Vec3& A, const Vec3& B, const Bounds3& bounds) {
    Fan fan;
    if (light.kind == LightKind::Directional) {
        const Vec3 centre = 0.5 * (bounds.lo + bounds.hi);
        const double reach = glm::length(bounds.hi - bounds.lo) + glm::length(A - centre) + glm::length(B - centre);
        const Vec3 A2 = A - reach * light.direction, B2 = B - reach * light.direction;
        fan.tri[0][0] = A, fan.tri[0][1] = B, fan.tri[0][2] = B2;
        fan.tri[1][0] = A, fan.tri[1][1] = B2, fan.tri[1][2] = A2;
        fan.count = 2;
    } else {
        fan.tri[0][0] = light.position, fan.tri[0][1] = A, fan.tri[0][2] = B;
        fan.count = 1;
    }
    return fan;
}

bool fan_overlaps_box(const Fan& fan, const Vec3& lo, const Vec3& hi) {
    for (int i = 0; i < fan.count; ++i)
        if (triangle_overlaps_box(fan.tri[i], lo, hi)) return true;
    return false;
}

bool fan_meets_sphere(const Fan& fan, const Vec3& c, double r) {
    for (int i = 0; i < fan.count; ++i) {
        const Vec3 q = closest_on_triangle(c, fan.tri[i][0], fan.tri[i][1], fan.tri[i][2]);
        const Vec3 dq = q - c;
        if (glm::dot(dq, dq) <= r * r * (1.0 + 1e-9)) return true;
    }
    return false;
}

// Gauss-Kronrod 3/7 rule on [-1, 1]: the 3-point Gauss rule and its 7-point Kronrod extension, whose
// difference is the panel's error estimate (pessimistic for smooth integrands, so the estimate is honest).
constexpr double kXk[4] = {0.960491268708020283423507092629080, 0.774596669241483377035853079956480,
                           0.434243749346802558002071502844628, 0.0};
constexpr double kWk[4] = {0.104656226026467265193823857192073, 0.268488089868333440728569280666710,
                           0.401397414775962222905051818618432, 0.450916538658474142345110087045571};
constexpr double kWg[2] = {0.555555555555555555555555555555556, 0.888888888888888888888888888888889};

struct Panel {
    double a, b, value, error;
    uint32_t piece;
};

template <class F>
Panel gauss_kronrod(F&& f, double a, double b, uint32_t piece) {
    const double centre = 0.5 * (a + b), half = 0.5 * (b - a);
    const double fc = f(centre);
    double kronrod = fc * kWk[3], gauss = fc * kWg[1];
    for (int j = 0; j < 3; ++j) {
        const double dx = half * kXk[j];
        const double sum = f(centre - dx) + f(centre + dx);
        kronrod += kWk[j] * sum;
        if (j == 1) gauss += kWg[0] * sum;
    }
    return {a, b, kronrod * half, std::abs((kronrod - gauss) * half), piece};
}

}  // namespace

void GasVolume::build(const FlatScene& scene, const RenderOptions& options) {
    spheres_.clear();
    bounds_ = Bounds3{};
    std::vector<BuildBox> boxes;
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
        boxes.push_back(make_build_box(s.center - r, s.center + r, static_cast<uint32_t>(spheres_.size())));
        bounds_.extend(s.center - r);
        bounds_.extend(s.center + r);
        spheres_.push_back(g);
    }
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
    // Sorted by place, then sphere, so the order (and the result) never depends on the BVH's leaf order.
    std::sort(events.begin(), events.end(), [](const Event& x, const Event& y) {
        if (x.t != y.t) return x.t < y.t;
        if (x.sphere != y.sphere) return x.sphere < y.sphere;
        return x.enter > y.enter;
    });
}

double GasVolume::light_weight(const Light& light, const Vec3& p, bool ambient, const SurfaceTransmittance& surfaces,
                               GasStats& stats) const {
    const LightIncidence inc = light_incidence(light, p);
    if (!(inc.factor > 0.0)) return 0.0;
    double visibility = 1.0;
    if (!light.headlight) {
        ++stats.visibility_rays;
        Ray shadow;
        shadow.o = p;
        if (light.kind == LightKind::Directional) {
            shadow.d = inc.to_light;
            shadow.t_max = kInf;
        } else {
            shadow.d = light.position - p;  // t = 1 at the light
            shadow.t_max = 1.0;
        }
        if (surfaces) visibility = surfaces(shadow);
        if (visibility > 0.0) visibility *= std::exp(-optical_depth(shadow));
    }
    return inc.factor * ((ambient ? light.ambient_intensity : 0.0) + light.intensity * visibility);
}

void GasVolume::split_points(const Light& light, const Ray& ray, double a, double b, std::vector<double>& out) const {
    // Roots are solved around the piece's midpoint, so that a far camera costs no precision.
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    const Vec3 pm = ray.at(mid);
    const Vec3& u = ray.d;
    auto keep = [&](int n, const double* s) {
        for (int i = 0; i < n; ++i)
            if (std::abs(s[i]) < half) out.push_back(mid + s[i]);
    };
    double s[2];
    if (light.kind != LightKind::Directional) {
        const Vec3 w0 = pm - light.position;
        // Where the light's radius ends (weight jumps to 0).
        keep(quadratic_roots(glm::dot(u, u), 2.0 * glm::dot(w0, u), glm::dot(w0, w0) - light.radius * light.radius, s),
             s);
        if (light.kind == LightKind::Spot) {
            const Vec3& D = light.direction;
            for (double angle : {light.cutoff_angle, light.beam_width}) {
                if (!(angle > 0.0 && angle < kPi)) continue;
                const double c2 = std::cos(angle) * std::cos(angle);
                const double uD = glm::dot(u, D), wD = glm::dot(w0, D);
                int n = quadratic_roots(uD * uD - c2 * glm::dot(u, u), 2.0 * (wD * uD - c2 * glm::dot(w0, u)),
                                        wD * wD - c2 * glm::dot(w0, w0), s);
                keep(n, s);
            }
        }
    }
    if (light.headlight || spheres_.empty()) return;
    // Spheres that can shadow the piece: those meeting its light fan. For each, where the path to the
    // light touches the sphere's silhouette (the camera ray meets its shadow cylinder or cone).
    const Fan fan = light_fan(light, ray.at(a), ray.at(b), bounds_);
    thread_local std::vector<uint32_t> stack;
    stack.assign(1, 0);
    while (!stack.empty()) {
        const uint32_t ni = stack.back();
        stack.pop_back();
        const BvhNode& n = bvh_.nodes[ni];
        const Vec3 lo(n.lo[0], n.lo[1], n.lo[2]), hi(n.hi[0], n.hi[1], n.hi[2]);
        if (!fan_overlaps_box(fan, lo, hi)) continue;
        if (n.count == 0) {
            stack.push_back(ni + 1);
            stack.push_back(n.offset);
            continue;
        }
        for (uint32_t i = n.offset; i < n.offset + n.count; ++i) {
            const GasSphere& g = spheres_[bvh_.order[i]];
            if (!fan_meets_sphere(fan, g.center, g.radius)) continue;
            const double r2 = g.radius * g.radius;
            if (light.kind == LightKind::Directional) {
                const Vec3& l = light.direction;
                const Vec3 q0 = pm - g.center;
                const Vec3 q0p = q0 - glm::dot(q0, l) * l, up = u - glm::dot(u, l) * l;
                keep(quadratic_roots(glm::dot(up, up), 2.0 * glm::dot(q0p, up), glm::dot(q0p, q0p) - r2, s), s);
            } else {
                const Vec3 m = g.center - light.position, w0 = pm - light.position;
                const double k = glm::dot(m, m) - r2, mu = glm::dot(m, u), mw = glm::dot(m, w0);
                keep(quadratic_roots(k * glm::dot(u, u) - mu * mu, 2.0 * (k * glm::dot(w0, u) - mw * mu),
                                     k * glm::dot(w0, w0) - mw * mw, s),
                     s);
            }
        }
    }
}

GasVolume::Result GasVolume::integrate(const Ray& ray, double t_end, const Lighting& lighting, double tolerance,
                                       GasStats& stats) const {
    Result result;
    if (spheres_.empty()) return result;
    // Pieces of constant sphere membership, front to back.
    struct Piece {
        double a, b, T, sigma;
    };
    thread_local std::vector<Event> events;
    thread_local std::vector<uint32_t> active;
    thread_local std::vector<Piece> pieces;
    thread_local std::vector<Vec3> coef;  // [piece * n_lights + light]: sigma*rho of the spheres it reaches
    collect_events(ray, t_end, events);
    const size_t n_lights = lighting.lights ? lighting.lights->size() : 0;
    active.clear();
    pieces.clear();
    coef.clear();
    double T = 1.0;
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
                    for (uint32_t l : (*lighting.light_sets)[g.light_set]) coef[base + l] += g.sigma_rho;
            }
            const double x = sigma * width;
            const double exact = width * one_minus_exp_over_x(x);  // integral of exp(-sigma (t - a))
            // Emission, and every light term constant along the piece, in closed form.
            L += T * exact * sigma_e;
            if (lighting.headlight) {
                const Light& h = *lighting.headlight;
                L += T * exact * (h.ambient_intensity + h.intensity) * sigma_rho * h.color;
            }
            for (size_t li = 0; li < n_lights; ++li) {
                const Light& light = (*lighting.lights)[li];
                if (light.kind == LightKind::Directional)  // att = spot = 1: the ambient term is constant
                    L += T * exact * light.ambient_intensity * coef[base + li] * light.color;
            }
            ++stats.pieces;
            pieces.push_back({a, b, T, sigma});
            T *= std::exp(-x);
        }
        if (e.enter) {
            active.push_back(e.sphere);
        } else {
            auto it = std::find(active.begin(), active.end(), e.sphere);
            if (it != active.end()) active.erase(it);
        }
        prev = std::max(prev, e.t);
    }
    // The rest of each light's term varies along a piece (shadows, attenuation, spot): integrated over the
    // whole ray at once, so that the error goes where the light is, to tolerance * the light's total.
    thread_local std::vector<Panel> panels;
    thread_local std::vector<double> cuts;
    thread_local std::vector<std::pair<double, uint32_t>> order;
    for (size_t li = 0; li < n_lights; ++li) {
        const Light& light = (*lighting.lights)[li];
        const bool ambient_varies = light.kind != LightKind::Directional;
        const double w_max = (ambient_varies ? light.ambient_intensity : 0.0) + light.intensity;
        if (!(w_max > 0.0)) continue;
        // Scalar weight of a piece (its colour factor's largest channel), and a bound on its integral:
        // w <= w_max since att, spot and V are at most 1.
        auto scale = [&](size_t p) {
            const Vec3 c = coef[p * n_lights + li] * light.color;
            return std::max(c.x, std::max(c.y, c.z));
        };
        order.clear();
        double remaining = 0.0;
        for (size_t p = 0; p < pieces.size(); ++p) {
            const double s = scale(p);
            if (!(s > 0.0)) continue;
            const Piece& pc = pieces[p];
            const double bound = pc.T * s * w_max * (pc.b - pc.a) * one_minus_exp_over_x(pc.sigma * (pc.b - pc.a));
            order.push_back({bound, uint32_t(p)});
            remaining += bound;
        }
        if (order.empty()) continue;
        std::sort(order.begin(), order.end(), [](auto& x, auto& y) { return x.first > y.first; });
        auto integrand = [&](uint32_t p) {
            const Piece& pc = pieces[p];
            const double s = scale(p);
            return [&, p, s](double t) {
                return pc.T * s * std::exp(-pc.sigma * (t - pc.a)) *
                       light_weight(light, ray.at(t), ambient_varies, lighting.surfaces, stats);
            };
        };
        // Pieces in order of their bound; once the bounds of all the rest are below a quarter of the
        // tolerance times what has been found so far (a lower bound of the total), they are left out.
        panels.clear();
        double found = 0.0;
        for (const auto& [bound, p] : order) {
            if (remaining <= 0.25 * tolerance * found) break;
            remaining -= bound;
            const Piece& pc = pieces[p];
            cuts.clear();
            cuts.push_back(pc.a);
            split_points(light, ray, pc.a, pc.b, cuts);
            cuts.push_back(pc.b);
            std::sort(cuts.begin() + 1, cuts.end() - 1);
            auto f = integrand(p);
            for (size_t i = 0; i + 1 < cuts.size(); ++i) {
                if (!(cuts[i + 1] > cuts[i])) continue;
                panels.push_back(gauss_kronrod(f, cuts[i], cuts[i + 1], p));
                found += panels.back().value;
            }
            ++stats.quadrature;
        }
        // Global adaptive refinement (QUADPACK's QAG idea) to three quarters of the tolerance.
        auto by_error = [](const Panel& x, const Panel& y) { return x.error < y.error; };
        std::make_heap(panels.begin(), panels.end(), by_error);
        const size_t max_panels = panels.size() + 2000;
        for (;;) {
            double value = 0.0, error = 0.0;
            for (const Panel& pn : panels) {
                value += pn.value;
                error += pn.error;
            }
            if (error <= 0.75 * tolerance * std::abs(value) || error == 0.0 || panels.size() >= max_panels) break;
            std::pop_heap(panels.begin(), panels.end(), by_error);
            const Panel worst = panels.back();
            panels.pop_back();
            const double mid = 0.5 * (worst.a + worst.b);
            if (!(mid > worst.a && mid < worst.b)) {  // cannot split further in double: keep it as it is
                panels.push_back({worst.a, worst.b, worst.value, 0.0, worst.piece});
                std::push_heap(panels.begin(), panels.end(), by_error);
                continue;
            }
            auto f = integrand(worst.piece);
            panels.push_back(gauss_kronrod(f, worst.a, mid, worst.piece));
            std::push_heap(panels.begin(), panels.end(), by_error);
            panels.push_back(gauss_kronrod(f, mid, worst.b, worst.piece));
            std::push_heap(panels.begin(), panels.end(), by_error);
        }
        for (const Panel& pn : panels) {
            const double s = scale(pn.piece);
            if (s > 0.0) L += (pn.value / s) * coef[pn.piece * n_lights + li] * light.color;
        }
    }
    result.radiance = L;
    result.transmittance = T;
    return result;
}

GasVolume::Result GasVolume::integrate_reference(const Ray& ray, double t_end, const Lighting& lighting,
                                                 int steps) const {
    Result result;
    if (spheres_.empty()) return result;
    std::vector<Event> events;
    collect_events(ray, t_end, events);
    std::vector<uint32_t> active;
    GasStats stats;
    double T = 1.0;
    Vec3 L(0.0);
    double prev = 0.0;
    for (const Event& e : events) {
        if (!active.empty() && e.t > prev) {
            const double a = prev, b = e.t, h = (b - a) / steps;
            double sigma = 0.0;
            Vec3 sigma_e(0.0);
            for (uint32_t id : active) {
                sigma += spheres_[id].sigma;
                sigma_e += spheres_[id].sigma_e;
            }
            L += T * (b - a) * one_minus_exp_over_x(sigma * (b - a)) * sigma_e;
            for (int k = 0; k < steps; ++k) {
                const double t = a + (k + 0.5) * h;
                const double w = h * std::exp(-sigma * (t - a));
                const Vec3 p = ray.at(t);
                for (uint32_t id : active) {
                    const GasSphere& g = spheres_[id];
                    if (lighting.headlight) {
                        const Light& hl = *lighting.headlight;
                        L += T * w * (hl.ambient_intensity + hl.intensity) * g.sigma_rho * hl.color;
                    }
                    if (!lighting.lights) continue;
                    for (uint32_t l : (*lighting.light_sets)[g.light_set]) {
                        const Light& light = (*lighting.lights)[l];
                        L += T * w * light_weight(light, p, true, lighting.surfaces, stats) * g.sigma_rho * light.color;
                    }
                }
            }
            T *= std::exp(-sigma * (b - a));
        }
        if (e.enter) {
            active.push_back(e.sphere);
        } else {
            auto it = std::find(active.begin(), active.end(), e.sphere);
            if (it != active.end()) active.erase(it);
        }
        prev = std::max(prev, e.t);
    }
    result.radiance = L;
    result.transmittance = T;
    return result;
}

}  // namespace vr

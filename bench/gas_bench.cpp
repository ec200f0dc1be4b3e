// Gas integrator alone: times GasVolume::integrate over a camera's pixels and measures its error
// against the brute-force oracle of tests/support/gas_reference.h, without the image library or the
// rest of the renderer, so that it runs under callgrind (see Build below) and so that two versions
// of src/render/gas.cpp can be compared on the same rays.
//
//   gas_bench SCENE.wrl [--size W H] [--density D] [--albedo R,G,B] [--emission R,G,B]
//             [--tolerance T]... [--reps N] [--check N] [--steps S] [--reference FILE]
//
// SCENE is any scene vrmlray reads (e.g. one written by the peer harness's generator,
// ../shared/bench/gen_scene.py, or by tools/gen_molecule.py --no-bonds): it is read, built and
// flattened as `vrmlray render --spheres gas` does, and the rays come from its first Viewpoint
// (else the default camera). Every sphere is gas with sigma = --density, albedo = diffuseColor and
// emission = emissiveColor unless --albedo/--emission (or the file's hints) say otherwise.
//
// For each tolerance: the median over --reps of the seconds to integrate every pixel (one thread),
// the integrator's counters, and with --check N the error on N pixels spread over the image whose
// ray meets the gas: the largest and the median relative error of the scattered (lit) radiance,
// channel by channel, against integrate_gas_reference with --steps steps per piece. The references
// are written to / read from --reference so that they are computed once. Build it with
// -DVRMLRAY_BENCH=ON (for callgrind, which knows no AVX-512, also -DVRMLRAY_NATIVE=OFF) and `cmake
// --build BUILD
// --target gas_bench`,
//
// and count instructions of the integrator alone with
//   valgrind --tool=callgrind "--toggle-collect=vr::GasVolume::integrate(vr::Ray const&, double,
//       vr::GasVolume::Lighting const&, double, vr::GasStats&) const" BUILD/bench/gas_bench SCENE
//       ...
// (the full signature: a pattern would also match the integrator's lambdas and stop counting inside
// them).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/gas.h"
#include "scene/build.h"
#include "support/gas_reference.h"

namespace {

using namespace vr;

struct BenchScene {
    FlatScene flat;
    Vec3 eye{0.0, 0.0, 10.0};
    Mat3 world_from_camera{1.0};
    double fov = 0.785398;
};

// The scene as vrmlray render --spheres gas sees it: the project's reader, scene build and
// flattening.
bool read_scene(const char* path, const FlattenOptions& flatten_options, BenchScene& out,
                std::string& error) {
    const LoadedScene loaded = load_scene(path);
    Diagnostics diagnostics;
    if (!loaded.ok()) {
        error = loaded.diagnostics.format(loaded.sources);
        return false;
    }
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenStats stats;
    out.flat = flatten_scene(scene, flatten_options, diagnostics, stats);
    if (!out.flat.viewpoints.empty()) {
        const Viewpoint& v = out.flat.viewpoints.front();
        out.eye = v.position;
        out.world_from_camera = v.world_from_camera;
        out.fov = v.field_of_view;
    }
    if (out.flat.spheres.empty()) {
        error = "no spheres";
        return false;
    }
    return true;
}

bool parse_vec3(const char* s, Vec3& v) {
    return std::sscanf(s, "%lf,%lf,%lf", &v.x, &v.y, &v.z) == 3;
}

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(
            stderr,
            "usage: %s SCENE.wrl [--size W H] [--density D] [--albedo R,G,B] [--emission R,G,B]\n"
            "          [--tolerance T]... [--reps N] [--check N] [--steps S] [--reference FILE]\n",
            argv[0]);
        return 2;
    }
    int width = 160, height = 120, reps = 3, check = 0, steps = 40000;
    std::vector<double> tolerances;
    std::string reference_file;
    RenderOptions options;
    options.threads = 1;
    std::optional<Vec3> albedo, emission;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        const bool more = i + 1 < argc;
        if (a == "--size" && i + 2 < argc) {
            width = std::atoi(argv[++i]);
            height = std::atoi(argv[++i]);
        } else if (a == "--density" && more) {
            options.density = std::atof(argv[++i]);
        } else if (a == "--albedo" && more) {
            Vec3 v;
            if (parse_vec3(argv[++i], v)) albedo = v;
        } else if (a == "--emission" && more) {
            Vec3 v;
            if (parse_vec3(argv[++i], v)) emission = v;
        } else if (a == "--tolerance" && more) {
            tolerances.push_back(std::atof(argv[++i]));
        } else if (a == "--reps" && more) {
            reps = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--check" && more) {
            check = std::atoi(argv[++i]);
        } else if (a == "--steps" && more) {
            steps = std::atoi(argv[++i]);
        } else if (a == "--reference" && more) {
            reference_file = argv[++i];
        } else {
            std::fprintf(stderr, "unknown argument %s\n", a.c_str());
            return 2;
        }
    }
    if (tolerances.empty()) tolerances = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
    FlattenOptions flatten_options;
    flatten_options.spheres = SpheresOption::Gas;
    flatten_options.density = options.density;
    flatten_options.albedo = albedo;
    flatten_options.emission = emission;
    flatten_options.scene_file = argv[1];
    BenchScene scene;
    std::string error;
    if (!read_scene(argv[1], flatten_options, scene, error)) {
        std::fprintf(stderr, "%s: %s\n", argv[1], error.c_str());
        return 3;
    }
    GasVolume gas;
    gas.build(scene.flat, options);
    GasVolume::Lighting lighting;
    lighting.lights = &scene.flat.lights;
    lighting.light_sets = &scene.flat.light_sets;

    // Camera rays through the pixel centres; fieldOfView spans the smaller image dimension
    // (docs/manual.md, Camera).
    const Vec3 right = scene.world_from_camera[0], up = scene.world_from_camera[1],
               forward = -scene.world_from_camera[2];
    const double scale = std::tan(0.5 * scene.fov) / (0.5 * std::min(width, height));
    auto pixel_ray = [&](int x, int y) {
        Ray r;
        r.o = scene.eye;
        r.d = glm::normalize(forward + ((x + 0.5 - 0.5 * width) * scale) * right +
                             ((0.5 * height - y - 0.5) * scale) * up);
        return r;
    };
    std::printf("%s: %zu gas spheres, %zu lights, %dx%d\n", argv[1], gas.size(),
                scene.flat.lights.size(), width, height);

    // Pixels to check: every k-th pixel whose ray meets the gas (transmittance < 1).
    std::vector<int> checked;
    std::vector<Vec3> reference;
    if (check > 0) {
        std::vector<int> in_gas;
        GasVolume::Lighting dark;
        for (int p = 0; p < width * height; ++p) {
            GasStats st;
            if (gas.integrate(pixel_ray(p % width, p / width), kInf, dark, 1e-2, st).transmittance <
                1.0)
                in_gas.push_back(p);
        }
        for (int k = 0; k < check && !in_gas.empty(); ++k)
            checked.push_back(in_gas[size_t(k) * in_gas.size() / size_t(check)]);
        std::ifstream in(reference_file);
        if (in) {
            int n = 0, s = 0;
            in >> n >> s;
            if (n == int(checked.size()) && s == steps) {
                reference.resize(checked.size());
                for (Vec3& v : reference) in >> v.x >> v.y >> v.z;
                if (!in) reference.clear();
            }
        }
        if (reference.empty()) {
            const double t0 = now();
            for (int p : checked)
                reference.push_back(integrate_gas_reference(gas, pixel_ray(p % width, p / width),
                                                            kInf, lighting, steps)
                                        .radiance);
            std::printf("reference: %zu pixels, %d steps per piece, %.1f s\n", checked.size(),
                        steps, now() - t0);
            if (!reference_file.empty()) {
                std::ofstream o(reference_file);
                o.precision(17);
                o << checked.size() << ' ' << steps << '\n';
                for (const Vec3& v : reference) o << v.x << ' ' << v.y << ' ' << v.z << '\n';
            }
        }
    }
    // The emission and the constant light terms are exact; the error is measured on the rest.
    auto exact_part = [&](const Ray& r) {
        GasVolume::Lighting constant;
        std::vector<Light> ambient_only;
        for (Light l : scene.flat.lights) {
            l.intensity = 0.0;
            ambient_only.push_back(l);
        }
        constant.lights = &ambient_only;
        constant.light_sets = &scene.flat.light_sets;
        GasStats st;
        return gas.integrate(r, kInf, constant, 1e-12, st).radiance;
    };
    std::vector<Vec3> exact;
    for (int p : checked) exact.push_back(exact_part(pixel_ray(p % width, p / width)));

    std::printf("%10s %10s %12s %14s %12s %12s %12s\n", "tolerance", "seconds", "pieces",
                "quadrature", "vis/pixel", "max rel err", "median rel");
    for (double tol : tolerances) {
        std::vector<double> times;
        GasStats stats;
        double sum = 0.0;
        for (int rep = 0; rep < reps; ++rep) {
            GasStats st;
            double s = 0.0;
            const double t0 = now();
            for (int y = 0; y < height; ++y)
                for (int x = 0; x < width; ++x) {
                    const GasVolume::Result g =
                        gas.integrate(pixel_ray(x, y), kInf, lighting, tol, st);
                    s += g.radiance.x + g.radiance.y + g.radiance.z;
                }
            times.push_back(now() - t0);
            stats = st;
            sum = s;
        }
        std::sort(times.begin(), times.end());
        std::vector<double> errors;
        for (size_t k = 0; k < checked.size(); ++k) {
            const int p = checked[k];
            GasStats st;
            const Vec3 got =
                gas.integrate(pixel_ray(p % width, p / width), kInf, lighting, tol, st).radiance;
            double e = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double lit = reference[k][c] - exact[k][c];
                if (lit > 1e-300) e = std::max(e, std::abs(got[c] - reference[k][c]) / lit);
            }
            errors.push_back(e);
        }
        std::sort(errors.begin(), errors.end());
        std::printf("%10.0e %10.3f %12llu %14llu %12.1f", tol, times[times.size() / 2],
                    (unsigned long long)stats.pieces, (unsigned long long)stats.quadrature,
                    double(stats.visibility_rays) / (width * height));
        if (errors.empty())
            std::printf(" %12s %12s", "-", "-");
        else
            std::printf(" %12.2e %12.2e", errors.back(), errors[errors.size() / 2]);
        std::printf("   (sum %.9g)\n", sum);
    }
    return 0;
}

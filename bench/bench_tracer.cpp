// Tracer-only benchmark: reads a scene in the peer harness's binary format (../shared/bench,
// written by `gen_scene.py --formats bin`), builds the FlatScene directly (no parser) and times the
// BVH build and the render, best of several repetitions, the way the harness times Embree and
// Tachyon.
//
//   bench_tracer SCENE.bin [--size W H] [--threads N] [--reps N] [--out FILE.ppm]
//
// Not built by default (it needs the harness's scenes): configure with -DVRMLRAY_BENCH=ON and
// `cmake --build BUILD --target bench_tracer` (it links the render layer alone).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "render/render.h"

namespace {

using namespace vr;

double cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The harness format: a text header (camera, lights, background, materials, counts) ended by
// "BINARY", then float32 spheres (x y z r), uint32 sphere materials, float32 cylinders
// (x0 y0 z0 x1 y1 z1 r, open ends), uint32 cylinder materials.
bool load_bench_scene(const char* path, FlatScene& scene, int& width, int& height,
                      std::string& error) {
    std::ifstream f(path, std::ios::binary);
    if (!f) {
        error = std::string("cannot open ") + path;
        return false;
    }
    scene = FlatScene();
    scene.headlight = false;
    scene.light_sets.emplace_back();
    size_t sphere_count = 0, cylinder_count = 0;
    std::string line;
    bool binary = false;
    while (std::getline(f, line)) {
        if (line == "BINARY") {
            binary = true;
            break;
        }
        std::istringstream in(line);
        std::string key;
        in >> key;
        if (key == "resolution") {
            in >> width >> height;
        } else if (key == "camera") {
            Viewpoint v;
            Vec3 forward, up;
            in >> v.position.x >> v.position.y >> v.position.z >> forward.x >> forward.y >>
                forward.z >> up.x >> up.y >> up.z >> v.field_of_view;
            forward = glm::normalize(forward);
            const Vec3 right = glm::normalize(glm::cross(forward, up));
            v.world_from_camera = Mat3(right, glm::cross(right, forward), -forward);
            scene.viewpoints.push_back(v);
        } else if (key == "light") {
            std::string kind;
            Vec3 a, color;
            in >> kind >> a.x >> a.y >> a.z >> color.x >> color.y >> color.z;
            Light l;
            l.color = color;
            l.ambient_intensity = 1.0;  // as the harness's .wrl writes it
            if (kind == "point") {
                l.kind = LightKind::Point;
                l.position = a;
                l.radius = 1e9;
            } else {
                l.direction = glm::normalize(a);
            }
            scene.lights.push_back(l);
            scene.light_sets[0].push_back(uint32_t(scene.lights.size() - 1));
        } else if (key == "background") {
            Vec3 b;
            in >> b.x >> b.y >> b.z;
            scene.background.sky_colors = {b};
            scene.background.present = true;
        } else if (key == "material") {
            Material m;
            double exponent;
            in >> m.diffuse.x >> m.diffuse.y >> m.diffuse.z >> m.specular.x >> m.specular.y >>
                m.specular.z >> exponent >> m.ambient_intensity;
            m.shininess = exponent / 128.0;
            scene.materials.push_back(m);
            Shading s;
            s.material = uint32_t(scene.materials.size() - 1);
            scene.shadings.push_back(s);
        } else if (key == "spheres") {
            in >> sphere_count;
        } else if (key == "cylinders") {
            in >> cylinder_count;
        }
    }
    if (!binary) {
        error = "no BINARY section";
        return false;
    }
    std::vector<float> spheres(sphere_count * 4), cylinders(cylinder_count * 7);
    std::vector<uint32_t> sphere_material(sphere_count), cylinder_material(cylinder_count);
    f.read(reinterpret_cast<char*>(spheres.data()), std::streamsize(spheres.size() * 4));
    f.read(reinterpret_cast<char*>(sphere_material.data()),
           std::streamsize(sphere_material.size() * 4));
    f.read(reinterpret_cast<char*>(cylinders.data()), std::streamsize(cylinders.size() * 4));
    f.read(reinterpret_cast<char*>(cylinder_material.data()),
           std::streamsize(cylinder_material.size() * 4));
    if (!f) {
        error = "truncated binary data";
        return false;
    }
    for (size_t i = 0; i < sphere_count; ++i) {
        Sphere s;
        s.center = Vec3(spheres[4 * i], spheres[4 * i + 1], spheres[4 * i + 2]);
        s.radius = spheres[4 * i + 3];
        s.shading = sphere_material[i];
        scene.spheres.push_back(s);
    }
    for (size_t i = 0; i < cylinder_count; ++i) {
        const float* c = &cylinders[7 * i];
        const Vec3 a(c[0], c[1], c[2]), b(c[3], c[4], c[5]);
        const double length = glm::length(b - a);
        const Vec3 y = (b - a) / length;
        const Vec3 x =
            glm::normalize(glm::cross(y, std::fabs(y.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
        Quadric q;
        q.kind = QuadricKind::Cylinder;
        q.size = Vec3(2.0 * c[6], length, 2.0 * c[6]);
        q.top = q.bottom = false;
        q.shading = cylinder_material[i];
        q.world_from_object =
            Mat4(Vec4(x, 0.0), Vec4(y, 0.0), Vec4(glm::cross(x, y), 0.0), Vec4(0.5 * (a + b), 1.0));
        q.object_from_world = glm::inverse(q.world_from_object);
        scene.quadrics.push_back(q);
    }
    return true;
}

void write_ppm(const char* path, const Image& image) {
    FILE* out = std::fopen(path, "wb");
    if (!out) return;
    std::fprintf(out, "P6\n%d %d\n255\n", image.width, image.height);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c)
                std::fputc(int(std::clamp(image.pixel(x, y)[c], 0.0f, 1.0f) * 255.0f + 0.5f), out);
    std::fclose(out);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: %s SCENE.bin [--size W H] [--threads N] [--reps N] [--out FILE.ppm]\n",
                     argv[0]);
        return 2;
    }
    FlatScene scene;
    int width = 640, height = 480, threads = 0, reps = 3;
    const char* out = nullptr;
    std::string error;
    if (!load_bench_scene(argv[1], scene, width, height, error)) {
        std::fprintf(stderr, "%s: %s\n", argv[1], error.c_str());
        return 3;
    }
    for (int i = 2; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--size") && i + 2 < argc) {
            width = std::atoi(argv[++i]);
            height = std::atoi(argv[++i]);
        } else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
            threads = std::atoi(argv[++i]);
        } else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = std::max(1, std::atoi(argv[++i]));
        } else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) {
            out = argv[++i];
        }
    }
    RenderOptions options;
    options.width = width;
    options.height = height;
    options.threads = threads;
    options.max_depth = 1;  // the harness renders no reflections
    Camera camera;
    if (!make_camera(scene, options, camera, error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 2;
    }
    double best_build = 1e300, best_render = 1e300, best_cpu = 1e300;
    RenderStats stats;
    Image image;
    for (int r = 0; r < reps; ++r) {
        const double cpu0 = cpu_seconds();
        image = render_image(scene, camera, options, nullptr, stats);
        best_cpu = std::min(best_cpu, cpu_seconds() - cpu0);
        best_build = std::min(best_build, stats.build_seconds);
        best_render = std::min(best_render, stats.render_seconds);
    }
    const double rays = double(stats.primary_rays + stats.shadow_rays + stats.secondary_rays);
    std::printf(
        "%s %dx%d threads=%d: build %.3f s, render %.3f s, %.2f Mrays/s (best of %d); cpu %.3f s; "
        "%llu primary + %llu shadow rays; %zu primitives, %zu BVH nodes\n",
        argv[1], width, height, threads, best_build, best_render, rays / best_render * 1e-6, reps,
        best_cpu, static_cast<unsigned long long>(stats.primary_rays),
        static_cast<unsigned long long>(stats.shadow_rays), stats.primitives, stats.bvh_nodes);
    if (out) write_ppm(out, image);
    return 0;
}

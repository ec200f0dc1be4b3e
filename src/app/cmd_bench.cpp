// vrmlray bench SCENE: speed against error (SPEC section 11). The scene is read and flattened once; then a
// reference image is read (--reference) or rendered at a much higher setting, and a ladder of settings is
// rendered and measured against it: seconds, rays/s, RMSE, PSNR, max error, SSIM. The table goes to the
// terminal and to a CSV file, and error against time to a log-log plot.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "app/commands.h"
#include "app/pipeline.h"
#include "image/compare.h"
#include "image/image.h"
#include "image/plot.h"
#include "render/flatten.h"
#include "render/render.h"

namespace vr {
namespace {

struct Setting {
    std::string series;  // the plot line it belongs to
    std::string sampler;
    int spp = 1;
    double tolerance = 1e-4;
};

struct Row {
    Setting setting;
    double seconds = 0, rays_per_second = 0;
    CompareMetrics metrics;
};

bool render_once(const FlatScene& flat, const RenderOptions& base, const Setting& s, Image& image,
                 RenderStats& stats, std::string& error) {
    RenderOptions o = base;
    o.sampler = s.sampler;
    o.spp = s.spp;
    o.tolerance = s.tolerance;
    Camera camera;
    if (!make_camera(flat, o, camera, error)) return false;
    image = render_image(flat, camera, o, {}, stats);
    return true;
}

std::string stem_of(const std::string& scene) {
    std::filesystem::path p = std::filesystem::path(scene).filename();
    while (p.has_extension()) p = p.stem();
    return p.string();
}

}  // namespace

int run_bench(const BenchCommand& cmd) {
    LoadedScene loaded;
    if (!load_and_report(cmd.scene, cmd.common, loaded)) return kExitBadInput;
    FlatScene flat;
    FlattenStats fs;
    if (!build_and_flatten(loaded, cmd.options, std::nullopt, cmd.common.quiet, flat, fs)) return kExitBadInput;
    const bool gas = std::any_of(flat.spheres.begin(), flat.spheres.end(), [](const Sphere& s) { return s.gas; });

    // The ladder: every sampler at rising spp; for gas scenes also rising integrator accuracy.
    std::vector<Setting> ladder;
    ladder.push_back({"center", "center", 1, cmd.options.tolerance});
    for (int n : {2, 3, 4, 6}) ladder.push_back({"grid", "grid", n * n, cmd.options.tolerance});
    if (gas)
        for (double tol : {1e-1, 1e-2, 1e-3, 1e-4, 1e-6}) ladder.push_back({"gas tolerance", "center", 1, tol});
    const std::string stem = stem_of(cmd.scene);
    const std::string csv_path = cmd.csv.empty() ? stem + "-bench.csv" : cmd.csv;
    const std::string plot_path = cmd.plot.empty() ? stem + "-bench.png" : cmd.plot;

    // Reference: given, or rendered at 8x8 samples (and 1e-8 gas tolerance) and cached.
    Image reference;
    std::string error;
    std::string ref_path = cmd.reference;
    if (ref_path.empty()) {
        ref_path = stem + "-reference-" + std::to_string(cmd.options.width) + "x" +
                   std::to_string(cmd.options.height) + ".exr";
        if (!std::filesystem::exists(ref_path)) {
            if (!cmd.common.quiet) std::cerr << "rendering the reference (grid 8x8" << (gas ? ", tolerance 1e-8" : "") << ") ...\n";
            RenderStats stats;
            if (!render_once(flat, cmd.options, {"reference", "grid", 64, 1e-8}, reference, stats, error)) {
                std::cerr << "vrmlray: error: " << error << "\n";
                return kExitUsage;
            }
            if (!write_image(ref_path, reference, false, error)) {
                std::cerr << "vrmlray: error: " << error << "\n";
                return kExitOutput;
            }
        }
    }
    if (reference.width == 0 && !read_image(ref_path, reference, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }

    std::vector<Row> rows;
    std::printf("%-14s %-8s %5s %9s %10s %11s %11s %9s %10s %8s\n", "series", "sampler", "spp", "tolerance",
                "seconds", "Mrays/s", "RMSE", "PSNR dB", "max err", "SSIM");
    for (const Setting& s : ladder) {
        std::vector<double> seconds;
        Row row;
        row.setting = s;
        Image image;
        for (int run = 0; run < std::max(1, cmd.runs); ++run) {
            RenderStats stats;
            if (!render_once(flat, cmd.options, s, image, stats, error)) {
                std::cerr << "vrmlray: error: " << error << "\n";
                return kExitUsage;
            }
            seconds.push_back(stats.render_seconds);
            row.rays_per_second = stats.rays_per_second();
        }
        std::sort(seconds.begin(), seconds.end());
        row.seconds = seconds[seconds.size() / 2];  // median
        if (!compare_images(image, reference, 1.0 / 255.0, row.metrics, error)) {
            std::cerr << "vrmlray: error: " << error << " (reference " << ref_path << ")\n";
            return kExitBadInput;
        }
        std::fflush(stdout);
        std::printf("%-14s %-8s %5d %9.0e %10.4f %11.3f %11.3e %9.2f %10.3e %8.5f\n", s.series.c_str(),
                    s.sampler.c_str(), s.spp, s.tolerance, row.seconds, row.rays_per_second * 1e-6,
                    row.metrics.rmse, row.metrics.psnr, row.metrics.max_abs, row.metrics.ssim);
        rows.push_back(row);
    }

    std::ofstream csv(csv_path);
    csv << "series,sampler,spp,tolerance,seconds,rays_per_second,rmse,psnr,max_abs,ssim\n";
    for (const Row& r : rows) {
        csv << r.setting.series << ',' << r.setting.sampler << ',' << r.setting.spp << ',' << r.setting.tolerance << ','
            << r.seconds << ',' << r.rays_per_second << ',' << r.metrics.rmse << ',' << r.metrics.psnr << ','
            << r.metrics.max_abs << ',' << r.metrics.ssim << '\n';
    }
    if (!csv) {
        std::cerr << "vrmlray: error: cannot write " << csv_path << "\n";
        return kExitOutput;
    }
    std::map<std::string, PlotSeries> lines;
    for (const Row& r : rows) {
        PlotSeries& line = lines[r.setting.series];
        line.label = r.setting.series;
        // A zero error cannot sit on a log axis; it is left out of the plot (the CSV keeps it).
        if (r.metrics.rmse > 0.0 && r.seconds > 0.0) {
            line.x.push_back(r.seconds);
            line.y.push_back(r.metrics.rmse);
        }
    }
    std::vector<PlotSeries> series;
    for (auto& [name, line] : lines) series.push_back(line);
    PlotOptions po;
    po.title = "RMSE vs time: " + stem;
    if (!write_image(plot_path, plot_series(series, po), false, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitOutput;
    }
    if (!cmd.common.quiet) std::cerr << "wrote " << csv_path << " and " << plot_path << " (reference " << ref_path << ")\n";
    return kExitOk;
}

}  // namespace vr

// vrmlray bench SCENE: speed against error (docs/manual.md, bench). The scene is read and flattened
// once; then a reference image is read (--reference) or rendered at a much higher setting, and a
// ladder of settings is rendered and measured against it: seconds, rays/s, RMSE, PSNR, max error,
// SSIM. The table goes to the terminal and to a CSV file, and error against time to a log-log plot.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "app/commands.h"
#include "app/pipeline.h"
#include "flatten/flatten.h"
#include "image/image.h"
#include "qa/compare.h"
#include "qa/plot.h"
#include "render/render.h"

namespace vr {
namespace {

struct Setting {
    std::string
        series;  // the plot line it belongs to: the sampler, "gas tolerance" or "light tolerance"
    SamplerKind sampler = SamplerKind::Center;
    int spp = 1;
    double threshold =
        0.0;  // adaptive: --adaptive-threshold; statistical: --noise-threshold; else unused
    double tolerance = 1e-4;
    int depth = kDefaultAdaptiveDepth;  // adaptive: --adaptive-depth
    double light_tolerance = 0.0;       // --light-tolerance; 0: the command line's
};

// The light tolerance series' reference is this much tighter than its tightest setting.
constexpr double kLightReferenceTolerance = 1e-4;

struct Row {
    Setting setting;
    double seconds = 0, rays_per_second = 0, rays_per_pixel = 0;
    CompareMetrics metrics;
};

bool render_once(const FlatScene& flat, const RenderOptions& base, const Setting& s, Image& image,
                 RenderStats& stats, std::string& error) {
    RenderOptions o = base;
    o.sampler = s.sampler;
    o.spp = s.spp;
    o.tolerance = s.tolerance;
    if (s.light_tolerance > 0.0) o.light_tolerance = s.light_tolerance;
    if (s.sampler == SamplerKind::Adaptive) {
        o.adaptive_threshold = s.threshold;
        o.adaptive_depth = s.depth;
    }
    if (s.sampler == SamplerKind::Statistical) o.noise_threshold = s.threshold;
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

// The default ladder: each sampler at rising cost (spp, or a falling threshold -- and for adaptive
// a deeper subdivision, for statistical a higher cap -- for the two that choose their own count),
// all at the given gas tolerance; for gas scenes also the centre sampler at falling integrator
// tolerance.
std::vector<Setting> default_ladder(const std::vector<std::string>& samplers, bool gas,
                                    bool soft_light, double tolerance) {
    std::vector<Setting> ladder;
    auto wanted = [&](const char* name) {
        return samplers.empty() ||
               std::find(samplers.begin(), samplers.end(), name) != samplers.end();
    };
    if (wanted("center")) ladder.push_back({"center", SamplerKind::Center, 1, 0.0, tolerance});
    if (wanted("grid"))
        for (int spp : {4, 9, 16, 36})
            ladder.push_back({"grid", SamplerKind::Grid, spp, 0.0, tolerance});
    if (wanted("rgss"))
        for (int spp : {4, 16, 36})
            ladder.push_back({"rgss", SamplerKind::Rgss, spp, 0.0, tolerance});
    if (wanted("rooks8"))
        for (int spp : {8, 32, 72})
            ladder.push_back({"rooks8", SamplerKind::Rooks8, spp, 0.0, tolerance});
    if (wanted("quincunx"))
        ladder.push_back({"quincunx", SamplerKind::Quincunx, 1, 0.0, tolerance});
    if (wanted("jitter"))
        for (int spp : {4, 16, 64})
            ladder.push_back({"jitter", SamplerKind::Jitter, spp, 0.0, tolerance});
    if (wanted("adaptive"))
        for (auto [t, depth] : {std::pair{0.2, 2}, {0.1, 3}, {0.05, 3}, {0.02, 4}, {0.01, 5}})
            ladder.push_back({"adaptive", SamplerKind::Adaptive, 1, t, tolerance, depth});
    if (wanted("statistical"))
        for (auto [t, cap] : {std::pair{0.05, 64}, {0.02, 256}, {0.01, 1024}, {0.005, 4096}})
            ladder.push_back({"statistical", SamplerKind::Statistical, cap, t, tolerance});
    if (gas && (samplers.empty() || wanted("tolerance")))
        for (double tol : {1e-1, 1e-2, 1e-3, 1e-4, 1e-6})
            ladder.push_back({"gas tolerance", SamplerKind::Center, 1, 0.0, tol});
    if (soft_light && (samplers.empty() || wanted("light-tolerance")))
        // 3e-1: the cheapest setting (8 blocks of 2 directions), often enough to match a peer's
        // noise.
        for (double tol : {3e-1, 1e-1, 3e-2, 1e-2, 3e-3, 1e-3})
            ladder.push_back({"light tolerance", SamplerKind::Center, 1, 0.0, tolerance, 3, tol});
    return ladder;
}

}  // namespace

namespace {

// Which sampler reaches a given error first: the least time among its settings at or below it. The
// gas tolerance series is left out when it was measured against its own reference.
void print_fastest(const std::vector<Row>& rows, bool own_references) {
    std::printf(
        "\nfastest sampler to reach an RMSE (seconds of rendering; '-' = not reached on the "
        "ladder):\n");
    for (double target : {1e-2, 5e-3, 2e-3, 1e-3}) {
        std::map<std::string, double> best;
        for (const Row& r : rows) {
            if (r.metrics.rmse > target) continue;
            if (own_references && r.setting.series != sampler_name(r.setting.sampler)) continue;
            auto [it, fresh] = best.emplace(r.setting.series, r.seconds);
            if (!fresh) it->second = std::min(it->second, r.seconds);
        }
        std::vector<std::pair<double, std::string>> order;
        for (auto& [name, t] : best) order.emplace_back(t, name);
        std::sort(order.begin(), order.end());
        std::printf("  RMSE <= %-7.0e", target);
        if (order.empty()) std::printf(" -");
        for (size_t i = 0; i < order.size() && i < 4; ++i)
            std::printf("%s %s %.4f", i ? "," : "", order[i].second.c_str(), order[i].first);
        std::printf("\n");
    }
}

// The table, one row per setting; false when it cannot be written.
bool write_csv(const std::string& csv_path, const std::vector<Row>& rows) {
    std::ofstream csv(csv_path);
    // light_tolerance last, so that the columns before it stay where scripts read them.
    csv << "series,sampler,spp,threshold,adaptive_depth,tolerance,seconds,rays_per_pixel,rays_per_"
           "second,rmse,psnr,max_abs,ssim,light_tolerance\n";
    for (const Row& r : rows) {
        csv << r.setting.series << ',' << sampler_name(r.setting.sampler) << ',' << r.setting.spp
            << ',' << r.setting.threshold << ','
            << (r.setting.sampler == SamplerKind::Adaptive ? std::to_string(r.setting.depth) : "")
            << ',' << r.setting.tolerance << ',' << r.seconds << ',' << r.rays_per_pixel << ','
            << r.rays_per_second << ',' << r.metrics.rmse << ',' << r.metrics.psnr << ','
            << r.metrics.max_abs << ',' << r.metrics.ssim << ','
            << (r.setting.light_tolerance > 0.0 ? std::to_string(r.setting.light_tolerance) : "")
            << '\n';
    }
    return bool(csv);
}

}  // namespace

namespace {

// References: given (--reference, then used for every series), or rendered and cached under a
// name that holds the settings they depend on: a fine grid (and for gas tolerance 1e-8) for the
// sampler series; for the tolerance series the same centre sampling at a much tighter tolerance
// (gas 1e-8, light kLightReferenceTolerance), so that a series shows its integrator's error alone,
// not the missing anti-aliasing.
struct References {
    const BenchCommand& cmd;
    const FlatScene& flat;
    const std::string& stem;
    bool gas = false;

    // The cached reference's path for setting `s`, and in `ref` the setting that renders it.
    std::string path_for(const Setting& s, Setting& ref) const {
        std::string name = stem + "-reference-" + std::to_string(cmd.options.width) + "x" +
                           std::to_string(cmd.options.height);
        if (s.series == "light tolerance") {
            ref = Setting{"reference", SamplerKind::Center,     1, 0.0, cmd.options.tolerance,
                          3,           kLightReferenceTolerance};
            return name + "-center-light1e-4.exr";
        }
        const bool gas_series = s.series == "gas tolerance";
        ref = gas_series ? Setting{"reference", SamplerKind::Center, 1, 0.0, 1e-8}
                         : Setting{"reference", SamplerKind::Grid, cmd.reference_spp, 0.0, 1e-8};
        return name +
               (gas_series ? std::string("-center") : "-grid" + std::to_string(cmd.reference_spp)) +
               (gas ? "-tol1e-8" : "") + ".exr";
    }

    // The path of the reference setting `s` is measured against.
    std::string wanted(const Setting& s) const {
        Setting unused;
        return cmd.reference.empty() ? path_for(s, unused) : cmd.reference;
    }

    // Reads setting `s`'s reference into `image`, rendering and caching it first when missing.
    int load(const Setting& s, Image& image, std::string& path, std::string& error) const {
        Setting ref;
        path = cmd.reference.empty() ? path_for(s, ref) : cmd.reference;
        if (cmd.reference.empty() && !std::filesystem::exists(path)) {
            if (!cmd.common.quiet)
                std::cerr << "rendering the reference " << path << " (" << sampler_name(ref.sampler)
                          << ", " << ref.spp << " samples per pixel"
                          << (gas ? ", tolerance 1e-8" : "")
                          << (ref.light_tolerance > 0.0 ? ", light tolerance 1e-4" : "")
                          << ") ...\n";
            RenderStats stats;
            if (!render_once(flat, cmd.options, ref, image, stats, error)) {
                std::cerr << "vrmlray: error: " << error << "\n";
                return kExitUsage;
            }
            if (!write_image(path, image, false, error)) {
                std::cerr << "vrmlray: error: " << error << "\n";
                return kExitOutput;
            }
            // Measured as read back, as every later run reads it: the file is RGB (written
            // without alpha), and compare measures the channels both images have.
        }
        if (!read_image(path, image, error)) {
            std::cerr << "vrmlray: error: " << error << "\n";
            return kExitBadInput;
        }
        return kExitOk;
    }
};

// Renders setting `s` cmd.runs times into `image`: the median seconds, the rays of the last run.
bool time_setting(const BenchCommand& cmd, const FlatScene& flat, const Setting& s, Image& image,
                  Row& row, std::string& error) {
    const double pixels = double(cmd.options.width) * cmd.options.height;
    std::vector<double> seconds;
    row.setting = s;
    for (int run = 0; run < std::max(1, cmd.runs); ++run) {
        RenderStats stats;
        if (!render_once(flat, cmd.options, s, image, stats, error)) return false;
        seconds.push_back(stats.render_seconds);
        row.rays_per_second = stats.rays_per_second();
        row.rays_per_pixel = double(stats.primary_rays) / pixels;
    }
    std::sort(seconds.begin(), seconds.end());
    row.seconds = seconds[seconds.size() / 2];  // median
    return true;
}

void print_header() {
    std::printf("%-13s %-11s %5s %9s %5s %9s %9s %8s %9s %10s %8s %10s %8s\n", "series", "sampler",
                "spp", "threshold", "depth", "tolerance", "seconds", "rays/px", "Mrays/s", "RMSE",
                "PSNR dB", "max err", "SSIM");
}

void print_row(const Row& row) {
    const Setting& s = row.setting;
    const bool adaptive = s.sampler == SamplerKind::Adaptive;
    std::printf("%-13s %-11s %5d %9.3g %5s %9.0e %9.4f %8.2f %9.3f %10.3e %8.2f %10.3e %8.5f\n",
                s.series.c_str(), sampler_name(s.sampler), s.spp, s.threshold,
                adaptive ? std::to_string(s.depth).c_str() : "-",
                s.light_tolerance > 0.0 ? s.light_tolerance : s.tolerance, row.seconds,
                row.rays_per_pixel, row.rays_per_second * 1e-6, row.metrics.rmse, row.metrics.psnr,
                row.metrics.max_abs, row.metrics.ssim);
    std::fflush(stdout);
}

// Error against time, a line per series, in ladder order, so the legend lists them as the table
// does.
std::vector<PlotSeries> plot_lines(const std::vector<Row>& rows) {
    std::vector<PlotSeries> series;
    for (const Row& r : rows) {
        auto line = std::find_if(series.begin(), series.end(),
                                 [&](const PlotSeries& p) { return p.label == r.setting.series; });
        if (line == series.end()) {
            series.push_back(PlotSeries{r.setting.series, {}, {}});
            line = series.end() - 1;
        }
        // A zero error cannot sit on a log axis; it is left out of the plot (the CSV keeps it).
        if (r.metrics.rmse > 0.0 && r.seconds > 0.0) {
            line->x.push_back(r.seconds);
            line->y.push_back(r.metrics.rmse);
        }
    }
    return series;
}

// Renders and measures every setting of the ladder, printing each row as it is measured.
int measure_ladder(const BenchCommand& cmd, const FlatScene& flat, const References& references,
                   const std::vector<Setting>& ladder, std::vector<Row>& rows,
                   std::string& used_refs) {
    std::string error;
    Image reference;
    std::string ref_path;
    print_header();
    for (const Setting& s : ladder) {
        Row row;
        Image image;
        if (!time_setting(cmd, flat, s, image, row, error)) {
            std::cerr << "vrmlray: error: " << error << "\n";
            return kExitUsage;
        }
        if (reference.width == 0 || references.wanted(s) != ref_path) {
            std::string path;
            if (int code = references.load(s, reference, path, error); code != kExitOk) return code;
            ref_path = path;
            if (used_refs.find(path) == std::string::npos)
                used_refs += (used_refs.empty() ? "" : ", ") + path;
        }
        if (!compare_images(image, reference, 1.0 / 255.0, row.metrics, error)) {
            std::cerr << "vrmlray: error: " << error << " (reference " << ref_path << ")\n";
            return kExitBadInput;
        }
        print_row(row);
        rows.push_back(row);
    }
    return kExitOk;
}

}  // namespace

int run_bench(const BenchCommand& cmd) {
    LoadedScene loaded;
    if (!load_and_report(cmd.scene, cmd.common, loaded, true, cmd.options.threads) ||
        !evaluate_time(loaded, 0.0, cmd.common))
        return kExitBadInput;
    FlatScene flat;
    FlattenStats fs;
    if (!build_and_flatten(loaded, cmd.options, std::nullopt, cmd.common, flat, fs))
        return kExitBadInput;
    if (!check_render_memory(cmd.scene, flat, cmd.options, cmd.common)) return kExitBadInput;
    const bool gas = std::any_of(flat.spheres.begin(), flat.spheres.end(),
                                 [](const Sphere& s) { return s.gas; });

    const bool soft_light = cmd.options.sky.has_value() ||
                            std::any_of(flat.lights.begin(), flat.lights.end(), [](const Light& l) {
                                return l.source_radius > 0.0 || l.angular_radius > 0.0;
                            });
    const std::vector<Setting> ladder =
        default_ladder(cmd.samplers, gas, soft_light, cmd.options.tolerance);
    const std::string stem = stem_of(cmd.scene);
    const std::string csv_path = cmd.csv.empty() ? stem + "-bench.csv" : cmd.csv;
    const std::string plot_path = cmd.plot.empty() ? stem + "-bench.png" : cmd.plot;

    const References references{cmd, flat, stem, gas};
    std::vector<Row> rows;
    std::string used_refs;
    if (int code = measure_ladder(cmd, flat, references, ladder, rows, used_refs); code != kExitOk)
        return code;

    print_fastest(rows, cmd.reference.empty());
    if (!write_csv(csv_path, rows)) {
        std::cerr << "vrmlray: error: cannot write " << csv_path << "\n";
        return kExitOutput;
    }
    PlotOptions po;
    po.title = "RMSE vs time: " + stem;
    std::string error;
    if (!write_image(plot_path, plot_series(plot_lines(rows), po), false, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitOutput;
    }
    if (!cmd.common.quiet)
        std::cerr << "wrote " << csv_path << " and " << plot_path << " (reference " << used_refs
                  << ")\n";
    return kExitOk;
}

}  // namespace vr

// render --stats: the JSON a render writes about itself, for one image and for a sequence (with
// each process's share under MPI), and the clock and memory readings it reports.
#include "app/render_stats.h"

#include <sys/resource.h>

#include <fstream>
#include <iostream>

#include "app/frame_plan.h"
#include "app/render_mpi.h"

namespace vr {

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double peak_memory_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

nlohmann::ordered_json render_stats_json(const RenderCommand& cmd, const FlatScene& flat,
                                         size_t sphere_count, const RenderStats& stats,
                                         const RenderTimings& t) {
    // Every figure at full precision (a double reads back as itself); the scene name escaped.
    nlohmann::ordered_json j;
    j["scene"] = cmd.scene;
    j["width"] = cmd.options.width;
    j["height"] = cmd.options.height;
    j["seconds"] = {{"parse", t.parse},
                    {"scene", t.scene},
                    {"build", stats.build_seconds},
                    {"render", stats.render_seconds},
                    {"write", t.write},
                    {"total", t.total}};
    j["primitives"] = {{"spheres", sphere_count},
                       {"quadrics", flat.quadrics.size()},
                       {"meshes", flat.meshes.size()},
                       {"triangles", flat.triangle_count()},
                       {"instances", flat.instances.size()},
                       {"instanced_triangles", flat.instanced_triangle_count()},
                       {"materials", flat.materials.size()},
                       {"lights", flat.lights.size()},
                       {"bvh_nodes", stats.bvh_nodes},
                       {"bvh_build", stats.bvh_build == BvhBuild::Morton ? "morton" : "sah"}};
    j["rays"] = {{"primary", stats.primary_rays},
                 {"shadow", stats.shadow_rays},
                 {"secondary", stats.secondary_rays},
                 {"per_pixel", static_cast<double>(stats.primary_rays) /
                                   (double(cmd.options.width) * cmd.options.height)},
                 {"per_second", stats.rays_per_second()}};
    const NonFiniteCounts& bad = stats.nonfinite;
    j["nonfinite"] = {{"shading", bad.shading}, {"gas", bad.gas}, {"light", bad.light}};
    if (cmd.options.sky || stats.soft.exact_points + stats.soft.sampled_points > 0) {
        // Present only when soft light ran, so that other renders' JSON stays as it was.
        const SoftLightCounts& s = stats.soft;
        j["soft_light"] = {{"bounded_points", s.exact_points},
                           {"sampled_points", s.sampled_points},
                           {"unconverged_points", s.unconverged},
                           {"sampled_rays", s.rays},
                           {"shared_points", s.shared_points}};
    }
    j["tracer_bytes"] = stats.tracer_bytes;
    const TracerBytes& parts = stats.tracer_parts;
    j["tracer_bytes_by_part"] = {
        {"bvh_nodes", parts.bvh_nodes},           {"spheres", parts.spheres},
        {"sphere_shading", parts.sphere_shading}, {"references", parts.references},
        {"transparency", parts.transparency},     {"quadrics", parts.quadrics},
        {"triangles", parts.triangles},           {"instances", parts.instances}};
    // What the flattened scene's spheres held before the render freed them (docs/manual.md).
    j["flat_sphere_bytes"] = sphere_count * sizeof(Sphere);
    j["peak_memory_mb"] = peak_memory_mb();
    j["peak_memory_mb_after_parse"] = t.peak_parse_mb;
    j["peak_memory_mb_after_scene"] = t.peak_scene_mb;
    return j;
}

std::vector<double> process_share(size_t tiles, const RenderStats& own, const RenderTimings& t,
                                  double init_seconds, double gather_seconds) {
    return {double(tiles),
            double(own.primary_rays + own.shadow_rays + own.secondary_rays),
            init_seconds,
            t.parse,
            t.scene,
            own.build_seconds,
            own.render_seconds,
            gather_seconds,
            t.reading.read_seconds,
            t.reading.exchange_seconds,
            double(t.reading.pieces),
            double(t.reading.built_here),
            double(t.reading.received),
            double(t.reading.bytes_sent)};
}

nlohmann::ordered_json process_shares_json(const std::vector<double>& shares) {
    constexpr size_t kFields = 14;  // process_share's
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (size_t at = 0; at + kFields <= shares.size(); at += kFields) {
        const double* s = &shares[at];
        nlohmann::ordered_json p;
        p["rank"] = at / kFields;
        p["tiles"] = uint64_t(s[0]);
        p["rays"] = uint64_t(s[1]);  // exact: a double holds integers to 2^53
        p["seconds"] = {{"mpi_init", s[2]}, {"parse", s[3]},  {"scene", s[4]},
                        {"build", s[5]},    {"render", s[6]}, {"gather", s[7]}};
        p["reading"] = {{"pieces", uint64_t(s[10])},
                        {"built", uint64_t(s[11])},
                        {"received", uint64_t(s[12])},
                        {"bytes_sent", uint64_t(s[13])},
                        {"seconds", {{"pieces", s[8]}, {"exchange", s[9]}}}};
        all.push_back(p);
    }
    return all;
}

int write_stats(const RenderCommand& cmd, const nlohmann::ordered_json& j) {
    // A file name that is not UTF-8 gets U+FFFD where it is broken rather than an exception.
    const std::string text =
        j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
    if (cmd.stats_text) {
        *cmd.stats_text = text;
        return kExitOk;
    }
    std::ofstream out(cmd.stats_path);
    out << text;
    if (!out) {
        std::cerr << cmd.stats_path << ": error: cannot write the stats file\n";
        return kExitOutput;
    }
    return kExitOk;
}

namespace {

// A process's frames for --stats: count, tiles, rays, seconds of MPI's start-up, parse, scene,
// build, render (each summed over its frames), then its frame numbers, -1 filling `slots`.
std::vector<double> frame_share(const std::vector<FrameRecord>& records, size_t slots,
                                double init_seconds, double parse_seconds) {
    std::vector<double> s = {0, 0, 0, init_seconds, parse_seconds, 0, 0, 0};
    for (const FrameRecord& r : records) {
        s[0] += 1;
        s[1] += double(r.tiles);
        s[2] += double(r.stats.primary_rays + r.stats.shadow_rays + r.stats.secondary_rays);
        s[5] += r.timings.scene;
        s[6] += r.stats.build_seconds;
        s[7] += r.stats.render_seconds;
    }
    for (size_t i = 0; i < slots; ++i) s.push_back(i < records.size() ? records[i].frame : -1);
    return s;
}

nlohmann::ordered_json frame_shares_json(const std::vector<double>& shares, size_t slots) {
    const size_t fields = 8 + slots;
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (size_t at = 0; at + fields <= shares.size(); at += fields) {
        const double* s = &shares[at];
        nlohmann::ordered_json p;
        p["rank"] = at / fields;
        nlohmann::ordered_json frames = nlohmann::ordered_json::array();
        for (size_t i = 0; i < slots; ++i)
            if (s[8 + i] >= 0) frames.push_back(int(s[8 + i]));
        p["frames"] = frames;
        p["tiles"] = uint64_t(s[1]);
        p["rays"] = uint64_t(s[2]);  // exact: a double holds integers to 2^53
        p["seconds"] = {{"mpi_init", s[3]},
                        {"parse", s[4]},
                        {"scene", s[5]},
                        {"build", s[6]},
                        {"render", s[7]}};
        all.push_back(p);
    }
    return all;
}

}  // namespace

// The --stats file of a sequence, by rank 0: its last frame's figures, which frame that is, how
// many frames it rendered at once, and under MPI which frames each process rendered.
int write_sequence_stats(const RenderCommand& cmd, const MpiProcesses& world, const FramePlan& plan,
                         const std::vector<FrameRecord>& records, double parse_seconds,
                         size_t builds) {
    std::vector<double> shares;
    if (world.parallel()) {
        const size_t slots = size_t((cmd.frames + world.size() - 1) / world.size());
        shares = world.gather(frame_share(records, slots, world.init_seconds(), parse_seconds));
        if (!world.root()) return agreed(world, kExitOk, "writing the stats");
    }
    nlohmann::ordered_json j = records.back().json;
    j["frame"] = records.back().frame;
    j["frames_at_once"] = plan.at_once;
    j["scene_builds"] = builds;  // this process's
    if (!shares.empty())
        j["processes"] =
            frame_shares_json(shares, size_t((cmd.frames + world.size() - 1) / world.size()));
    return agreed(world, write_stats(cmd, j), "writing the stats");
}

}  // namespace vr

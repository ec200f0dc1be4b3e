// Many processes rendering (docs/mpi.md): the exit code they all agree on, the gather of one
// image's tiles and totals to rank 0, and rank 0 writing the frames the others rendered.
#include "app/render_mpi.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "app/frame_plan.h"
#include "app/render_stats.h"

namespace vr {

// The exit code all processes agree on (the largest); rank 0 says so when another process failed
// where it did not, since the failing process's own message may be far up the log.
int agreed(const MpiProcesses& world, int code, const char* step) {
    const int all = world.agree(code);
    if (world.parallel() && world.root() && code == kExitOk && all != kExitOk)
        std::fprintf(stderr, "vrmlray: error: another process failed while %s (exit %d)\n", step,
                     all);
    return all;
}

// Many processes: rank 0 gets every tile, and every process the totals of the rays, of the
// covered pixels, of the soft-light counts and of the non-finite values, the longest render and
// whether any timed out. Returns the seconds the gather took here.
double combine(const MpiProcesses& world, const RenderOptions& options, RenderStats& stats,
               Pixels& px) {
    if (!world.parallel()) return 0.0;
    const auto start = std::chrono::steady_clock::now();
    if (px.image8.channels > 0)
        world.gather_tiles(px.image8.samples.data(), size_t(px.image8.channels), options.width,
                           options.height);
    else
        world.gather_tiles(reinterpret_cast<uint8_t*>(px.image.rgba.data()), 4 * sizeof(float),
                           options.width, options.height);
    px.covered = size_t(world.sum(px.covered));
    stats.primary_rays = world.sum(stats.primary_rays);
    stats.shadow_rays = world.sum(stats.shadow_rays);
    stats.secondary_rays = world.sum(stats.secondary_rays);
    stats.soft.exact_points = world.sum(stats.soft.exact_points);
    stats.soft.sampled_points = world.sum(stats.soft.sampled_points);
    stats.soft.unconverged = world.sum(stats.soft.unconverged);
    stats.soft.rays = world.sum(stats.soft.rays);
    stats.soft.shared_points = world.sum(stats.soft.shared_points);
    stats.nonfinite.shading = world.sum(stats.nonfinite.shading);
    stats.nonfinite.gas = world.sum(stats.nonfinite.gas);
    stats.nonfinite.light = world.sum(stats.nonfinite.light);
    stats.timed_out = world.agree(stats.timed_out ? 1 : 0) != 0;
    stats.render_seconds = world.max(stats.render_seconds);
    return seconds_since(start);
}

// A temporary file for frame k of this process, with the output's extension, which names the
// image format.
std::string sent_frame_path(const std::string& output, int k) {
    std::error_code ec;
    const std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    const std::string name = "vrmlray-" + std::to_string(getpid()) + "-frame-" + std::to_string(k) +
                             std::filesystem::path(output).extension().string();
    return ((ec ? std::filesystem::path(".") : dir) / name).string();
}

namespace {

std::vector<uint8_t> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

// Rank 0 writes the frames the others rendered, in frame order, as each sends its own in that
// order; their temporary files go whatever happened. `code`: what all agreed on after rendering.
int write_sent_frames(const RenderCommand& cmd, const MpiProcesses& world,
                      const std::string& output, const std::vector<FrameRecord>& records,
                      int code) {
    size_t mine = 0;
    for (int k = 0; code == kExitOk && k < cmd.frames; ++k) {
        const int owner = k % world.size();
        if (owner == 0) continue;
        if (world.rank() == owner) {
            world.send(file_bytes(records[mine++].sent), 0);
            continue;
        }
        if (!world.root()) continue;
        const std::vector<uint8_t> bytes = world.receive(owner);
        bool unused = false;
        std::string error;
        const std::string path = frame_path(output, k, unused, error);
        std::ofstream out;
        if (!bytes.empty()) {
            out.open(path, std::ios::binary);
            out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            out.close();
        }
        if (bytes.empty() || !out) {
            std::cerr << "vrmlray: error: " << path << ": cannot write frame " << k
                      << (bytes.empty() ? " (process " + std::to_string(owner) + " sent nothing)"
                                        : std::string())
                      << "\n";
            code = kExitOutput;  // the rest are still received, so that no sender waits forever
            for (int rest = k + 1; rest < cmd.frames; ++rest)
                if (rest % world.size() != 0) world.receive(rest % world.size());
        }
    }
    for (const FrameRecord& r : records)
        if (!r.sent.empty()) {
            std::error_code ec;
            std::filesystem::remove(r.sent, ec);
        }
    return agreed(world, code, "writing the frames");
}

}  // namespace vr

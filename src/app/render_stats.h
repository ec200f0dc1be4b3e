// render --stats: the JSON a render writes about itself (docs/manual.md, README "Statistics").
#pragma once
#include <chrono>
#include <nlohmann/json.hpp>
#include <vector>

#include "app/commands.h"
#include "app/shared_pieces.h"
#include "render/flat_scene.h"
#include "render/render.h"

namespace vr {

class MpiProcesses;
struct FramePlan;
struct FrameRecord;

double seconds_since(std::chrono::steady_clock::time_point t);
// The process's peak resident memory so far, MB.
double peak_memory_mb();

struct RenderTimings {
    double parse = 0.0, scene = 0.0, write = 0.0, total = 0.0;  // seconds
    // The process's peak memory when reading and the scene build had ended (MB): bench/scale.sh's
    // bytes per atom of each phase.
    double peak_parse_mb = 0.0, peak_scene_mb = 0.0;
    // Many processes: this one's part in reading the file's pieces (app/shared_pieces.h).
    SharedReading reading;
};

// scene, width, height, seconds{parse scene build render write total}, primitives{...}, rays{...},
// nonfinite{shading gas light}, tracer_bytes, peak_memory_mb{, _after_parse, _after_scene}.
// `sphere_count`: the spheres before the render freed them.
nlohmann::ordered_json render_stats_json(const RenderCommand& cmd, const FlatScene& flat,
                                         size_t sphere_count, const RenderStats& stats,
                                         const RenderTimings& timings);

// One process's share of a render with many processes (docs/mpi.md), as the doubles that
// MpiProcesses::gather carries: tiles, rays (all kinds), then seconds of MPI's start-up, parse,
// scene, build, render and gather (which includes waiting for the slowest process), then its part
// in the shared reading (SharedReading: seconds of its pieces and of the exchange, pieces built
// and received, bytes sent).
std::vector<double> process_share(size_t tiles, const RenderStats& own,
                                  const RenderTimings& timings, double init_seconds,
                                  double gather_seconds);
// --stats "processes": [{rank, tiles, rays, seconds{mpi_init parse scene build render gather},
// reading{pieces built received bytes_sent seconds{pieces exchange}}}, ...] from every process's
// process_share, one after the other in rank order.
nlohmann::ordered_json process_shares_json(const std::vector<double>& shares);

// Writes `j` to --stats FILE (or cmd.stats_text in a batch); kExitOutput when it cannot.
int write_stats(const RenderCommand& cmd, const nlohmann::ordered_json& j);

// The --stats file of a sequence, by rank 0: its last frame's figures, which frame that is, how
// many frames it rendered at once, and under MPI which frames each process rendered.
int write_sequence_stats(const RenderCommand& cmd, const MpiProcesses& world, const FramePlan& plan,
                         const std::vector<FrameRecord>& records, double parse_seconds,
                         size_t builds);

}  // namespace vr

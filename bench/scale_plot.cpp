// Draws bench/scale.sh's cost-growth table (its --csv file) as two log-log plots with vrmlray's own
// plotting code: seconds of each phase against atoms, and peak bytes per atom after each phase.
// Usage: scale_plot TABLE.csv SECONDS.png BYTES.png
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "image/image.h"
#include "qa/plot.h"

namespace {

std::map<std::string, std::vector<double>> read_csv(const char* path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> names;
    std::stringstream header(line);
    for (std::string name; std::getline(header, name, ',');) names.push_back(name);
    std::map<std::string, std::vector<double>> columns;
    while (std::getline(in, line)) {
        std::stringstream row(line);
        std::string cell;
        for (size_t i = 0; i < names.size() && std::getline(row, cell, ','); ++i)
            columns[names[i]].push_back(std::stod(cell));
    }
    return columns;
}

bool plot(const std::map<std::string, std::vector<double>>& table,
          const std::vector<std::pair<std::string, std::string>>& columns, const char* y_label,
          const char* title, const char* out) {
    std::vector<vr::PlotSeries> series;
    for (const auto& [column, label] : columns)
        series.push_back({label, table.at("atoms"), table.at(column)});
    vr::PlotOptions options;
    options.title = title;
    options.x_label = "atoms";
    options.y_label = y_label;
    std::string error;
    if (!vr::write_image(out, vr::plot_series(series, options), false, error)) {
        std::fprintf(stderr, "scale_plot: %s\n", error.c_str());
        return false;
    }
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: scale_plot TABLE.csv SECONDS.png BYTES.png\n");
        return 2;
    }
    const auto table = read_csv(argv[1]);
    if (!table.count("atoms")) {
        std::fprintf(stderr, "scale_plot: %s is not a bench/scale.sh table\n", argv[1]);
        return 3;
    }
    const bool ok =
        plot(table,
             {{"total_s", "whole process"},
              {"parse_s", "read"},
              {"scene_s", "scene build"},
              {"bvh_s", "BVH"},
              {"render_s", "render 1920x1080"},
              {"wrl_scan_s", "wrl_scan"}},
             "seconds", "vrmlray render: seconds per phase (bench/scale.sh)", argv[2]) &&
        plot(table,
             {{"bytes_per_atom_parse", "after reading"},
              {"bytes_per_atom_scene", "after scene build"},
              {"bytes_per_atom", "peak (whole process)"}},
             "bytes per atom", "vrmlray render: peak memory per atom (bench/scale.sh)", argv[3]);
    return ok ? 0 : 4;
}

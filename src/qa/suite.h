// Golden-image suites (docs/golden-tests.md): a reference folder and a result folder matched by
// relative path, every pair compared with the same thresholds, the outcomes ordered worst first.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"
#include "qa/compare.h"

namespace vr {

// Worst first: the order of the summary, the report and the JUnit file.
enum class PairStatus {
    kMissing,       // in the reference folder only: the suite did not produce it
    kExtra,         // in the result folder only: nothing to compare it with
    kSizeMismatch,  // both there, of different sizes
    kUnreadable,    // a file could not be read as an image
    kFail,          // compared, a threshold failed
    kWarn,          // compared, passed with an idiff warning
    kPass
};

// "missing", "extra", "size", "error", "fail", "warn", "pass".
const char* pair_status_name(PairStatus status);
// Every status but kWarn and kPass fails the suite.
inline bool pair_failed(PairStatus status) { return status < PairStatus::kWarn; }

struct SuitePair {
    std::string name;  // the relative path, '/'-separated (the same in both folders)
    std::filesystem::path reference, result;  // empty for the side that lacks the file
    PairStatus status = PairStatus::kPass;
    bool compared = false;  // metrics are set (kFail, kWarn, kPass)
    CompareMetrics metrics;
    std::vector<std::string> failures, warnings;  // the thresholds' lines
    std::string message;  // why a pair was not compared (missing, extra, size, unreadable)
    double seconds = 0;   // reading and comparing, for JUnit's time attribute
};

// The image files (by extension: png, exr, tif, tiff, jpg, jpeg, ppm, pfm, hdr, bmp, tga) under
// `dir`, as sorted '/'-separated relative paths. Other files (tables, notes) are not images of the
// suite and are left out.
// A folder holding the file kReportMarker is a --report folder and is skipped with all below it.
std::vector<std::string> list_suite_images(const std::filesystem::path& dir);
inline constexpr const char* kReportMarker = ".vrmlray-report";

// Called once per pair from the worker threads, after the comparison, with the images read (an
// empty Image for a side that is missing or unreadable); for the report's pictures.
using PairVisitor =
    std::function<void(const SuitePair& pair, const Image& reference, const Image& result)>;

// The thresholds of each pair: those of the first rule whose pattern (a shell glob, as fnmatch
// matches it; '*' also crosses '/') matches the relative path, else the fallback.
struct ThresholdRule {
    std::string pattern;
    CompareThresholds thresholds;
};
struct SuiteThresholds {
    SuiteThresholds(const CompareThresholds& all = {}) : fallback(all) {}
    CompareThresholds fallback;
    std::vector<ThresholdRule> rules;
    const CompareThresholds& for_pair(const std::string& name) const;
};

// Compares every relative path found in either folder on `threads` threads (0: all cores). The
// result is sorted worst first: by status, then by RMSE (largest first), then by name.
std::vector<SuitePair> compare_folders(const std::filesystem::path& reference_dir,
                                       const std::filesystem::path& result_dir,
                                       const SuiteThresholds& thresholds, int threads,
                                       const PairVisitor& visit = {});

// One line a pair, worst first, aligned: status, RMSE, PSNR, max abs, SSIM, fail %, name, and the
// failed thresholds or the message; then a line of counts. Ends with a newline.
std::string format_suite_table(const std::vector<SuitePair>& pairs);

}  // namespace vr

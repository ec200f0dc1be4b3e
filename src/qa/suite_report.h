// What a folder comparison publishes: a JUnit XML file for CI systems and an HTML report that a
// browser shows offline (docs/golden-tests.md).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "qa/suite.h"

namespace vr {

// JUnit XML (the schema Jenkins, GitLab and GitHub's test reporters read): one <testsuite> named
// `suite_name`, one <testcase> a pair (classname "vrmlray.compare", name the relative path, time in
// seconds). A failed threshold, a missing, extra or size-mismatched image is a <failure> whose
// message names it and whose text holds the figures; an unreadable image is an <error>; warnings go
// to <system-out>. Text is escaped; characters XML 1.0 forbids become '?'.
std::string format_junit(const std::vector<SuitePair>& pairs, const std::string& suite_name);

// The report's pictures of one pair under `dir`: ref/NAME.png and out/NAME.png (a PNG copied as it
// is, another format written as an 8-bit PNG, colour clamped to [0,1] as stored, no alpha) and,
// when compared, diff/NAME.png (the --diff heat-map). Safe to call from several threads for
// different pairs. False with `error` set when a file cannot be written.
bool write_report_images(const std::filesystem::path& dir, const SuitePair& pair,
                         const Image& reference, const Image& result, std::string& error);

// dir/index.html: counts, a filter by status (also from the address:
// index.html#status=fail,missing), then per pair, worst first, its status, figures and failed
// thresholds, the reference, the result and the heat-map side by side with the heat-map's colour
// legend, and a flip view (click to swap reference and result in place). No network: styles and
// script are inline, images relative.
bool write_report_html(const std::filesystem::path& dir, const std::vector<SuitePair>& pairs,
                       const std::string& title, std::string& error);

}  // namespace vr

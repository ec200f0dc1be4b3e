// JUnit XML and the offline HTML report of a folder comparison.
#include "qa/suite_report.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "core/xml_escape.h"

namespace vr {
namespace fs = std::filesystem;
namespace {

// Escaped for XML and HTML text and attribute values (core/xml_escape.h).
std::string escape(const std::string& s) { return xml_escaped(s, XmlEscape::kTextOrAttribute); }

// A relative path as a URL path: bytes other than unreserved ones and '/' percent-encoded, so that
// '#', '?', '%' and spaces in file names still find the file.
std::string url_path(const std::string& s) {
    std::string out;
    char hex[4];
    for (unsigned char c : s) {
        if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') {
            out += char(c);
        } else {
            std::snprintf(hex, sizeof hex, "%%%02X", c);
            out += hex;
        }
    }
    return out;
}

std::string fmt(const char* format, double v) {
    char buf[64];
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

// The figures of a compared pair in one line, full enough to judge a failure from a CI log.
std::string figures(const SuitePair& p) {
    const CompareMetrics& m = p.metrics;
    return "RMSE " + fmt("%.6g", m.rmse) + ", PSNR " + fmt("%.3f", m.psnr) + " dB, mean abs " +
           fmt("%.6g", m.mean_abs) + ", max abs " + fmt("%.6g", m.max_abs) + ", SSIM " +
           fmt("%.6f", m.ssim) + ", " + fmt("%.4g", m.fail_percent) + "% of pixels over " +
           fmt("%.6g", m.pixel_threshold) + " (" + std::to_string(m.width) + "x" +
           std::to_string(m.height) + ")";
}

std::string junit_case(const SuitePair& p) {
    std::string x = "    <testcase classname=\"vrmlray.compare\" name=\"" + escape(p.name) +
                    "\" time=\"" + fmt("%.6f", p.seconds) + "\"";
    const std::string body = p.compared ? figures(p) : p.message;
    std::string inner;
    if (p.status == PairStatus::kUnreadable) {
        inner = "      <error type=\"error\" message=\"" + escape(p.message) + "\">" +
                escape(body) + "</error>\n";
    } else if (pair_failed(p.status)) {
        std::string message = p.compared ? "" : p.message;
        for (const std::string& f : p.failures) message += (message.empty() ? "" : "; ") + f;
        inner = "      <failure type=\"" + std::string(pair_status_name(p.status)) +
                "\" message=\"" + escape(message) + "\">" + escape(body) + "</failure>\n";
    }
    std::string out_text = p.compared ? figures(p) : "";
    for (const std::string& w : p.warnings) out_text += "\nwarning: " + w;
    if (!out_text.empty()) inner += "      <system-out>" + escape(out_text) + "</system-out>\n";
    return x + ">\n" + inner + "    </testcase>\n";
}

bool write_text(const fs::path& path, const std::string& text, std::string& error) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    out.close();
    if (out) return true;
    error = "cannot write '" + path.string() + "'";
    return false;
}

bool write_png(const fs::path& path, const Image& image, std::string& error) {
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    return write_image(path.string(), image, false, error);
}

// A PNG is copied as it is (every browser shows it, and encoding is most of the report's time);
// other formats are converted.
bool show_png(const fs::path& source, const fs::path& path, const Image& image,
              std::string& error) {
    std::string ext = source.extension().string();
    for (char& c : ext) c = char(std::tolower((unsigned char)c));
    if (ext != ".png") return write_png(path, image, error);
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    fs::copy_file(source, path, fs::copy_options::overwrite_existing, ec);
    if (!ec) return true;
    error = "cannot copy '" + source.string() + "' to '" + path.string() + "': " + ec.message();
    return false;
}

}  // namespace

std::string format_junit(const std::vector<SuitePair>& pairs, const std::string& suite_name) {
    size_t failures = 0, errors = 0;
    double seconds = 0;
    for (const SuitePair& p : pairs) {
        errors += p.status == PairStatus::kUnreadable;
        failures += pair_failed(p.status) && p.status != PairStatus::kUnreadable;
        seconds += p.seconds;
    }
    const std::string counts = "tests=\"" + std::to_string(pairs.size()) + "\" failures=\"" +
                               std::to_string(failures) + "\" errors=\"" + std::to_string(errors) +
                               "\"";
    std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x += "<testsuites name=\"vrmlray compare\" " + counts + " time=\"" + fmt("%.6f", seconds) +
         "\">\n";
    x += "  <testsuite name=\"" + escape(suite_name) + "\" " + counts + " skipped=\"0\" time=\"" +
         fmt("%.6f", seconds) + "\">\n";
    for (const SuitePair& p : pairs) x += junit_case(p);
    x += "  </testsuite>\n</testsuites>\n";
    return x;
}

bool write_report_images(const fs::path& dir, const SuitePair& pair, const Image& reference,
                         const Image& result, std::string& error) {
    const std::string png = pair.name + ".png";
    if (reference.width > 0 && !show_png(pair.reference, dir / "ref" / png, reference, error))
        return false;
    if (result.width > 0 && !show_png(pair.result, dir / "out" / png, result, error)) return false;
    if (pair.compared &&
        !write_png(dir / "diff" / png, difference_heatmap(result, reference), error))
        return false;
    return true;
}

namespace {

const char* const kStyle = R"(body{font:14px sans-serif;margin:1em;background:#f4f4f4;color:#222}
h1{font-size:1.3em}.pair{background:#fff;margin:1em 0;padding:.6em 1em;border-left:6px solid #3a3}
.pair[data-status=warn]{border-color:#db0}.pair[data-failed]{border-color:#d22}
.pair[hidden]{display:none}.status{font-weight:bold;text-transform:uppercase;margin-right:.6em}
.pair[data-failed] .status{color:#d22}.figs{font-family:monospace;margin:.3em 0}
.why{color:#a00;font-family:monospace}.imgs{display:flex;flex-wrap:wrap;gap:.6em}
figure{margin:0}figcaption{font-size:.85em;color:#555}img{image-rendering:pixelated;
max-width:48vw;border:1px solid #ccc;min-width:192px}.flip img{cursor:pointer}
.legendbox{display:inline-block;vertical-align:top;margin:.2em .5em}
.legend{display:block;width:256px;height:1em;border:1px solid #888}
.ticks{display:block;position:relative;width:256px;height:1.3em;font-size:.8em}
.ticks span{position:absolute;transform:translateX(-50%);white-space:nowrap}
figcaption .legendbox{display:block;margin:.2em 0}figcaption .legend,figcaption .ticks{width:auto}
#filter label{margin-right:1em}
)";

// Filters by the checked statuses; #status=a,b in the address picks which are checked at load.
const char* const kScript = R"(function applyFilter(){
 var on={};document.querySelectorAll('#filter input').forEach(function(c){on[c.value]=c.checked;});
 document.querySelectorAll('.pair').forEach(function(p){p.hidden=!on[p.dataset.status];});}
function flip(img){var a=img.dataset.a,b=img.dataset.b,now=img.getAttribute('src')==a;
 img.setAttribute('src',now?b:a);img.nextElementSibling.textContent=now?img.dataset.bn:img.dataset.an;}
window.addEventListener('DOMContentLoaded',function(){
 var m=location.hash.match(/status=([a-z,]+)/);
 if(m){var want=m[1].split(',');document.querySelectorAll('#filter input').forEach(function(c){
  c.checked=want.indexOf(c.value)>=0;});}
 document.querySelectorAll('#filter input').forEach(function(c){c.addEventListener('change',applyFilter);});
 applyFilter();});
)";

// The heat-map's ramp as a CSS gradient from the same colours the PNGs use, one stop a decade,
// with each decade's label under its stop.
std::string legend_bar() {
    std::string stops;
    for (int k = 0; k <= 4; ++k) {
        float rgb[3];
        heatmap_color(kHeatmapMinDiff * std::pow(10.0, k), rgb);
        char buf[48];
        std::snprintf(buf, sizeof buf, "%srgb(%d,%d,%d)", k ? "," : "", int(rgb[0] * 255 + 0.5f),
                      int(rgb[1] * 255 + 0.5f), int(rgb[2] * 255 + 0.5f));
        stops += buf;
    }
    static const char* const kLabels[] = {"&le;1e-4", "1e-3", "1e-2", "1e-1", "&ge;1"};
    std::string ticks;
    for (int k = 0; k <= 4; ++k)
        ticks += "<span style=\"left:" + std::to_string(25 * k) + "%\">" + kLabels[k] + "</span>";
    return "<span class=\"legendbox\"><span class=\"legend\" style=\"background:linear-gradient(to "
           "right," +
           stops + ")\"></span><span class=\"ticks\">" + ticks + "</span></span>";
}

std::string figure_html(const std::string& src, const std::string& caption) {
    return "<figure><img loading=\"lazy\" src=\"" + escape(src) + "\" alt=\"" + escape(caption) +
           "\"><figcaption>" + escape(caption) + "</figcaption></figure>";
}

std::string pair_html(const SuitePair& p) {
    const std::string png = url_path(p.name) + ".png";
    const std::string ref = "ref/" + png, out = "out/" + png;
    std::string h =
        "<section class=\"pair\" data-status=\"" + std::string(pair_status_name(p.status)) + "\"" +
        (pair_failed(p.status) ? " data-failed" : "") + ">\n<h2><span class=\"status\">" +
        pair_status_name(p.status) + "</span>" + escape(p.name) + "</h2>\n";
    if (p.compared) h += "<div class=\"figs\">" + escape(figures(p)) + "</div>\n";
    std::string why = p.message;
    for (const std::string& f : p.failures) why += (why.empty() ? "" : "; ") + f;
    for (const std::string& w : p.warnings) why += (why.empty() ? "" : "; ") + ("warning: " + w);
    if (!why.empty()) h += "<div class=\"why\">" + escape(why) + "</div>\n";
    h += "<div class=\"imgs\">";
    if (!p.reference.empty() && p.status != PairStatus::kUnreadable)
        h += figure_html(ref, "reference");
    if (!p.result.empty() && p.status != PairStatus::kUnreadable) h += figure_html(out, "result");
    if (p.compared) {
        static const std::string legend = legend_bar();
        h += "<figure><img loading=\"lazy\" src=\"" + escape("diff/" + png) +
             "\" alt=\"heat-map\"><figcaption>heat-map<br>" + legend + "</figcaption></figure>";
        h += "<figure class=\"flip\"><img loading=\"lazy\" onclick=\"flip(this)\" src=\"" +
             escape(ref) + "\" data-a=\"" + escape(ref) + "\" data-b=\"" + escape(out) +
             "\" data-an=\"flip: reference (click for the result)\" data-bn=\"flip: result "
             "(click for the reference)\" alt=\"flip\"><figcaption>flip: reference (click for "
             "the result)</figcaption></figure>";
    }
    return h + "</div>\n</section>\n";
}

}  // namespace

bool write_report_html(const fs::path& dir, const std::vector<SuitePair>& pairs,
                       const std::string& title, std::string& error) {
    size_t counts[int(PairStatus::kPass) + 1] = {};
    for (const SuitePair& p : pairs) ++counts[int(p.status)];
    size_t failed = 0;
    for (const SuitePair& p : pairs) failed += pair_failed(p.status);
    std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" +
                    escape(title) + "</title>\n<style>" + kStyle + "</style>\n<script>" + kScript +
                    "</script></head><body>\n<h1>" + escape(title) + "</h1>\n";
    h += "<p id=\"summary\">" + std::to_string(pairs.size()) +
         " images: " + std::to_string(pairs.size() - failed) + " passed, " +
         std::to_string(failed) + " failed</p>\n<div id=\"filter\">show: ";
    for (int s = 0; s <= int(PairStatus::kPass); ++s) {
        if (counts[s] == 0) continue;
        const std::string name = pair_status_name(PairStatus(s));
        h += "<label><input type=\"checkbox\" value=\"" + name + "\" checked> " + name + " (" +
             std::to_string(counts[s]) + ")</label>";
    }
    h += "</div>\n<div id=\"legend\">heat-map: largest channel difference per pixel " +
         legend_bar() + "</div>\n";
    for (const SuitePair& p : pairs) h += pair_html(p);
    h += "</body></html>\n";
    std::error_code ec;
    fs::create_directories(dir, ec);
    // The marker keeps a report written inside a result folder out of that folder's next compare.
    return write_text(dir / kReportMarker, "written by vrmlray compare --report\n", error) &&
           write_text(dir / "index.html", h, error);
}

}  // namespace vr

// Elements of an exporter's own XML namespace. UCSF Chimera writes the window its user looked
// through into the X3D it exports, as elements of xmlns:chimera='http://www.cgl.ucsf.edu/chimera/':
//   <chimera:WindowSize width='512' height='512'/>
//   <chimera:DepthCue range='35.2169 40.437' color='1 1 1'/>
// They are not X3D nodes (an X3D browser skips them): read as what they say, for the command line
// to use as defaults (docs/input.md "Exporters' own elements"); any other foreign element is the
// exporter's business and is ignored without a word.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "parser/x3d_xml_reader.h"

namespace vr::x3d_xml_detail {

namespace {

// The numbers of a space-separated attribute value; stops at the first word that is not one.
std::vector<double> numbers_of(const std::string& text) {
    std::vector<double> out;
    const char* p = text.c_str();
    for (;;) {
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p || !std::isfinite(v)) break;
        out.push_back(v);
        p = end;
        while (*p == ' ' || *p == ',' || *p == '\t' || *p == '\n' || *p == '\r') ++p;
    }
    return out;
}

}  // namespace

void XmlReader::foreign_element(const XmlElement& e) {
    ++scene_.stats.foreign_elements;
    const std::string_view tag = name_text(e.tag);
    auto value = [&](std::string_view name) -> std::vector<double> {
        for (const XmlAttr& a : e.attrs)
            if (name_text(a.name) == name) return numbers_of(attr_text(e, a));
        return {};
    };
    ExporterView& view = scene_.stats.exporter_view;
    if (tag == "WindowSize") {
        const std::vector<double> w = value("width"), h = value("height");
        // A size the command line could not take is a mistake of the file: said, and not used.
        const bool usable = w.size() == 1 && h.size() == 1 && w[0] >= 1.0 && h[0] >= 1.0 &&
                            w[0] <= 65536.0 && h[0] <= 65536.0;
        if (!usable)
            return warn(e.file, e.offset,
                        "<WindowSize> wants width and height of 1 to 65536 pixels; ignored",
                        "xml-foreign-window-size");
        view.window_width = static_cast<int>(std::lround(w[0]));
        view.window_height = static_cast<int>(std::lround(h[0]));
        return;
    }
    if (tag == "DepthCue") {
        const std::vector<double> range = value("range"), color = value("color");
        if (range.size() != 2 || !(range[0] < range[1]))
            return warn(e.file, e.offset,
                        "<DepthCue> wants range='NEAR FAR' with NEAR < FAR; ignored",
                        "xml-foreign-depth-cue");
        view.depth_cue = true;
        view.depth_cue_near = range[0];
        view.depth_cue_far = range[1];
        view.depth_cue_has_color = color.size() == 3;
        for (size_t i = 0; i < 3 && view.depth_cue_has_color; ++i)
            view.depth_cue_color[i] = std::clamp(color[i], 0.0, 1.0);
    }
}

}  // namespace vr::x3d_xml_detail

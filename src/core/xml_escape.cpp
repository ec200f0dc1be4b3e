#include "core/xml_escape.h"

namespace vr {

void append_xml_escaped(std::string& out, std::string_view text, XmlEscape mode) {
    const bool attribute = mode == XmlEscape::kSingleQuotedAttribute;
    for (char ch : text) {
        const unsigned char c = static_cast<unsigned char>(ch);
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += attribute ? "\"" : "&quot;";
                break;
            case '\'':
                out += attribute ? "&apos;" : "&#39;";
                break;
            case '\n':
                out += attribute ? "&#10;" : "\n";
                break;
            case '\r':
                out += attribute ? "&#13;" : "\r";
                break;
            case '\t':
                out += attribute ? "&#9;" : "\t";
                break;
            default:
                out += c < 0x20 ? '?' : ch;
        }
    }
}

}  // namespace vr

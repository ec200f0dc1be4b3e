// Text escaped for XML and HTML, written once for the X3D XML writer (parser/xml_writer.cpp) and
// the compare reports (qa/suite_report.cpp). The two differ only in the quote they write between
// and in whether tab, newline and carriage return survive as themselves, which `XmlEscape` names.
#pragma once
#include <string>
#include <string_view>

namespace vr {

enum class XmlEscape {
    // An attribute value between single quotes: ' as &apos;, " as itself, and tab, newline and
    // carriage return as character references, which attribute-value normalisation keeps.
    kSingleQuotedAttribute,
    // Element text or an attribute value between either quote (JUnit XML, HTML): " as &quot;, ' as
    // &#39;, tab, newline and carriage return as themselves.
    kTextOrAttribute,
};

// Appends `text` to `out` with &, < and > escaped, quotes and white space as `mode` says; other
// control characters, which XML 1.0 allows not even as references, become '?'.
void append_xml_escaped(std::string& out, std::string_view text, XmlEscape mode);

inline std::string xml_escaped(std::string_view text, XmlEscape mode) {
    std::string out;
    out.reserve(text.size());
    append_xml_escaped(out, text, mode);
    return out;
}

}  // namespace vr

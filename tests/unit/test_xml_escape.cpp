// core/xml_escape.h: the one XML escaping of the X3D writer and the compare reports, each mode
// against hand-written expectations (the characters each mode treats differently side by side).
#include <gtest/gtest.h>

#include "core/xml_escape.h"

namespace vr {
namespace {

// Every character the two modes treat specially, then a control character and UTF-8 bytes.
const std::string kSample = std::string("a&b<c>d\"e'f\tg\nh\ri") + '\x01' + "j\xC3\xA9";

TEST(XmlEscape, SingleQuotedAttributeKeepsWhiteSpaceAsReferences) {
    // The X3D writer's attribute values: between single quotes, so '"' stays and '\'' is
    // escaped; tab, newline and CR as references, which attribute-value normalisation keeps.
    EXPECT_EQ(xml_escaped(kSample, XmlEscape::kSingleQuotedAttribute),
              "a&amp;b&lt;c&gt;d\"e&apos;f&#9;g&#10;h&#13;i?j\xC3\xA9");
}

TEST(XmlEscape, TextOrAttributeEscapesBothQuotes) {
    // JUnit XML and HTML: text or attributes between either quote; white space as itself.
    EXPECT_EQ(xml_escaped(kSample, XmlEscape::kTextOrAttribute),
              "a&amp;b&lt;c&gt;d&quot;e&#39;f\tg\nh\ri?j\xC3\xA9");
}

TEST(XmlEscape, AppendsToWhatIsThere) {
    std::string out = "<x a='";
    append_xml_escaped(out, "1 < 2", XmlEscape::kSingleQuotedAttribute);
    EXPECT_EQ(out, "<x a='1 &lt; 2");
}

}  // namespace
}  // namespace vr

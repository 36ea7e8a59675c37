// UTF-8 repair and XML/JSON escaping (harness/text_escape.hpp): valid text passes unchanged,
// each maximal ill-formed subpart becomes one U+FFFD, and the control characters XML 1.0 forbids
// become visible escapes.
#include "harness/text_escape.hpp"

#include <gtest/gtest.h>

#include <string>

namespace geomint {
namespace text_escape_test {
namespace {

const std::string kFffd = "\xEF\xBF\xBD";

TEST(TextEscape, ValidUtf8IsUnchanged) {
  const std::string text = "plain, é, λ, 漢, 😀 and U+10FFFF \xF4\x8F\xBF\xBF";
  EXPECT_EQ(utf8_replacing_invalid(text), text);
}

TEST(TextEscape, IllFormedSequencesBecomeOneReplacementEach) {
  EXPECT_EQ(utf8_replacing_invalid("a\xFF"
                                   "b"),
            "a" + kFffd + "b");                                              // never a UTF-8 byte
  EXPECT_EQ(utf8_replacing_invalid("\x80\x80"), kFffd + kFffd);              // stray continuations
  EXPECT_EQ(utf8_replacing_invalid("\xC0\xAF"), kFffd + kFffd);              // overlong '/'
  EXPECT_EQ(utf8_replacing_invalid("\xED\xA0\x80"), kFffd + kFffd + kFffd);  // a surrogate
  EXPECT_EQ(utf8_replacing_invalid("\xE2\x82"
                                   "x"),
            kFffd + "x");  // truncated '€'
  EXPECT_EQ(utf8_replacing_invalid("\xF4\x90\x80\x80"),
            kFffd + kFffd + kFffd + kFffd);                             // > U+10FFFF
  EXPECT_EQ(utf8_replacing_invalid("end\xF0\x9F\x98"), "end" + kFffd);  // cut at the end
}

TEST(TextEscape, XmlEscapesMarkupAndShowsForbiddenControls) {
  EXPECT_EQ(xml_escaped("a<b>&\"c\"'"), "a&lt;b&gt;&amp;&quot;c&quot;&#39;");
  EXPECT_EQ(xml_escaped("tab\tnl\ncr\r"), "tab&#9;nl&#10;cr&#13;");
  EXPECT_EQ(xml_escaped(std::string("nul\0bel\x07"
                                    "esc\x1b",
                                    12)),
            "nul\\x00bel\\x07esc\\x1B");
  EXPECT_EQ(xml_escaped("\xEF\xBF\xBE\xEF\xBF\xBF"), "\\uFFFE\\uFFFF");
  EXPECT_EQ(xml_escaped("bad\xFF"), "bad" + kFffd);
  EXPECT_EQ(xml_escaped("λ"), "λ");
}

TEST(TextEscape, JsonEscapesQuotesBackslashesAndControls) {
  EXPECT_EQ(json_escaped("say \"hi\" \\ now"), "say \\\"hi\\\" \\\\ now");
  EXPECT_EQ(json_escaped("a\nb\tc\rd\x01\x7f"), "a\\nb\\tc\\rd\\u0001\\u007f");
  EXPECT_EQ(json_escaped("bad\xC3"), "bad" + kFffd);
  EXPECT_EQ(json_escaped("λ <ok>"), "λ <ok>");
}

}  // namespace
}  // namespace text_escape_test
}  // namespace geomint

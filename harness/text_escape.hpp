// Text made safe for the machine-readable outputs: valid UTF-8 (invalid bytes → U+FFFD), and
// escaped for an XML 1.0 attribute or text node and for a JSON string (gate --format junit/json).
#pragma once

#include <string>
#include <string_view>

namespace geomint {

// `text` with every byte that does not start or continue a well-formed UTF-8 sequence (stray
// continuation bytes, overlong forms, surrogates, code points above U+10FFFF, truncated
// sequences) replaced by U+FFFD, one per maximal ill-formed subpart (Unicode §3.9, U+FFFD
// substitution of maximal subparts); valid UTF-8 comes back unchanged.
std::string utf8_replacing_invalid(std::string_view text);

// Valid XML 1.0 for an attribute value or text: & < > " ' as entities, tab, newline and carriage
// return as character references (an attribute would otherwise normalise them to spaces), and the
// control characters XML 1.0 forbids even as references (U+0000–U+001F but those three, and
// U+FFFE, U+FFFF) as the visible text \xNN or \uFFFE; invalid UTF-8 as U+FFFD.
std::string xml_escaped(std::string_view text);

// The inside of a JSON string (RFC 8259): " and \ escaped, control characters as \n, \t, \r or
// \u00NN, invalid UTF-8 as U+FFFD, so a strict parser reads it back.
std::string json_escaped(std::string_view text);

}  // namespace geomint

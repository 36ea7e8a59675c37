// UTF-8 repair and XML/JSON escaping for the machine-readable outputs (harness/text_escape.hpp).
#include "harness/text_escape.hpp"

#include <fmt/format.h>

#include <cstdint>

namespace geomint {
namespace {

constexpr std::string_view kReplacement = "\xEF\xBF\xBD";  // U+FFFD

// Length of the well-formed UTF-8 sequence at text[at], or 0 when the bytes there are ill-formed;
// `maximal` is the length of the maximal ill-formed subpart then (at least 1). Table 3-7 of the
// Unicode standard: the second byte's range depends on the first.
std::size_t sequence_length(std::string_view text, std::size_t at, std::size_t& maximal) {
  const auto byte = [&](std::size_t k) { return static_cast<std::uint8_t>(text[at + k]); };
  const std::uint8_t lead = byte(0);
  maximal = 1;
  if (lead < 0x80) return 1;
  std::size_t length = 0;
  std::uint8_t low = 0x80, high = 0xBF;  // range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;   // no overlong forms
    if (lead == 0xED) high = 0x9F;  // no surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;   // no overlong forms
    if (lead == 0xF4) high = 0x8F;  // nothing above U+10FFFF
  } else {
    return 0;  // a continuation byte, C0, C1 or F5..FF
  }
  for (std::size_t k = 1; k < length; ++k) {
    if (at + k >= text.size()) return 0;
    const std::uint8_t next = byte(k);
    const bool ok = k == 1 ? next >= low && next <= high : next >= 0x80 && next <= 0xBF;
    if (!ok) return 0;
    maximal = k + 1;
  }
  return length;
}

// Calls emit(code_point, bytes) for each well-formed sequence and emit(-1, U+FFFD) for each
// maximal ill-formed subpart.
template <typename Emit>
void for_each_code_point(std::string_view text, Emit&& emit) {
  for (std::size_t at = 0; at < text.size();) {
    std::size_t maximal = 1;
    const std::size_t length = sequence_length(text, at, maximal);
    if (length == 0) {
      emit(-1L, kReplacement);
      at += maximal;
      continue;
    }
    const auto byte = [&](std::size_t k) { return static_cast<std::uint8_t>(text[at + k]); };
    long code = length == 1 ? byte(0) : byte(0) & (0x7F >> length);
    for (std::size_t k = 1; k < length; ++k) code = (code << 6) | (byte(k) & 0x3F);
    emit(code, text.substr(at, length));
    at += length;
  }
}

}  // namespace

std::string utf8_replacing_invalid(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for_each_code_point(text, [&](long, std::string_view bytes) { out += bytes; });
  return out;
}

std::string xml_escaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for_each_code_point(text, [&](long code, std::string_view bytes) {
    switch (code) {
      case '&':
        out += "&amp;";
        return;
      case '<':
        out += "&lt;";
        return;
      case '>':
        out += "&gt;";
        return;
      case '"':
        out += "&quot;";
        return;
      case '\'':
        out += "&#39;";
        return;
      case '\t':
        out += "&#9;";
        return;
      case '\n':
        out += "&#10;";
        return;
      case '\r':
        out += "&#13;";
        return;
      case 0xFFFE:
      case 0xFFFF:
        out += fmt::format("\\u{:04X}", code);
        return;
      default:
        break;
    }
    if (code >= 0 && code < 0x20) {
      out += fmt::format("\\x{:02X}", code);
    } else {
      out += bytes;
    }
  });
  return out;
}

std::string json_escaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for_each_code_point(text, [&](long code, std::string_view bytes) {
    switch (code) {
      case '"':
        out += "\\\"";
        return;
      case '\\':
        out += "\\\\";
        return;
      case '\n':
        out += "\\n";
        return;
      case '\r':
        out += "\\r";
        return;
      case '\t':
        out += "\\t";
        return;
      default:
        break;
    }
    if ((code >= 0 && code < 0x20) || code == 0x7F) {
      out += fmt::format("\\u{:04x}", code);
    } else {
      out += bytes;
    }
  });
  return out;
}

}  // namespace geomint

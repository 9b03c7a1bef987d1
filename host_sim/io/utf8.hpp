// UTF-8 well-formedness, byte by byte: shared by the readers that must refuse text that is
// not UTF-8 before a library sees it (TinyXML over-read a truncated sequence; JSON written
// from a Latin-1 name failed only after a whole run).
#pragma once

#include <cstddef>
#include <string>

namespace jg::io {

/// The length of the UTF-8 sequence starting at `text[k]` (1-4), or 0 when it is not a
/// well-formed sequence (a stray continuation byte, an overlong or out-of-range lead byte,
/// missing continuation bytes, or the text ending inside it).
inline std::size_t utf8_sequence_length(const std::string& text, std::size_t k) {
  const auto c = static_cast<unsigned char>(text[k]);
  std::size_t len = 1;
  if (c >= 0xF0 && c <= 0xF4) {
    len = 4;
  } else if (c >= 0xE0) {
    len = c <= 0xEF ? 3 : 0;
  } else if (c >= 0xC2) {
    len = 2;
  } else if (c >= 0x80) {
    len = 0;
  }
  if (len == 0 || k + len > text.size()) return 0;
  for (std::size_t n = 1; n < len; ++n) {
    if ((static_cast<unsigned char>(text[k + n]) & 0xC0U) != 0x80U) return 0;
  }
  return len;
}

}  // namespace jg::io

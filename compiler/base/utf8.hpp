// UTF-8 encoding and decoding of single code points (reader, printer, strings).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace sicm {

// Append code point cp to out as UTF-8.
inline void append_utf8(std::string &out, uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// Decode the code point at the start of s (non-empty); len receives its
// length in bytes. A byte that does not start a well-formed sequence stands
// for itself (len 1), so every byte string reads as some characters.
inline uint32_t decode_utf8(std::string_view s, size_t &len) {
  auto b = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
  unsigned char c = b(0);
  len = 1;
  size_t extra = c >= 0xF0 && c < 0xF5   ? 3
                 : c >= 0xE0 && c < 0xF0 ? 2
                 : c >= 0xC2 && c < 0xE0 ? 1
                                         : 0;
  if (extra == 0 || extra >= s.size()) return c;
  uint32_t cp = c & (0x3F >> extra);
  for (size_t k = 1; k <= extra; ++k) {
    if ((b(k) & 0xC0) != 0x80) return c;
    cp = (cp << 6) | (b(k) & 0x3F);
  }
  len = 1 + extra;
  return cp;
}

} // namespace sicm

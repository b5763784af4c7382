// Source positions: every datum the reader produces and every error a user
// can cause carries one.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace sicm {

struct SrcLoc {
  uint32_t file = 0; // index into the source registry; 0 means unknown
  uint32_t line = 0; // 1-based
  uint32_t col = 0;  // 1-based, in bytes
  bool known() const { return file != 0; }
};

// The registry of source texts, so that diagnostics can quote the line.
uint32_t register_source(std::string name, std::string text);
const std::string &source_name(uint32_t file);
// "file:line:col", as diagnostics and run-time sites name a place (loc must be known).
std::string loc_text(SrcLoc loc);
const std::string &source_text(uint32_t file);
// The text of line `line` of `file` without its newline ("" if out of range).
std::string_view source_line(uint32_t file, uint32_t line);

} // namespace sicm

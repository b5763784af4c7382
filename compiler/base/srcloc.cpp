// The source registry: names and texts of every file or REPL entry read.
#include "base/srcloc.hpp"

#include <deque>

namespace sicm {

namespace {
struct Source {
  std::string name, text;
};
// Index 0 is the "unknown" source. A deque keeps references stable.
std::deque<Source> &sources() {
  static std::deque<Source> all{Source{"<unknown>", ""}};
  return all;
}
} // namespace

uint32_t register_source(std::string name, std::string text) {
  sources().push_back(Source{std::move(name), std::move(text)});
  return static_cast<uint32_t>(sources().size() - 1);
}

std::string loc_text(SrcLoc loc) {
  return source_name(loc.file) + ":" + std::to_string(loc.line) + ":" + std::to_string(loc.col);
}

const std::string &source_name(uint32_t file) {
  return sources().at(file < sources().size() ? file : 0).name;
}

const std::string &source_text(uint32_t file) {
  return sources().at(file < sources().size() ? file : 0).text;
}

std::string_view source_line(uint32_t file, uint32_t line) {
  std::string_view text = source_text(file);
  size_t start = 0;
  for (uint32_t l = 1; l < line; ++l) {
    size_t nl = text.find('\n', start);
    if (nl == std::string_view::npos) return {};
    start = nl + 1;
  }
  size_t end = text.find('\n', start);
  if (end == std::string_view::npos) end = text.size();
  return text.substr(start, end - start);
}

} // namespace sicm

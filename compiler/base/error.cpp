// The one reporter of user errors: file:line:col, message, source line, caret.
#include "base/error.hpp"

namespace sicm {

namespace {
TopLevelProbe g_top_level_probe = nullptr;
} // namespace

void set_top_level_probe(TopLevelProbe probe) {
  g_top_level_probe = probe;
}

bool raised_at_top_level() {
  return g_top_level_probe && g_top_level_probe();
}

void syntax_error(SrcLoc loc, const std::string &msg) {
  throw Error(ErrorKind::Syntax, loc, msg);
}

void runtime_error(SrcLoc loc, const std::string &msg) {
  throw Error(ErrorKind::Runtime, loc, msg);
}

std::string format_error(const Error &e) {
  std::string out;
  if (e.loc.known()) {
    out += loc_text(e.loc) + ": ";
  }
  out += "error: ";
  out += e.what();
  out += "\n";
  if (e.loc.known()) {
    std::string_view line = source_line(e.loc.file, e.loc.line);
    if (!line.empty()) {
      // Tabs are kept in the caret line so the caret lines up with the text.
      std::string caret;
      for (uint32_t i = 1; i < e.loc.col && i <= line.size(); ++i)
        caret += line[i - 1] == '\t' ? '\t' : ' ';
      out += "    ";
      out += line;
      out += "\n    " + caret + "^\n";
    }
  }
  if (!e.note.empty()) out += "note: " + e.note + "\n";
  return out;
}

void report_error(std::FILE *f, const Error &e) {
  std::string s = format_error(e);
  std::fwrite(s.data(), 1, s.size(), f);
  std::fflush(f);
}

void internal_failure(const char *file, int line, const char *what) {
  std::fprintf(stderr, "sicm: internal error at %s:%d: %s\n", file, line, what);
  std::abort();
}

} // namespace sicm

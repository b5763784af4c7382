// The protocol of `sicm repl --kernel`: reading requests, writing JSON replies
// (see jupyter_protocol.hpp for the messages).
#include "driver/jupyter_protocol.hpp"

#include <cstdlib>

namespace sicm {

namespace {

// Longest cell or name accepted: far beyond any notebook's, small enough
// that a corrupt header cannot make us allocate the machine.
constexpr size_t kMaxRequestBytes = size_t{64} << 20;

bool read_line(std::FILE *in, std::string &line) {
  line.clear();
  for (int c; (c = std::fgetc(in)) != EOF;) {
    if (c == '\n') return true;
    line += static_cast<char>(c);
  }
  return !line.empty();
}

} // namespace

JupyterRequest read_jupyter_request(std::FILE *in) {
  std::string header;
  if (!read_line(in, header)) return {};
  size_t space = header.find(' ');
  if (space == std::string::npos) return {};
  char *end = nullptr;
  unsigned long long n = std::strtoull(header.c_str() + space + 1, &end, 10);
  if ((*end != '\0' && *end != ' ') || n > kMaxRequestBytes) return {};
  JupyterRequest r{header.substr(0, space), std::string(n, '\0'), *end ? end + 1 : ""};
  if (n && std::fread(r.text.data(), 1, n, in) != n) return {};
  return r;
}

std::string json_string(std::string_view s) {
  static const char kHex[] = "0123456789abcdef";
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
    case '"': out += "\\\""; break;
    case '\\': out += "\\\\"; break;
    case '\n': out += "\\n"; break;
    case '\t': out += "\\t"; break;
    case '\r': out += "\\r"; break;
    default:
      if (c < 0x20) {
        out += "\\u00";
        out += kHex[c >> 4];
        out += kHex[c & 15];
      } else {
        out += static_cast<char>(c);
      }
    }
  }
  return out + "\"";
}

std::string json_strings(const std::vector<std::string> &items) {
  std::string out = "[";
  for (size_t i = 0; i < items.size(); ++i)
    out += (i ? "," : "") + json_string(items[i]);
  return out + "]";
}

std::string json_object(const std::vector<std::pair<std::string, std::string>> &members) {
  std::string out = "{";
  for (size_t i = 0; i < members.size(); ++i)
    out += (i ? "," : "") + json_string(members[i].first) + ":" + members[i].second;
  return out + "}";
}

void write_jupyter_message(std::FILE *out, const std::string &json) {
  std::fwrite(json.data(), 1, json.size(), out);
  std::fputc('\n', out);
  std::fflush(out);
}

} // namespace sicm

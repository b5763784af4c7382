// Functions that differ only in their registers' names (see
// shared_functions.hpp).
#include "codegen/shared_functions.hpp"

#include <cctype>
#include <map>

namespace sicm {

namespace {

bool identifier_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

} // namespace

std::string canonical_function_text(const std::string &code, const std::string &name) {
  // The comment naming the function (its procedure's name) is not code.
  size_t start = 0;
  if (code.rfind("/*", 0) == 0) {
    size_t end = code.find("*/\n");
    if (end != std::string::npos) start = end + 3;
  }
  std::string out;
  std::map<std::string, std::string> renamed;
  for (size_t i = start; i < code.size();) {
    if (!identifier_char(code[i])) {
      out += code[i++];
      continue;
    }
    size_t j = i;
    while (j < code.size() && identifier_char(code[j]))
      ++j;
    std::string word = code.substr(i, j - i);
    i = j;
    if (word == name) {
      out += "FUNCTION";
    } else if (word.size() > 1 && word[0] == 'r' &&
               word.find_first_not_of("0123456789", 1) == std::string::npos) {
      auto [it, fresh] = renamed.emplace(word, "");
      if (fresh) it->second = "r" + std::to_string(renamed.size());
      out += it->second;
    } else {
      out += word;
    }
  }
  return out;
}

} // namespace sicm

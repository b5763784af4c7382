// Files for unit tests: reading one whole, and a scratch directory of their own.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace sicm_test {

// The bytes of the file at path ("" if it cannot be read).
inline std::string slurp(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A new directory under $TMPDIR (else /tmp) named sicm-<name>-XXXXXX, or ""
// if it cannot be made.
inline std::string make_temp_dir(const std::string &name) {
  std::string pattern =
      std::filesystem::temp_directory_path().string() + "/sicm-" + name + "-XXXXXX";
  std::vector<char> tmpl(pattern.begin(), pattern.end());
  tmpl.push_back('\0');
  const char *made = mkdtemp(tmpl.data());
  return made ? std::string(made) : std::string();
}

} // namespace sicm_test

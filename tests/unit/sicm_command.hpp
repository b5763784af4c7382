// Running the sicm binary from a unit test, as a user would: where it is,
// and what a shell command prints.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace sicm_test {

// $SICM_BINARY (tests/run sets it), else build/sicm (unit tests run from the
// repository root).
inline std::string sicm_path() {
  const char *e = std::getenv("SICM_BINARY");
  return e && *e ? e : "build/sicm";
}

// What `command` (run by the shell) writes on stdout.
inline std::string command_output(const std::string &command) {
  std::string text;
  if (FILE *p = popen(command.c_str(), "r")) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, p))
      text += buf;
    pclose(p);
  }
  return text;
}

} // namespace sicm_test

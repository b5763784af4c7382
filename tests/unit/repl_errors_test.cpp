// An error raised inside the library during a REPL entry is located at the
// user's entry (<repl-N>), as sicm run locates it at the program's line,
// with the library's place in a note.
#include <gtest/gtest.h>

#include "sicm_command.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

using sicm_test::command_output;
using sicm_test::sicm_path;

TEST(ReplErrors, ALibraryErrorIsLocatedAtTheUsersEntry) {
  if (!fs::exists(sicm_path())) GTEST_SKIP() << "no sicm binary at " << sicm_path();
  fs::path input = fs::temp_directory_path() / "sicm-repl-errors-test.txt";
  std::ofstream(input) << "(define ((L-free m) local) (* 1/2 m (square (velocity local))))\n"
                          "((L-free 'm) (up 't 'x))\n";
  std::string command = sicm_path() + " repl < " + input.string() + " 2>&1 >/dev/null";
  std::string text = command_output(command);
  fs::remove(input);
  EXPECT_NE(text.find("<repl-2>:1:1: error: velocity: the local tuple has 2 parts; a "
                      "Lagrangian needs (up t q v)\n    ((L-free 'm) (up 't 'x))\n    ^\n"
                      "note: raised inside the library, at <stdlib>/local.sicm:"),
            std::string::npos)
      << text;
}

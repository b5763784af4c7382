// sicm build -o PATH where PATH cannot be written: one line naming the path
// and the system's reason, status 73, before any work (no partial
// evaluation, no C compiler and its linker's messages).
#include <gtest/gtest.h>

#include "sicm_command.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using sicm_test::command_output;
using sicm_test::sicm_path;

// stdout and stderr of `sicm build PROGRAM -o output`, then "status=N".
std::string build_to(const std::string &output, const std::string &program_text = "(display 1)\n") {
  fs::path program = fs::temp_directory_path() / "sicm-build-output-test.sicm";
  std::ofstream(program) << program_text;
  std::string command =
      sicm_path() + " build " + program.string() + " -o '" + output + "' 2>&1; echo status=$?";
  std::string text = command_output(command);
  fs::remove(program);
  return text;
}

} // namespace

TEST(BuildOutput, AMissingDirectoryIsOneLine) {
  if (!fs::exists(sicm_path())) GTEST_SKIP() << "no sicm binary at " << sicm_path();
  EXPECT_EQ(build_to("/nonexistent-sicm-test-dir/scene"),
            "sicm: error: cannot write the executable /nonexistent-sicm-test-dir/scene: No such "
            "file or directory\nstatus=73\n");
}

TEST(BuildOutput, ADirectoryIsOneLine) {
  if (!fs::exists(sicm_path())) GTEST_SKIP() << "no sicm binary at " << sicm_path();
  std::string dir = fs::temp_directory_path().string();
  EXPECT_EQ(build_to(dir),
            "sicm: error: cannot write the executable " + dir + ": Is a directory\nstatus=73\n");
}

// A program the build refuses: its note says what `sicm run` does with it,
// found by running it -- "interprets this program" only where it does.
TEST(BuildOutput, TheRefusalSaysWhatSicmRunDoes) {
  if (!fs::exists(sicm_path())) GTEST_SKIP() << "no sicm binary at " << sicm_path();
  const std::string refused = "(define ((spring k) s) (up 1 (ref s 2) (- (* k (ref s 1)))))\n"
                              "(define r ((state-advancer spring 1.) (up 0. 0. 1.) 1.))\n"
                              "(display (number->string (ref r 1)))\n";
  const std::string out = (fs::temp_directory_path() / "sicm-build-output-test").string();
  std::string runs = build_to(out, refused);
  EXPECT_NE(runs.find("note: sicm build leaves only numerical work for run time; `sicm run` "
                      "interprets this program\n"),
            std::string::npos)
      << runs;
  std::string fails = build_to(out, refused + "(car '())\n");
  EXPECT_NE(fails.find("note: sicm build leaves only numerical work for run time; `sicm run` "
                       "fails on it too: "),
            std::string::npos)
      << fails;
  EXPECT_NE(fails.find(":4:1: error: The object (), passed as the first argument to car, is not "
                       "the correct type."),
            std::string::npos)
      << fails;
}

// sicm build -o PATH where PATH cannot be written: one line naming the path
// and the system's reason, status 73, before any work (no partial
// evaluation, no C compiler and its linker's messages).
#include <gtest/gtest.h>

#include "sicm_command.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

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

// A build killed while the C compiler runs leaves no C behind in $TMPDIR
// (base/temporary_files.hpp).
TEST(BuildOutput, AKilledBuildLeavesNoCBehind) {
  if (!fs::exists(sicm_path())) GTEST_SKIP() << "no sicm binary at " << sicm_path();
  char tmpl[] = "/tmp/sicm-build-killed-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const fs::path dir = tmpl, tmpdir = dir / "tmp";
  fs::create_directory(tmpdir);
  std::ofstream(dir / "p.sicm")
      << "(define ((spring k) s) (up 1 (ref s 2) (- (* k (sin (ref s 1))))))\n"
         "(display ((state-advancer spring 1.3) (up 0. 1. 0.) 10. 1e-12))\n";
  const std::string program = (dir / "p.sicm").string(), out = (dir / "p").string();
  const std::string env = "TMPDIR=" + tmpdir.string();
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    putenv(const_cast<char *>(env.c_str()));
    int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    execl(sicm_path().c_str(), "sicm", "build", program.c_str(), "-o", out.c_str(),
          static_cast<char *>(nullptr));
    _exit(127);
  }
  // Wait for the C to be written (then the removal is armed), and kill.
  bool seen = false;
  for (int i = 0; i < 6000 && !seen; ++i) {
    for (const auto &entry : fs::directory_iterator(tmpdir))
      if (entry.path().extension() == ".c" && fs::file_size(entry.path()) > 0) seen = true;
    if (!seen) usleep(5000);
  }
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(seen) << "the build's C never appeared in " << tmpdir;
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
  size_t left = 0;
  for (const auto &entry : fs::directory_iterator(tmpdir))
    left += entry.path().extension() == ".c";
  EXPECT_EQ(left, 0u);
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

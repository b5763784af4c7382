// SIGINT and SIGTERM during a long run: sicm finishes its plot files (whole
// TSV lines, well-formed SVG) and exits 130 / 143.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_files.hpp"

namespace {

using sicm_test::slurp;

const char *sicm_binary() {
  const char *env = std::getenv("SICM_BINARY");
  return env ? env : "build/sicm";
}

// Run a program that plots forever, interrupt it after it has produced
// points, and return its exit status; dir receives the plot files.
int run_and_signal(int sig, const std::string &dir) {
  std::string prog = dir + "/forever.sicm";
  std::ofstream(prog) << "(define win (frame 0 1 0 1 \"forever\"))\n"
                         "(let loop ((i 0))\n"
                         "  (plot-point win (/ (modulo i 1000) 1000.) .5)\n"
                         "  (loop (+ i 1)))\n";
  pid_t pid = fork();
  if (pid == 0) {
    execl(sicm_binary(), "sicm", "run", prog.c_str(), "--plot-dir", dir.c_str(), (char *)nullptr);
    _exit(127);
  }
  // Wait until the TSV file has grown, so points were really produced.
  std::string tsv = dir + "/forever.tsv";
  for (int i = 0; i < 200; ++i) {
    struct stat st;
    if (stat(tsv.c_str(), &st) == 0 && st.st_size > 100000) break;
    usleep(20000);
  }
  kill(pid, sig);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

void expect_complete_files(const std::string &dir) {
  std::string tsv = slurp(dir + "/forever.tsv");
  ASSERT_FALSE(tsv.empty());
  EXPECT_EQ(tsv.back(), '\n'); // the last line is whole
  std::string svg = slurp(dir + "/forever.svg");
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>\n"), std::string::npos);
  struct stat st;
  EXPECT_NE(stat((dir + "/forever.svg.tmp").c_str(), &st), 0);
}

std::string temp_dir() {
  return sicm_test::make_temp_dir("interrupt");
}

} // namespace

TEST(Interrupt, SigintFinishesPlotFilesAndExits130) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  std::string dir = temp_dir();
  EXPECT_EQ(run_and_signal(SIGINT, dir), 130);
  expect_complete_files(dir);
}

TEST(Interrupt, SigtermFinishesPlotFilesAndExits143) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  std::string dir = temp_dir();
  EXPECT_EQ(run_and_signal(SIGTERM, dir), 143);
  expect_complete_files(dir);
}

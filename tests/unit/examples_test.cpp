// The scenes of examples/ (examples/figure-*.sicm and sweep-*.sicm), run small, both
// with `sicm run` and compiled by `sicm build`.
//
// Every scene begins with the line
//     (define example-size 'full)
// and sizes its work (orbits, final time, points) from it. Here each scene
// is copied into a temporary directory with that line replaced by
//     (define example-size 'small)
// and run with `$SICM_BINARY run FILE --plot-dir DIR` (build/sicm when the
// variable is unset; unit tests run from the repository root). The run must
// exit with status 0 and leave DIR/NAME.svg, a whole SVG document (it starts
// with <?xml and ends with </svg>), and DIR/NAME.tsv with at least one data
// line, NAME being the scene's file name without .sicm (the title it gives
// its frame). examples/README.md describes the convention.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

using sicm_test::slurp;

constexpr const char *kFullLine = "(define example-size 'full)";
constexpr const char *kSmallLine = "(define example-size 'small)";
constexpr int kTimeoutSeconds = 60; // per scene; a small run takes about a second

const char *sicm_binary() {
  const char *env = std::getenv("SICM_BINARY");
  return env && *env ? env : "build/sicm";
}

// The scenes, sorted by name: examples/figure-*.sicm and sweep-*.sicm.
std::vector<std::string> scene_names() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto &entry : fs::directory_iterator("examples", ec)) {
    std::string file = entry.path().filename().string();
    bool scene = file.rfind("figure-", 0) == 0 || file.rfind("sweep-", 0) == 0;
    if (scene && entry.path().extension() == ".sicm") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The scene's text with its size line set to 'small; empty if the scene
// has no size line.
std::string small_version(const std::string &text) {
  size_t at = text.find(kFullLine);
  if (at == std::string::npos) return "";
  if (at != 0 && text[at - 1] != '\n') return ""; // must start a line
  return text.substr(0, at) + kSmallLine + text.substr(at + std::string(kFullLine).size());
}

struct RunResult {
  int status = -1; // exit status, or 128 + signal
  bool timed_out = false;
  std::string output; // stdout and stderr, for the failure message
};

// Run argv (argv[0] a path), stdout and stderr to dir/output.txt, within the timeout.
RunResult run_command(const std::vector<std::string> &argv, const fs::path &dir) {
  RunResult r;
  fs::path out = dir / "output.txt";
  pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0); // its own group, so that a timeout kills the C compiler too
    int fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    std::vector<char *> args;
    for (const std::string &a : argv)
      args.push_back(const_cast<char *>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  if (pid < 0) return r;
  setpgid(pid, pid);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kTimeoutSeconds);
  int wstatus = 0;
  for (;;) {
    pid_t done = waitpid(pid, &wstatus, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return r;
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-pid, SIGKILL);
      waitpid(pid, &wstatus, 0);
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
  r.output = slurp(out);
  return r;
}

// `sicm run program --plot-dir dir`.
RunResult run_scene(const fs::path &program, const fs::path &dir) {
  return run_command({sicm_binary(), "run", program.string(), "--plot-dir", dir.string()}, dir);
}

std::string temp_dir() {
  return sicm_test::make_temp_dir("examples");
}

// Lines of the TSV that are data, not # comments.
int data_lines(const std::string &tsv) {
  int n = 0;
  std::istringstream in(tsv);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') ++n;
  return n;
}

std::string trim_right(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' '))
    s.pop_back();
  return s;
}

// DIR/NAME.svg is a whole SVG document and DIR/NAME.tsv has data.
void expect_figure(const std::string &name, const std::string &dir) {
  std::string svg = slurp(fs::path(dir) / (name + ".svg"));
  EXPECT_FALSE(svg.empty()) << name << ".svg was not written (frame title must be \"" << name
                            << "\")";
  if (!svg.empty()) {
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u) << name << ".svg does not start with <?xml";
    std::string end = trim_right(svg);
    EXPECT_TRUE(end.size() >= 6 && end.compare(end.size() - 6, 6, "</svg>") == 0)
        << name << ".svg does not end with </svg>";
  }
  std::string tsv = slurp(fs::path(dir) / (name + ".tsv"));
  EXPECT_GE(data_lines(tsv), 1) << name << ".tsv has no data line";
}

class ExampleScene : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleScene, RunsSmallAndDrawsItsFigure) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  const std::string name = GetParam();
  const fs::path source = fs::path("examples") / (name + ".sicm");

  std::string small = small_version(slurp(source));
  ASSERT_FALSE(small.empty()) << source << " has no line " << kFullLine
                              << " at the start of a line";

  std::string dir = temp_dir();
  ASSERT_FALSE(dir.empty()) << "cannot make a temporary directory";
  const fs::path program = fs::path(dir) / (name + ".sicm");
  std::ofstream(program, std::ios::binary) << small;

  RunResult r = run_scene(program, dir);
  EXPECT_FALSE(r.timed_out) << name << " ran longer than " << kTimeoutSeconds << " s";
  EXPECT_EQ(r.status, 0) << name << " (small) failed; its output:\n" << r.output;
  expect_figure(name, dir);
  if (!HasFailure()) fs::remove_all(dir);
}

// The same scene compiled by `sicm build` and run as an executable draws
// the same number of points.
TEST_P(ExampleScene, BuildsSmallAndDrawsItsFigure) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  const std::string name = GetParam();
  std::string small = small_version(slurp(fs::path("examples") / (name + ".sicm")));
  ASSERT_FALSE(small.empty());
  std::string dir = temp_dir(), interpreted = temp_dir();
  ASSERT_FALSE(dir.empty() || interpreted.empty()) << "cannot make a temporary directory";
  const fs::path program = fs::path(dir) / (name + ".sicm");
  std::ofstream(program, std::ios::binary) << small;
  const fs::path exe = fs::path(dir) / name;

  RunResult b = run_command({sicm_binary(), "build", program.string(), "-o", exe.string()}, dir);
  ASSERT_EQ(b.status, 0) << name << " (small) does not build:\n" << b.output;
  RunResult r = run_command({exe.string(), "--plot-dir", dir}, dir);
  EXPECT_FALSE(r.timed_out) << name << " ran longer than " << kTimeoutSeconds << " s";
  EXPECT_EQ(r.status, 0) << name << " (small, built) failed; its output:\n" << r.output;
  expect_figure(name, dir);

  RunResult i = run_scene(program, interpreted);
  ASSERT_EQ(i.status, 0) << i.output;
  EXPECT_EQ(data_lines(slurp(fs::path(dir) / (name + ".tsv"))),
            data_lines(slurp(fs::path(interpreted) / (name + ".tsv"))))
      << name << ": the built scene and sicm run plot different numbers of points";
  if (!HasFailure()) {
    fs::remove_all(dir);
    fs::remove_all(interpreted);
  }
}

std::string test_name(const ::testing::TestParamInfo<std::string> &info) {
  std::string s = info.param;
  for (char &c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(Examples, ExampleScene, ::testing::ValuesIn(scene_names()), test_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(ExampleScene);

// The scenes are there at all (the directory is read relative to the
// repository root, where the unit tests run).
TEST(ExampleScenes, Exist) {
  EXPECT_GE(scene_names().size(), 20u)
      << "examples/figure-*.sicm not found from " << fs::current_path();
}

} // namespace

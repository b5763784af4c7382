// scmutils' plot-function (stdlib/plotting.sicm), end to end: the segments
// it writes join (x, f(x)) from x0 by dx, the last ending at the first x at
// or past x1, with the values of f computed here independently.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sicm_command.hpp"

namespace fs = std::filesystem;
using sicm_test::command_output;
using sicm_test::sicm_path;

namespace {

// The data lines of a plot's TSV file, as numbers.
std::vector<std::vector<double>> data_lines(const fs::path &tsv) {
  std::vector<std::vector<double>> lines;
  std::ifstream in(tsv);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> numbers;
    for (double x; fields >> x;)
      numbers.push_back(x);
    lines.push_back(numbers);
  }
  return lines;
}

} // namespace

TEST(PlotFunction, SegmentsJoinTheGraphPointsUpToThePastTheEnd) {
  if (!fs::exists(sicm_path())) GTEST_SKIP() << "no sicm binary at " << sicm_path();
  char tmpl[] = "/tmp/sicm-plot-function-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const fs::path dir = tmpl;
  std::ofstream(dir / "p.sicm") << "(define w (frame 0. 2. -1. 1. \"graph\"))\n"
                                   "(plot-function w sin 0. 1.5707963267948966 .5)\n"
                                   "(define v (frame -2. 0. -1. 1. \"backward\"))\n"
                                   "(plot-function v cos 0. -1. -.25)\n"
                                   "(graphics-close w)\n(graphics-close v)\n";
  std::string out = command_output(sicm_path() + " run " + (dir / "p.sicm").string() +
                                   " --plot-dir " + dir.string() + " 2>&1");
  EXPECT_EQ(out, "");
  // 0 -> .5 -> 1 -> 1.5 -> 2: 2 is the first x past pi/2.
  std::vector<std::vector<double>> graph = data_lines(dir / "graph.tsv");
  ASSERT_EQ(graph.size(), 4u);
  for (size_t k = 0; k < graph.size(); ++k) {
    ASSERT_EQ(graph[k].size(), 4u);
    const double x0 = 0.5 * k, x1 = 0.5 * (k + 1);
    EXPECT_DOUBLE_EQ(graph[k][0], x0);
    EXPECT_NEAR(graph[k][1], std::sin(x0), 1e-15);
    EXPECT_DOUBLE_EQ(graph[k][2], x1);
    EXPECT_NEAR(graph[k][3], std::sin(x1), 1e-15);
  }
  // A negative dx runs from x0 down: 0 -> -.25 -> -.5 -> -.75 -> -1.
  std::vector<std::vector<double>> backward = data_lines(dir / "backward.tsv");
  ASSERT_EQ(backward.size(), 4u);
  EXPECT_DOUBLE_EQ(backward.back()[2], -1.0);
  EXPECT_NEAR(backward.back()[3], std::cos(-1.0), 1e-15);
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

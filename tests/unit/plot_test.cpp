// Unit tests of the runtime's plot files: TSV as the run goes, SVG on finish,
// atomic replacement, bad ranges refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include "sicm/runtime.h"
#include "test_files.hpp"

namespace {

using sicm_test::slurp;

bool exists(const std::string &path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

std::string temp_dir() {
  return sicm_test::make_temp_dir("plot");
}

} // namespace

TEST(Plot, TsvHoldsEveryPointBeforeFinish) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "p", "a title", 0, 1, -1, 1);
  ASSERT_NE(p, nullptr);
  for (int i = 0; i < 5000; ++i)
    ASSERT_EQ(sicm_plot_point(p, i / 5000.0, 0.5), 0);
  // Not finished yet: the flushed part of the TSV is already on disk.
  std::string early = slurp(dir + "/p.tsv");
  EXPECT_GE(std::count(early.begin(), early.end(), '\n'), 4096);
  EXPECT_FALSE(exists(dir + "/p.svg"));
  ASSERT_EQ(sicm_plot_finish(p), 0);
  std::string tsv = slurp(dir + "/p.tsv");
  EXPECT_EQ(std::count(tsv.begin(), tsv.end(), '\n'), 5000 + 2); // two header lines
  EXPECT_EQ(sicm_plot_count(p), 5000u);
  sicm_plot_free(p);
}

TEST(Plot, SvgIsCompleteAndReplacedAtomically) {
  std::string dir = temp_dir();
  for (int round = 0; round < 2; ++round) {
    sicm_plot *p = sicm_plot_open(dir.c_str(), "q", "x<y & \"z\"", -3, 3, 0, 10);
    ASSERT_NE(p, nullptr);
    sicm_plot_point(p, 1, 5);
    sicm_plot_point(p, 100, 5); // outside the frame: in the TSV, not drawn
    sicm_plot_line(p, -3, 0, 3, 10);
    sicm_plot_free(p);
  }
  std::string svg = slurp(dir + "/q.svg");
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>\n"), std::string::npos);
  EXPECT_NE(svg.find("x&lt;y &amp; &quot;z&quot;"), std::string::npos); // title escaped
  EXPECT_NE(svg.find("<line"), std::string::npos);
  EXPECT_FALSE(exists(dir + "/q.svg.tmp"));
  std::string tsv = slurp(dir + "/q.tsv");
  EXPECT_NE(tsv.find("100\t5\n"), std::string::npos);
}

TEST(Plot, EmptyRangesAreRefused) {
  std::string dir = temp_dir();
  EXPECT_EQ(sicm_plot_open(dir.c_str(), "r", nullptr, 1, 1, 0, 1), nullptr);
  EXPECT_EQ(sicm_plot_open(dir.c_str(), "r", nullptr, 0, 1, 2, 1), nullptr);
}

TEST(Plot, MarksAfterFinishAreRefused) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "s", nullptr, 0, 1, 0, 1);
  ASSERT_NE(p, nullptr);
  sicm_plot_finish(p);
  EXPECT_EQ(sicm_plot_point(p, 0.5, 0.5), -1);
  sicm_plot_free(p);
}

// --plot-dir may name a directory that does not exist yet: it is made.
TEST(Plot, MissingDirectoriesAreCreated) {
  std::string dir = temp_dir() + "/a/b";
  sicm_plot *p = sicm_plot_open(dir.c_str(), "r", nullptr, 0, 1, 0, 1);
  ASSERT_NE(p, nullptr);
  sicm_plot_free(p);
  EXPECT_TRUE(exists(dir + "/r.svg"));
  std::string file = temp_dir() + "/file";
  std::ofstream(file) << "x";
  errno = 0;
  EXPECT_EQ(sicm_plot_open((file + "/c").c_str(), "r", nullptr, 0, 1, 0, 1), nullptr);
  EXPECT_EQ(errno, ENOTDIR);
}

// Ticks over a tiny range are written compactly, and the axes carry labels.
TEST(Plot, TinyTicksAreCompactAndAxesAreLabelled) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "s", nullptr, 0, 1, 0, 1e-9);
  ASSERT_NE(p, nullptr);
  ASSERT_EQ(sicm_plot_set_labels(p, "t (s)", "x<y"), 0);
  sicm_plot_free(p);
  std::string svg = slurp(dir + "/s.svg");
  EXPECT_NE(svg.find(">2e-10</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">0</text>"), std::string::npos);
  EXPECT_EQ(svg.find("0.0000000002"), std::string::npos);
  EXPECT_NE(svg.find(">t (s)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">x&lt;y</text>"), std::string::npos);
}

// graphics-clear: the picture keeps only what comes after the clear: its
// SVG is that of a plot that had only those marks (the segment and the
// named series before it gone, the legend's colours given anew); the TSV
// logs every mark and the clear; a finished plot refuses it.
TEST(Plot, ClearDropsEarlierMarksFromThePicture) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "c", "a plot", 0, 10, 0, 10);
  sicm_plot *fresh = sicm_plot_open(dir.c_str(), "fresh", "a plot", 0, 10, 0, 10);
  ASSERT_NE(p, nullptr);
  ASSERT_NE(fresh, nullptr);
  ASSERT_EQ(sicm_plot_line(p, 1, 1, 9, 9), 0);
  ASSERT_EQ(sicm_plot_series_point(p, "before", 2, 2), 0);
  EXPECT_EQ(sicm_plot_count(p), 2u);
  ASSERT_EQ(sicm_plot_clear(p), 0);
  EXPECT_EQ(sicm_plot_count(p), 0u);
  ASSERT_EQ(sicm_plot_series_point(p, "after", 5, 5), 0);
  ASSERT_EQ(sicm_plot_series_point(fresh, "after", 5, 5), 0);
  ASSERT_EQ(sicm_plot_finish(p), 0);
  ASSERT_EQ(sicm_plot_finish(fresh), 0);
  EXPECT_EQ(sicm_plot_clear(p), -1);
  std::string svg = slurp(dir + "/c.svg");
  EXPECT_EQ(svg, slurp(dir + "/fresh.svg"));
  EXPECT_EQ(svg.find("before"), std::string::npos);
  std::string tsv = slurp(dir + "/c.tsv");
  const size_t cleared = tsv.find("# cleared\n");
  ASSERT_NE(cleared, std::string::npos);
  EXPECT_LT(tsv.find("before"), cleared);
  EXPECT_GT(tsv.find("after"), cleared);
  sicm_plot_free(p);
  sicm_plot_free(fresh);
}

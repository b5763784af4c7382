// Unit tests of the parallel sweeps of built programs (runtime/src/parallel.c):
// outputs in member order whatever the threads, prints and plot marks emitted
// as a serial run emits them, serial and nested sweeps, and a failing member.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <pthread.h>
#include <unistd.h>

#include "sicm/runtime.h"
#include "test_files.hpp"

namespace {

using sicm_test::slurp;

const sicm_site kSite = {"sweep.sicm:3:1", "(parallel-map f xs)", 1};

// Members with the kernel ABI.
extern "C" void square_plus(const double *in, double *out, const double *p) {
  out[0] = in[0] * in[0] + p[0];
  out[1] = in[0];
}

// Prints "i:x^2 " for its input x = i; the low members are the slow ones,
// so with several threads the high members finish first.
extern "C" void slow_printer(const double *in, double *out, const double *) {
  const int i = static_cast<int>(in[0]);
  if (i < 4) usleep(static_cast<useconds_t>(20000 * (4 - i)));
  sicm_print_integer(in[0]);
  sicm_print_text(":");
  sicm_print_real(in[0] * in[0] / 4);
  sicm_print_text(" ");
  out[0] = in[0];
}

std::string run_printers(int threads, size_t n) {
  sicm_parallel_set_threads(threads);
  std::vector<double> in(n), out(n);
  for (size_t i = 0; i < n; ++i)
    in[i] = static_cast<double>(i);
  const sicm_closure f = {slow_printer, nullptr};
  testing::internal::CaptureStdout();
  sicm_parallel_map(&kSite, &f, 1, n, in.data(), 1, out.data(), 1, 0);
  std::fflush(stdout);
  return testing::internal::GetCapturedStdout();
}

std::string temp_dir() {
  return sicm_test::make_temp_dir("parallel");
}

// sicm_program_init as a built program calls it, keeping the error hook of
// the other tests.
void init_program(const std::vector<std::string> &args) {
  static std::vector<std::string> kept; // argv strings live as long as the options
  kept = args;
  kept.insert(kept.begin(), "parallel-test");
  std::vector<char *> argv;
  for (std::string &a : kept)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  static const char *const no_parameters[] = {nullptr};
  sicm_error_handler_t *hook = sicm_set_error_handler(nullptr);
  sicm_program_init(static_cast<int>(kept.size()), argv.data(), "parallel-test.sicm",
                    no_parameters);
  sicm_set_error_handler(hook);
}

} // namespace

TEST(ParallelMap, OutputsInMemberOrder) {
  const size_t n = 37;
  std::vector<double> in(n), ps(n);
  std::vector<sicm_closure> each(n);
  const double offset = 0.5;
  const sicm_closure one = {square_plus, &offset};
  for (size_t i = 0; i < n; ++i) {
    in[i] = static_cast<double>(i) - 10;
    ps[i] = static_cast<double>(i) * 100;
    each[i] = {square_plus, &ps[i]};
  }
  for (int threads : {1, 2, 4}) {
    sicm_parallel_set_threads(threads);
    EXPECT_EQ(sicm_parallel_threads(), threads);
    std::vector<double> out(2 * n, -1);
    sicm_parallel_map(&kSite, &one, 1, n, in.data(), 1, out.data(), 2, 0);
    for (size_t i = 0; i < n; ++i) {
      EXPECT_EQ(out[2 * i], in[i] * in[i] + 0.5) << "threads " << threads << ", member " << i;
      EXPECT_EQ(out[2 * i + 1], in[i]);
    }
    std::vector<double> out_each(2 * n, -1);
    sicm_parallel_map(&kSite, each.data(), n, n, in.data(), 1, out_each.data(), 2, 0);
    for (size_t i = 0; i < n; ++i)
      EXPECT_EQ(out_each[2 * i], in[i] * in[i] + ps[i])
          << "threads " << threads << ", member " << i;
  }
}

TEST(ParallelMap, NoMembersCallsNothing) {
  sicm_parallel_set_threads(4);
  const sicm_closure f = {square_plus, nullptr}; // would crash on NULL p
  sicm_parallel_map(&kSite, &f, 1, 0, nullptr, 1, nullptr, 2, 0);
  sicm_parallel_map(&kSite, &f, 1, 0, nullptr, 1, nullptr, 2, 1);
}

TEST(ParallelMap, PrintsComeOutInMemberOrder) {
  const std::string serial = run_printers(1, 12);
  EXPECT_EQ(serial, "0:0. 1:.25 2:1. 3:2.25 4:4. 5:6.25 6:9. 7:12.25 8:16. 9:20.25 10:25. "
                    "11:30.25 ");
  EXPECT_EQ(run_printers(4, 12), serial);
  EXPECT_EQ(run_printers(2, 12), serial);
  EXPECT_EQ(run_printers(4, 3), "0:0. 1:.25 2:1. ") << "fewer members than threads";
}

// Serial members run in order on the calling thread.
namespace {
std::vector<pthread_t> seen_threads;
std::vector<int> seen_members;
extern "C" void record_thread(const double *in, double *, const double *) {
  seen_threads.push_back(pthread_self());
  seen_members.push_back(static_cast<int>(in[0]));
  sicm_print_integer(in[0]);
}
} // namespace

TEST(ParallelMap, SerialMembersRunInOrderOnTheCallingThread) {
  sicm_parallel_set_threads(4);
  seen_threads.clear();
  seen_members.clear();
  const double in[] = {0, 1, 2, 3, 4, 5, 6, 7};
  const sicm_closure f = {record_thread, nullptr};
  testing::internal::CaptureStdout();
  sicm_parallel_map(&kSite, &f, 1, 8, in, 1, nullptr, 0, 1);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "01234567");
  EXPECT_EQ(seen_members, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  for (pthread_t t : seen_threads)
    EXPECT_TRUE(pthread_equal(t, pthread_self()));
}

// A member that sweeps itself: its members run in order on its thread, and
// what they print is part of what it prints.
namespace {
extern "C" void inner_member(const double *in, double *out, const double *p) {
  sicm_print_text("(");
  sicm_print_integer(p[0]);
  sicm_print_text(" ");
  sicm_print_integer(in[0]);
  sicm_print_text(")");
  out[0] = p[0] * 10 + in[0];
}
extern "C" void outer_member(const double *in, double *out, const double *) {
  const pthread_t self = pthread_self();
  if (in[0] == 0) usleep(30000); // the first finishes last
  const double inner_in[] = {1, 2, 3};
  double inner_out[3];
  const sicm_closure f = {inner_member, in};
  sicm_print_integer(in[0]);
  sicm_print_text(":");
  sicm_parallel_map(&kSite, &f, 1, 3, inner_in, 1, inner_out, 1, 0);
  sicm_print_text(" ");
  out[0] = inner_out[0] + inner_out[1] + inner_out[2];
  out[1] = pthread_equal(self, pthread_self()) ? 1 : 0;
}
} // namespace

TEST(ParallelMap, NestedSweepRunsInTheMember) {
  sicm_parallel_set_threads(4);
  const double in[] = {0, 1, 2, 3, 4};
  double out[10];
  const sicm_closure f = {outer_member, nullptr};
  testing::internal::CaptureStdout();
  sicm_parallel_map(&kSite, &f, 1, 5, in, 1, out, 2, 0);
  std::fflush(stdout);
  EXPECT_EQ(testing::internal::GetCapturedStdout(),
            "0:(0 1)(0 2)(0 3) 1:(1 1)(1 2)(1 3) 2:(2 1)(2 2)(2 3) 3:(3 1)(3 2)(3 3) "
            "4:(4 1)(4 2)(4 3) ");
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(out[2 * i], 30.0 * i + 6) << "member " << i;
    EXPECT_EQ(out[2 * i + 1], 1.0) << "member " << i;
  }
}

// Members that call the numerical drivers at once: each thread keeps its own
// failure message, and the results are the serial run's.
namespace {
extern "C" void sine(const double *in, double *out, const double *) {
  out[0] = std::sin(in[0]);
}
extern "C" void integrate_sine(const double *in, double *out, const double *) {
  const sicm_closure f = {sine, nullptr};
  out[0] = sicm_drive_integral(&kSite, f, 0, in[0], 1e-12);
}
// Near 2 pi the integral cancels and the driver relaxes the tolerance, after
// a message to the error hook; built programs record it, here it is dropped.
extern "C" void ignore_error(const char *, int) {}
} // namespace

TEST(ParallelMap, DriversRunInParallel) {
  const size_t n = 64;
  std::vector<double> in(n), serial(n), parallel(n);
  for (size_t i = 0; i < n; ++i)
    in[i] = 0.1 * static_cast<double>(i);
  const sicm_closure f = {integrate_sine, nullptr};
  sicm_error_handler_t *hook = sicm_set_error_handler(ignore_error);
  sicm_parallel_set_threads(1);
  sicm_parallel_map(&kSite, &f, 1, n, in.data(), 1, serial.data(), 1, 0);
  sicm_parallel_set_threads(4);
  sicm_parallel_map(&kSite, &f, 1, n, in.data(), 1, parallel.data(), 1, 0);
  sicm_set_error_handler(hook);
  EXPECT_EQ(parallel, serial);
  EXPECT_NEAR(serial[10], 1 - std::cos(1.0), 1e-12);
}

// A member that fails: the members before it print, it prints what it did
// before failing, its error is sicm_program_fail's, and the status is 70.
namespace {
const sicm_site kFailSite = {"members.sicm:7:5", "  (if (= i 5) (error-at i))", 5};
extern "C" void fails_at_five(const double *in, double *, const double *) {
  const int i = static_cast<int>(in[0]);
  if (i < 3) usleep(20000);
  sicm_print_integer(in[0]);
  sicm_print_text(" ");
  if (i == 5) sicm_program_fail(&kFailSite, "find-root", "the interval does not bracket a root");
}

void run_failing_sweep(const std::string &stdout_path) {
  if (!std::freopen(stdout_path.c_str(), "w", stdout)) std::exit(99);
  sicm_parallel_set_threads(4);
  std::vector<double> in(20);
  for (size_t i = 0; i < in.size(); ++i)
    in[i] = static_cast<double>(i);
  const sicm_closure f = {fails_at_five, nullptr};
  sicm_parallel_map(&kSite, &f, 1, in.size(), in.data(), 1, nullptr, 0, 0);
  std::exit(0); // not reached
}
void run_serial_failing_sweep(const std::string &stdout_path) {
  if (!std::freopen(stdout_path.c_str(), "w", stdout)) std::exit(99);
  sicm_parallel_set_threads(4);
  const double in[] = {3, 4, 5, 6};
  const sicm_closure f = {fails_at_five, nullptr};
  sicm_parallel_map(&kSite, &f, 1, 4, in, 1, nullptr, 0, 1);
  std::exit(0); // not reached
}
} // namespace

TEST(ParallelMapDeathTest, FailingMemberStopsTheSweep) {
  // The source line under the message is indented by four spaces, as the
  // compiler indents its diagnostics (base/error.cpp).
  // The pool's threads are started here first: the child of the death
  // test's fork has none of them, and must start its own.
  EXPECT_EQ(run_printers(4, 8), "0:0. 1:.25 2:1. 3:2.25 4:4. 5:6.25 6:9. 7:12.25 ");
  const std::string out = temp_dir() + "/stdout";
  EXPECT_EXIT(run_failing_sweep(out), ::testing::ExitedWithCode(70),
              "^members\\.sicm:7:5: error: find-root: the interval does not bracket a root\n"
              " {6}\\(if \\(= i 5\\) \\(error-at i\\)\\)\n"
              " {8}\\^\n$");
  EXPECT_EQ(slurp(out), "0 1 2 3 4 5 ");
}

TEST(ParallelMapDeathTest, FailingSerialMember) {
  const std::string out = temp_dir() + "/stdout";
  EXPECT_EXIT(run_serial_failing_sweep(out), ::testing::ExitedWithCode(70),
              "members\\.sicm:7:5: error: find-root: ");
  EXPECT_EQ(slurp(out), "3 4 5 ");
}

TEST(ParallelMapDeathTest, ThreadsOption) {
  init_program({"--threads", "3"});
  EXPECT_EQ(sicm_parallel_threads(), 3);
  for (const char *bad : {"0", "-2", "x", "2.5", ""})
    EXPECT_EXIT(init_program({"--threads", bad}), ::testing::ExitedWithCode(64),
                "--threads.*\nusage: .*\\[--threads N\\]")
        << bad;
  EXPECT_EXIT(init_program({"--threads"}), ::testing::ExitedWithCode(64), "usage: ");
}

// Plot marks of members go into the file in member order: the TSV of four
// threads is the TSV of one, byte for byte.
namespace {
sicm_plot *sweep_plot;
extern "C" void plot_member(const double *in, double *, const double *) {
  const double i = in[0];
  if (i < 3) usleep(10000);
  for (int k = 0; k < 50; ++k)
    sicm_program_plot_point(&kSite, sweep_plot, i + k / 50.0, std::sin(i + k / 50.0));
  sicm_program_plot_line(&kSite, sweep_plot, i, 0, i + 1, 1);
}

std::string plot_sweep(const std::string &dir, const char *name, int threads) {
  sicm_parallel_set_threads(threads);
  sweep_plot = sicm_program_frame(&kSite, name, "a sweep", 0, 20, -1, 1);
  std::vector<double> in(20);
  for (size_t i = 0; i < in.size(); ++i)
    in[i] = static_cast<double>(i);
  const sicm_closure f = {plot_member, nullptr};
  sicm_parallel_map(&kSite, &f, 1, in.size(), in.data(), 1, nullptr, 0, 0);
  EXPECT_EQ(sicm_plot_count(sweep_plot), 20u * 51);
  EXPECT_EQ(sicm_plot_finish(sweep_plot), 0);
  return slurp(dir + "/" + name + ".tsv");
}
} // namespace

TEST(ParallelMap, PlotMarksComeOutInMemberOrder) {
  const std::string dir = temp_dir();
  init_program({"--plot-dir", dir});
  const std::string one = plot_sweep(dir, "one", 1);
  EXPECT_EQ(plot_sweep(dir, "two", 2), one);
  EXPECT_EQ(plot_sweep(dir, "four", 4), one);
  EXPECT_EQ(one.rfind("# a sweep\n# x\ty\n0\t0\n0.02\t0.0199986", 0), 0u) << one;
  EXPECT_EQ(slurp(dir + "/four.svg"), slurp(dir + "/one.svg"));
}

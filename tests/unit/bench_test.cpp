// sicm bench end to end (compiler/bench/): the work-precision table of two small programs.
//
// Runs `$SICM_BINARY bench` (build/sicm when the variable is unset; skipped
// when there is none) on the harmonic oscillator, whose solution is known,
// and on a stiff system, where the explicit methods' failed runs must be
// rows, not a crash.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const char *sicm_binary() {
  const char *env = std::getenv("SICM_BINARY");
  return env && *env ? env : "build/sicm";
}

std::vector<std::string> split(const std::string &s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string field; std::getline(in, field, sep);)
    out.push_back(field);
  return out;
}

TEST(Bench, ErrorsAgreeWithTheExactSolutionAndFailuresAreRows) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  char tmpl[] = "/tmp/sicm-bench-test-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const fs::path dir = tmpl;
  {
    std::ofstream program(dir / "two-sites.sicm");
    program
        << "(define (oscillator-sysder) (lambda (s) (up 1 (ref s 2) (- (ref s 1)))))\n"
           "((evolve oscillator-sysder) (up 0. 1. 0.) (lambda (s) 'ok) 1. 10. 1e-12)\n"
           "(define (stiff-sysder) (lambda (s) (up 1 (* -1e6 (- (ref s 1) (cos (ref s 0)))))))\n"
           "((state-advancer stiff-sysder) (up 0. 1.) 10. 1e-8 'cvode-bdf)\n";
  }
  const fs::path out = dir / "out";
  std::string command = std::string(sicm_binary()) + " bench " + (dir / "two-sites.sicm").string() +
                        " --out " + out.string() +
                        " --methods rk8pd,bulirsch-stoer,rkf45 --tolerances 1e-3:1e-10"
                        " --repeats 1 > " +
                        (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);

  std::ifstream tsv(out / "work-precision.tsv");
  std::string line;
  ASSERT_TRUE(std::getline(tsv, line));
  EXPECT_EQ(line, "site\tmethod\ttolerance\tseconds\tsteps\trhs_evals\terror\tfinal");
  int oscillator_rows = 0, stiff_rows = 0, failed_rows = 0;
  while (std::getline(tsv, line)) {
    std::vector<std::string> f = split(line, '\t');
    ASSERT_EQ(f.size(), 8u) << line;
    std::vector<std::string> state = split(f[7], ' ');
    const double error = std::strtod(f[6].c_str(), nullptr);
    if (f[0].find(":2:1") != std::string::npos) {
      ++oscillator_rows;
      ASSERT_EQ(state.size(), 3u);
      // The error against x = cos t, v = -sin t at t = 10, from the final column.
      const double t = std::stod(state[0]), x = std::stod(state[1]), v = std::stod(state[2]);
      const double exact = std::fmax(std::fabs(t - 10), std::fmax(std::fabs(x - std::cos(10.0)),
                                                                  std::fabs(v + std::sin(10.0))));
      EXPECT_TRUE(std::fabs(error - exact) <= 1e-15 || (error <= 2 * exact && exact <= 2 * error))
          << line << " (exact error " << exact << ")";
    } else {
      // Stiff: the explicit methods stop (the stiffness watch), and say where.
      ++stiff_rows;
      if (std::isinf(error)) ++failed_rows;
      ASSERT_EQ(state.size(), 2u);
      EXPECT_TRUE(std::isfinite(std::stod(state[0])) && std::isfinite(std::stod(state[1])));
    }
  }
  EXPECT_EQ(oscillator_rows, 3 * 8);
  EXPECT_EQ(stiff_rows, 3 * 8);
  EXPECT_GT(failed_rows, 0);
  // Each failure says why on stdout.
  std::ifstream printed(dir / "stdout.txt");
  std::stringstream text;
  text << printed.rdbuf();
  EXPECT_NE(text.str().find("  stopped for rk8pd at "), std::string::npos) << text.str();

  // The diagram is well-formed XML (checked by Python's parser, which CI has).
  std::string check =
      "python3 -c \"import xml.dom.minidom,sys; xml.dom.minidom.parse(sys.argv[1])\" " +
      (out / "work-precision.svg").string();
  EXPECT_EQ(std::system(check.c_str()), 0);
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

// A fixed-step method whose step (its tolerance) would need more steps than
// the limit takes none: no row, and a line saying why (it was a silent row
// of error inf and 0 steps).
TEST(Bench, AFixedStepMethodThatCannotStartSaysWhyAndHasNoRow) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  char tmpl[] = "/tmp/sicm-bench-test-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const fs::path dir = tmpl;
  std::ofstream(dir / "spring.sicm")
      << "(define ((spring k) s) (up 1 (ref s 2) (- (* k (ref s 1)))))\n"
         "((state-advancer spring 1.) (up 0. 0. 1.) 10. 1e-10)\n";
  const fs::path out = dir / "out";
  std::string command = std::string(sicm_binary()) + " bench " + (dir / "spring.sicm").string() +
                        " --out " + out.string() +
                        " --methods verlet --tolerances 1e-4:1e-5 --repeats 1 > " +
                        (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  std::ifstream printed(dir / "stdout.txt");
  std::stringstream text;
  text << printed.rdbuf();
  EXPECT_NE(text.str().find("  no row for verlet at 1e-05: verlet: too many steps at t = 0. with "
                            "state [0., 0., 1.]: 1000000 steps of 1e-05 are needed and the limit "
                            "is 500000 (for verlet the tolerance argument is the step size)\n"),
            std::string::npos)
      << text.str();
  std::ifstream tsv(out / "work-precision.tsv");
  int rows = 0;
  for (std::string line; std::getline(tsv, line);)
    rows += line.find("\tverlet\t") != std::string::npos;
  EXPECT_EQ(rows, 1); // 1e-4 only
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}

} // namespace

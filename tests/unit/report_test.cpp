// sicm report and sicm build --fix end to end (compiler/codegen/kernel_report.cpp).
//
// Runs `$SICM_BINARY report` (build/sicm when unset; skipped when there is
// none) on a pendulum with and without the drive of figure 1.7: a drive
// whose amplitude is 0 -- written 0 or 0., or a parameter fixed to 0 with
// --fix -- must leave the state derivative with exactly the op counts of
// the pendulum written without it; a drive that is on, or a parameter left
// for run time, costs more. The JSON has the documented shape.
#include <gtest/gtest.h>

#include "codegen/kernel_report.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

const char *sicm_binary() {
  const char *env = std::getenv("SICM_BINARY");
  return env && *env ? env : "build/sicm";
}

class Report : public ::testing::Test {
protected:
  void SetUp() override {
    struct stat st;
    if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
    char tmpl[] = "/tmp/sicm-report-test-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ignored;
    if (!dir_.empty()) fs::remove_all(dir_, ignored);
  }

  // The JSON of `sicm report` on a program whose state derivative is the
  // driven pendulum's with drive amplitude `amplitude` (Scheme text), or the
  // undriven pendulum's when it is empty. Mass and length are an exact 1,
  // which folds (a flonum 1. would be a kernel parameter, and the two forms
  // of the Lagrangian would then differ in their multiplications by it).
  std::string report(const std::string &amplitude, const std::string &options = "") {
    fs::path program = dir_ / ("scene" + std::to_string(n_++) + ".sicm");
    std::ofstream(program)
        << (amplitude.empty()
                ? "(define ((L m l g) local)\n"
                  "  (+ (* 1/2 m (square (* l (velocity local)))) (* m g l (cos (coordinate "
                  "local)))))\n"
                  "(define (sysder) (Lagrangian->state-derivative (L 1 1 9.8)))\n"
                : "(define (sysder) (Lagrangian->state-derivative\n"
                  "  (L-periodically-driven-pendulum 1 1 9.8 " +
                      amplitude + " (* 2 (sqrt 9.8)))))\n")
        << "((state-advancer sysder) (up 0. 1. 0.) 1.)\n";
    fs::path json = program;
    json.replace_extension(".json");
    std::string command = std::string(sicm_binary()) + " report " + program.string() + " " +
                          options + " --report=" + json.string() + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    std::ifstream in(json);
    std::stringstream s;
    s << in.rdbuf();
    last_json_ = json;
    return s.str();
  }

  // The ops object of the state-derivative kernel.
  static std::string derivative_ops(const std::string &json) {
    static const std::regex rx(R"("role": "state-derivative", "inputs": \d+, "outputs": \d+, )"
                               R"("parameters": \[[^\]]*\], "ops": (\{[^}]*\}), "total": (\d+))");
    std::smatch m;
    return std::regex_search(json, m, rx) ? m[1].str() + " total " + m[2].str() : "none";
  }

  fs::path dir_, last_json_;
  int n_ = 0;
};

TEST_F(Report, AnEffectSwitchedOffCostsNothing) {
  const std::string without = derivative_ops(report(""));
  ASSERT_NE(without, "none");
  EXPECT_EQ(derivative_ops(report("0")), without);
  EXPECT_EQ(derivative_ops(report("0.")), without);
  EXPECT_EQ(derivative_ops(report("(parameter 'a .1)", "--fix a=0")), without);
  EXPECT_NE(derivative_ops(report(".1")), without);
  const std::string unfixed = report("(parameter 'a 0.)");
  EXPECT_NE(derivative_ops(unfixed), without);
  EXPECT_NE(unfixed.find(R"("parameters": ["a"])"), std::string::npos) << unfixed;
}

TEST_F(Report, TheJsonHasTheDocumentedShape) {
  report(".1");
  const std::string check =
      "python3 -c \"import json,sys\n"
      "d = json.load(open(sys.argv[1]))\n"
      "assert set(d) == {'kernels', 'effects'}\n"
      "ops = ['add','mul','div','sqrt','sin','cos','exp','log','pow','atan2','solve','call']\n"
      "for k in d['kernels']:\n"
      "  assert list(k) == ['site','role','inputs','outputs','parameters','ops','total'], k\n"
      "  assert k['role'] in ['state-derivative','monitor','map','objective','integrand',"
      "'jacobian','other']\n"
      "  assert list(k['ops']) == ops and k['total'] == sum(k['ops'].values())\n"
      "assert any(k['role'] == 'state-derivative' for k in d['kernels'])\n\" " +
      last_json_.string();
  EXPECT_EQ(std::system(check.c_str()), 0);
}

// Run a shell command; its stdout.
std::string output_of(const std::string &command) {
  std::string out;
  FILE *p = popen(command.c_str(), "r");
  if (!p) return out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p))
    out += buf;
  pclose(p);
  return out;
}

TEST_F(Report, FixAndParamPrintTheSameNumbers) {
  fs::path program = dir_ / "swept.sicm";
  std::ofstream(program) << "(define (sysder a) (Lagrangian->state-derivative\n"
                            "  (L-periodically-driven-pendulum 1. 1. 9.8 a (* 2 (sqrt 9.8)))))\n"
                            "((state-advancer sysder (parameter 'a 0.)) (up 0. 1. 0.) 1.)\n";
  const std::string sicm = sicm_binary(), src = program.string();
  const std::string fixed = (dir_ / "fixed").string(), swept = (dir_ / "swept").string();
  ASSERT_EQ(std::system((sicm + " build " + src + " --fix a=.1 -o " + fixed).c_str()), 0);
  ASSERT_EQ(std::system((sicm + " build " + src + " -o " + swept).c_str()), 0);
  const std::string a = output_of(fixed), b = output_of(swept + " --param a=.1");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, output_of(sicm + " run " + src + " --param a=.1"));
}

} // namespace

// The checked forms of the program's own arithmetic count as the operation
// they check: a square root of a run-time value is a sqrt, not a call.
TEST(ReportOps, CheckedOperationsCountAsTheOperation) {
  auto ops = sicm::count_c_ops(
      "out[0] = sicm_checked_sqrt(&site0, r0 * r0 + 2.0) + sicm_checked_log(&site1, r0) + "
      "sicm_checked_pow(&site2, r0, r1) + sicm_checked_quotient(&site3, \"/\", r0, r1);");
  EXPECT_EQ(ops["sqrt"], 1u);
  EXPECT_EQ(ops["log"], 1u);
  EXPECT_EQ(ops["pow"], 1u);
  EXPECT_EQ(ops["div"], 1u);
  EXPECT_EQ(ops["call"], 0u);
  EXPECT_EQ(ops["add"], 4u);
  EXPECT_EQ(ops["mul"], 1u);
}

// A loop's body counts as many times as the loop runs: the pairs i < j of
// n bodies n (n - 1) / 2 times; its index arithmetic is not the kernel's.
TEST(ReportOps, LoopBodiesCountOncePerIteration) {
  auto ops = sicm::count_c_ops("  for (int oo0 = 0; oo0 < 300; ++oo0)\n"
                               "    out[301 + oo0] = -0.0;\n"
                               "  for (int oi0 = 0; oi0 < 100; ++oi0)\n"
                               "    for (int oj0 = oi0 + 1; oj0 < 100; ++oj0) {\n"
                               "    double d = in[1 + 3 * oi0] - in[1 + 3 * oj0];\n"
                               "    double r = sqrt(d * d);\n"
                               "    out[2 + oi0] = out[2 + oi0] + d / r;\n"
                               "  }\n"
                               "  out[0] = in[0] * 2.0;\n"
                               "  for (int k = 0; k < order; ++k) out[k] = out[k] + 1.0;\n");
  EXPECT_EQ(ops["sqrt"], 4950u);
  EXPECT_EQ(ops["add"], 300u + 2 * 4950u + 1u); // -0.0, d's -, the sum's +, the last loop once
  EXPECT_EQ(ops["mul"], 4950u + 1u);
  EXPECT_EQ(ops["div"], 4950u);
  EXPECT_EQ(ops["call"], 0u);
}

// Each effect of stdlib/effects.sicm costs nothing when it is off, through sicm report.
//
// For every effect of the library, a scene (a body in a central field, or a
// rotor for the spin-orbit coupling) is reported by `$SICM_BINARY report`
// (build/sicm when unset; skipped when there is none) without the effect,
// and with it at coefficient 0, 0., a (parameter ...) fixed to 0 by --fix,
// and a coefficient that is on. Off, the state derivative must have exactly
// the op counts of the scene without the effect; on, more. Then: what a
// program computes but never observes (an energy in a monitor that prints
// only an angle, an energy defined and never printed) costs nothing either.
#include <gtest/gtest.h>

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

// One effect: the scene's Lagrangian and dissipation function, with COEF
// where the effect's coefficient goes, and without the effect.
struct Effect {
  const char *name;
  const char *with;    // Lagrangian, then dissipation function (or empty)
  const char *without; // the same scene without the effect
};

// A body in 3D at (coordinate local), in the field of a unit central mass.
#define BODY "(kinetic-energy 1. pos) (central-gravity 1. 1. pos)"

const Effect kEffects[] = {
    {"uniform-gravity", "(+ " BODY " (uniform-gravity 1. COEF pos))", "(+ " BODY ")"},
    {"central-gravity", "(+ (kinetic-energy 1. pos) (central-gravity COEF 1. pos))",
     "(kinetic-energy 1. pos)"},
    {"J2-oblateness", "(+ " BODY " (J2-oblateness 1. 1. .1 COEF pos))", "(+ " BODY ")"},
    {"linear-spring", "(+ " BODY " (linear-spring COEF 0 pos))", "(+ " BODY ")"},
    {"nonlinear-spring", "(+ " BODY " (nonlinear-spring 2. COEF pos))",
     "(+ " BODY " (linear-spring 2. 0 pos))"},
    {"driven-support",
     "(+ (kinetic-energy 1. (driven-support pos COEF 2.)) "
     "(central-gravity 1. 1. (driven-support pos COEF 2.)))",
     "(+ " BODY ")"},
    {"rotating-frame", "(+ " BODY " (rotating-frame 1. COEF pos))", "(+ " BODY ")"},
    {"spin-orbit-coupling",
     "(+ (lambda (l) (* 1/2 .8 (square (velocity l)))) (spin-orbit-coupling .8 COEF 1.))",
     "(lambda (l) (* 1/2 .8 (square (velocity l))))"},
    {"Rayleigh-dissipation", "(+ " BODY ") (Rayleigh-dissipation COEF)", "(+ " BODY ")"},
};

class EffectsReport : public ::testing::TestWithParam<Effect> {
protected:
  void SetUp() override {
    struct stat st;
    if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
    char tmpl[] = "/tmp/sicm-effects-test-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ignored;
    if (!dir_.empty()) fs::remove_all(dir_, ignored);
  }

  // The JSON `sicm report` writes for a program.
  std::string report(const std::string &text, const std::string &options = "") {
    fs::path program = dir_ / ("scene" + std::to_string(n_++) + ".sicm");
    std::ofstream(program) << text;
    fs::path json = program;
    json.replace_extension(".json");
    std::string command = std::string(sicm_binary()) + " report " + program.string() + " " +
                          options + " --report=" + json.string() + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command << "\n" << text;
    std::ifstream in(json);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  // The scene: state-advancer over the Lagrangian (and dissipation function) given.
  static std::string scene(std::string system, const std::string &coef) {
    for (size_t at; (at = system.find("COEF")) != std::string::npos;)
      system.replace(at, 4, coef);
    const bool rotor = system.find("spin-orbit") != std::string::npos ||
                       system.find("(lambda (l)") != std::string::npos;
    return "(define (pos local) (coordinate local))\n"
           "(define (sysder) (Lagrangian->state-derivative " +
           system + "))\n((state-advancer sysder) " +
           (rotor ? "(up 0. .1 1.)" : "(up 0. (up 1. .2 .1) (up .1 1. .3))") + " 1.)\n";
  }

  // The ops object and total of the kernel of a role.
  static std::string ops_of(const std::string &json, const std::string &role) {
    const std::regex rx("\"role\": \"" + role +
                        R"(", "inputs": \d+, "outputs": \d+, "parameters": \[[^\]]*\], )"
                        R"("ops": (\{[^}]*\}), "total": (\d+))");
    std::smatch m;
    return std::regex_search(json, m, rx) ? m[1].str() + " total " + m[2].str() : "none";
  }

  static int total_of(const std::string &ops) {
    return std::atoi(ops.substr(ops.rfind(' ') + 1).c_str());
  }

  fs::path dir_;
  int n_ = 0;
};

TEST_P(EffectsReport, OffCostsNothingOnCostsMore) {
  const Effect &e = GetParam();
  const std::string without = ops_of(report(scene(e.without, "")), "state-derivative");
  ASSERT_NE(without, "none");
  EXPECT_EQ(ops_of(report(scene(e.with, "0")), "state-derivative"), without) << "0";
  EXPECT_EQ(ops_of(report(scene(e.with, "0.")), "state-derivative"), without) << "0.";
  EXPECT_EQ(ops_of(report(scene(e.with, "(parameter 'c .3)"), "--fix c=0"), "state-derivative"),
            without)
      << "--fix c=0";
  const std::string on_json = report(scene(e.with, ".3"));
  EXPECT_GT(total_of(ops_of(on_json, "state-derivative")), total_of(without)) << "on";
  EXPECT_NE(on_json.find("\"" + std::string(e.name) + "\""), std::string::npos)
      << "the effects list names " << e.name << ": " << on_json;
}

INSTANTIATE_TEST_SUITE_P(Library, EffectsReport, ::testing::ValuesIn(kEffects),
                         [](const ::testing::TestParamInfo<Effect> &info) {
                           std::string name = info.param.name;
                           for (char &c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

// Nobody observes the energy: a monitor that computes it but prints only the
// angle costs what the monitor printing the angle alone costs, and an
// energy defined at top level and never printed is not computed at all.
TEST_F(EffectsReport, UnobservedQuantitiesAreNotComputed) {
  const std::string scene_head =
      "(define (bob local) (pendulum-position 1. (coordinate local)))\n"
      "(define L (+ (kinetic-energy 1. bob) (uniform-gravity 1. 9.8 bob)))\n"
      "(define energy (Lagrangian->energy L))\n";
  const std::string run = "((evolve Lagrangian->state-derivative L) (up 0. 1. 0.) monitor .1 1.)\n";
  const std::string plain =
      report(scene_head + "(define (monitor s) (write-line (coordinate s)))\n" + run);
  const std::string with_energy = report(
      scene_head + "(define (monitor s) (let ((E (energy s))) (write-line (coordinate s))))\n" +
      run + "(define E-final (energy (up 1. 2. 3.)))\n");
  ASSERT_NE(ops_of(plain, "monitor"), "none") << plain;
  EXPECT_EQ(ops_of(with_energy, "monitor"), ops_of(plain, "monitor"));
  EXPECT_EQ(ops_of(with_energy, "state-derivative"), ops_of(plain, "state-derivative"));
  const std::string printed =
      report(scene_head + "(define (monitor s) (write-line (energy s)))\n" + run);
  EXPECT_GT(total_of(ops_of(printed, "monitor")), total_of(ops_of(plain, "monitor")));
}

} // namespace

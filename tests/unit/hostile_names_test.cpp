// Unit tests of generated C for C-hostile procedure names: mangling, warnings, one unit.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "base/number.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/jit.hpp"
#include "codegen/kernel.hpp"
#include "codegen/trace.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "syntax/reader.hpp"

namespace sicm {
// Defined in emit_c.cpp; its declaration belongs in emit_c.hpp (not this
// change's file), and repeating it here stays valid once it is there.
std::string c_kernel_name(std::string_view name);
} // namespace sicm

using namespace sicm;

namespace {

Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<hostile_names_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

// A procedure name as the user spells it, how the reader must see it, and
// what the procedure computes from x = 2.
struct Hostile {
  std::string name;
  std::string spelled;
  std::string body;
  double at2;
};

std::vector<Hostile> hostile_procedures() {
  std::string long_name(300, 'a');
  return {
      {"int", "int", "(* 2 x)", 4},
      {"double", "double", "(* 3 x)", 6},
      {"main", "main", "(* 4 x)", 8},
      {"return", "return", "(+ x 100)", 102},
      {"_Bool", "_Bool", "(+ x 101)", 103},
      {"x->y", "x->y", "(* 5 x)", 10},
      {"p_x", "p_x", "(* 6 x)", 12},
      {"λ", "λ", "(* 7 x)", 14},
      {"μ", "μ", "(* 8 x)", 16},
      {"x-y", "x-y", "(+ x 1)", 3},
      {"x_y", "x_y", "(+ x 2)", 4},
      {"x?y", "x?y", "(+ x 3)", 5},
      {"Foo", "Foo", "(- x 1)", 1},
      {"foo", "foo", "(- x 2)", 0},
      {"FOO", "FOO", "(- x 3)", -1},
      {"sicm_kernel_foo", "sicm_kernel_foo", "(- x 4)", -2},
      {"evil */ #include <stdio.h>", "|evil */ #include <stdio.h>|", "(* x x)", 4},
      {"?\?/", "|?\?/|", "(/ x 2)", 1},
      {long_name, long_name, "(* x 9)", 18},
      {long_name + "b", long_name + "b", "(* x 10)", 20},
  };
}

const std::regex kIdentifier("[A-Za-z_][A-Za-z0-9_]*");

// Compile C text to an object with every warning an error; "" on success,
// else the compiler's diagnostics.
std::string compile_strictly(const std::string &source) {
  char tmpl[] = "/tmp/sicm-hostile-XXXXXX";
  std::string dir = mkdtemp(tmpl);
  std::ofstream(dir + "/k.c") << source;
  std::string command = "cc -std=c11 -Wall -Wextra -Werror -pedantic-errors -c -o " + dir +
                        "/k.o " + dir + "/k.c > " + dir + "/log 2>&1";
  int status = std::system(command.c_str());
  std::ifstream log(dir + "/log");
  std::ostringstream text;
  text << log.rdbuf();
  std::system(("rm -rf " + dir).c_str());
  return status == 0 ? "" : "status " + std::to_string(status) + ": " + text.str();
}

} // namespace

TEST(HostileNames, KernelNamesAreDistinctBoundedIdentifiers) {
  std::vector<std::string> names;
  for (const Hostile &h : hostile_procedures())
    names.push_back(h.name);
  // Names built to meet the mangled forms of others: each kept or hashed
  // form's tail, spelled as a name of its own.
  for (const std::string &n : {std::string("x-y"), std::string("λ"), std::string(300, 'a')})
    names.push_back(c_kernel_name(n).substr(std::string("sicm_kernel_").size()));
  names.push_back("");
  std::set<std::string> seen;
  for (const std::string &n : names) {
    std::string c = c_kernel_name(n);
    EXPECT_TRUE(std::regex_match(c, kIdentifier)) << c;
    EXPECT_EQ(c.rfind("sicm_kernel_", 0), 0u) << c;
    EXPECT_LE(c.size(), 70u) << c;
    EXPECT_TRUE(seen.insert(c).second) << "two names give " << c;
  }
  EXPECT_EQ(c_kernel_name("foo"), "sicm_kernel_foo"); // plain names stay readable
  EXPECT_EQ(c_kernel_name("p_x"), "sicm_kernel_p_x");
  EXPECT_EQ(c_kernel_name("x-y").rfind("sicm_kernel_x_y_h", 0), 0u);
  EXPECT_EQ(c_kernel_name("x-y"), c_kernel_name("x-y"));
}

// Every hostile procedure compiled by the whole pipeline: its C compiles
// with warnings as errors and pedantic, contains only printable ASCII, and
// its kernel gives the interpreter's answer.
TEST(HostileNames, EachKernelsCCompilesWithWarningsAsErrors) {
  for (const Hostile &h : hostile_procedures()) {
    SCOPED_TRACE(h.name.substr(0, 40));
    Value proc = run("(define (" + h.spelled + " x) " + h.body + ") " + h.spelled);
    std::string why;
    Kernel *k = compile_kernel(proc, run("(list 1.)"), nullptr, &why);
    ASSERT_NE(k, nullptr) << why;
    EXPECT_EQ(k->name, h.name);
    EXPECT_TRUE(std::regex_match(k->c_name, kIdentifier)) << k->c_name;
    for (char ch : k->c_source)
      EXPECT_TRUE(ch == '\n' || (ch >= 32 && ch < 127)) << "byte " << int(ch);
    EXPECT_EQ(compile_strictly(k->c_source), "") << k->c_source;
    double in = 2, out = 0;
    kernel_call(k, &in, &out);
    EXPECT_EQ(out, h.at2);
  }
}

// All the hostile kernels, named by c_kernel_name, in one translation unit
// (as `sicm emit-c` prints them): no two definitions clash, it compiles with
// warnings as errors, and each function computes its procedure.
TEST(HostileNames, OneTranslationUnitHoldsThemAll) {
  std::string unit = "#define _GNU_SOURCE\n#include <math.h>\n\n";
  std::vector<std::string> c_names;
  for (const Hostile &h : hostile_procedures()) {
    Value proc = run("(define (" + h.spelled + " x) " + h.body + ") " + h.spelled);
    Trace t;
    std::string why;
    ASSERT_TRUE(trace_procedure(proc, run("(list 1.)"), &t, &why)) << why;
    c_names.push_back(c_kernel_name(h.name));
    unit += "void " + c_names.back() + "(const double *in, double *out, const double *p);\n";
    unit += emit_kernel_function(t, c_names.back(), false);
  }
  ASSERT_EQ(compile_strictly(unit), "") << unit;
  std::vector<Hostile> procs = hostile_procedures();
  for (size_t i = 0; i < procs.size(); ++i) {
    std::string why;
    void *fn = jit_load(unit, c_names[i], nullptr, &why);
    ASSERT_NE(fn, nullptr) << why;
    double in = 2, out = 0;
    reinterpret_cast<KernelFn>(fn)(&in, &out, nullptr);
    EXPECT_EQ(out, procs[i].at2) << procs[i].name.substr(0, 40);
  }
}

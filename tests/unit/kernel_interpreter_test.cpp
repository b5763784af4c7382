// Unit tests of the kernel interpreter: the bits of its results against the JIT'ed C of the same
// trace.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "base/number.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/jit.hpp"
#include "codegen/kernel_interpreter.hpp"
#include "codegen/trace.hpp"
#include "eval/interp.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<kernel_interpreter_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

uint64_t bits(double d) {
  uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

// Trace `proc` on the one state `sample`, JIT its C and load its program;
// then both run on `count` states near the sample (each leaf times a
// random factor in [-2, 2]), which must give the same bits, output by
// output. Returns the C, for the caller to check what it exercised.
std::string expect_same_bits(const std::string &proc, const std::string &sample, int count) {
  Trace t;
  std::string why;
  Value samples = run("(list " + sample + ")");
  if (!trace_procedure(run(proc), samples, &t, &why)) {
    ADD_FAILURE() << why;
    return "";
  }
  std::string c = emit_kernel_unit(t, "under_test", "under_test");
  auto fn = reinterpret_cast<KernelFn>(jit_load(c, "under_test", nullptr, &why));
  if (!fn) {
    ADD_FAILURE() << why;
    return "";
  }
  std::shared_ptr<const KernelProgram> program =
      load_kernel_program(t.outputs, t.inputs, t.param_symbols);
  std::vector<double> params;
  for (Value v : t.params)
    params.push_back(to_double(v));
  std::vector<double> start;
  flatten_value(car(samples), start);
  std::mt19937_64 random(20240611);
  std::uniform_real_distribution<double> factor(-2.0, 2.0);
  size_t n = t.outputs.size();
  std::vector<double> in(start.size()), compiled(n), interpreted(n);
  for (int k = 0; k < count; ++k) {
    for (size_t i = 0; i < in.size(); ++i)
      in[i] = k == 0 ? start[i] : start[i] * factor(random);
    fn(in.data(), compiled.data(), params.data());
    run_kernel_program(*program, in.data(), interpreted.data(), params.data());
    for (size_t j = 0; j < n; ++j)
      if (bits(compiled[j]) != bits(interpreted[j])) {
        ADD_FAILURE() << "state " << k << ", output " << j << ": the C gives " << compiled[j]
                      << ", the interpreter " << interpreted[j];
        return c;
      }
  }
  return c;
}

TEST(KernelInterpreter, PowersAndSinCosAsTheC) {
  std::string c = expect_same_bits(
      "(let ((g 9.8)) (lambda (s) (let ((x (ref s 0)) (y (ref s 1)) (z (ref s 2))) "
      "(up (* g (expt x 7) (sin y)) (+ (cos y) (expt x -3) (expt z 70) (expt y 5)) "
      "(* (sin x) (cos x) (exp (/ y 3))) (atan x y) (sqrt (abs (* x z))) (expt (abs z) 1/3) "
      "(- (log (+ 5 (* x x))) (tan z) (asin (/ 1 (+ 2 (* y y)))))))))",
      "(up .7 1.3 -1.1)", 20000);
  EXPECT_NE(c.find("sincos("), std::string::npos);
  EXPECT_NE(c.find("pow("), std::string::npos);
  EXPECT_NE(c.find("p[0]"), std::string::npos); // g is a parameter
}

// Matrices of more than two rows of run-time values are factored
// (algebra/linear_solve.hpp): LDL^T when symmetric, else LU.
TEST(KernelInterpreter, SymmetricSolveAsTheC) {
  std::string c =
      expect_same_bits("(lambda (s) (let ((x (ref s 0)) (y (ref s 1)) (z (ref s 2))) "
                       "(/ (up (sin x) y (* z z)) (matrix-by-rows (list (+ 3 (* x x)) (cos y) z) "
                       "(list (cos y) (+ 4 (* y y)) x) (list z x (+ 5 (* z z)))))))",
                       "(up .4 .9 -.3)", 20000);
  EXPECT_NE(c.find("sicm_ldlt_solve("), std::string::npos);
}

TEST(KernelInterpreter, UnsymmetricSolveAsTheC) {
  std::string c = expect_same_bits(
      "(lambda (s) (let ((x (ref s 0)) (y (ref s 1)) (z (ref s 2))) "
      "(/ (up (sin x) y 1) (matrix-by-rows (list (+ 2 x) 1 z) (list (* 3 y) (+ 4 (* x y)) 1) "
      "(list 1 (* z y) (- 2 x))))))",
      "(up .4 .9 -.3)", 20000);
  EXPECT_NE(c.find("sicm_lu_solve("), std::string::npos);
}

TEST(KernelInterpreter, SingularMatrixGivesTheSingularNaN) {
  // At x = 1 the matrix is singular: both give the NaN that says so.
  std::string c = expect_same_bits("(lambda (s) (let ((x (ref s 0))) (/ (up 1 2 3) "
                                   "(matrix-by-rows (list x 1 0) (list 1 x 0) (list 0 0 x)))))",
                                   "(up 1.)", 1);
  EXPECT_NE(c.find("sicm_singular_nan()"), std::string::npos);
}

TEST(KernelInterpreter, GlibcSincosIsSinAndCos) {
  // The C compiler may turn a sin and a cos of one argument into sincos:
  // the interpreter agrees with it either way only if sincos gives their bits.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> angle(-1e3, 1e3);
  for (int k = 0; k < 200000; ++k) {
    double x = k < 100000 ? angle(random) : std::ldexp(angle(random), -(k % 60));
    double s, c;
    ::sincos(x, &s, &c);
    ASSERT_EQ(bits(s), bits(std::sin(x))) << x;
    ASSERT_EQ(bits(c), bits(std::cos(x))) << x;
  }
}

} // namespace

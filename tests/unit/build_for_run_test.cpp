// Unit tests of compile_for_run (pe/for_run.cpp): a procedure of one
// real compiled by the partial evaluator for sicm run, loops included, and
// refused, with the heap as it was, when tracing it once would do its
// effects once.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "base/limits.hpp"
#include "base/number.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "pe/build.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

// Evaluate every form of text; the value of the last.
Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<build_for_run_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

CompiledFn compile(const std::string &proc, std::string *why) {
  return compile_for_run(run(proc), "bisect", why);
}

double call(CompiledFn fn, double x) {
  double out = NAN;
  EXPECT_EQ(fn(&x, &out, interrupt_flag()), 0) << "at " << x;
  return out;
}

TEST(CompileForRun, LoopWhoseExitDependsOnTheArgument) {
  // Halve x until it is below 1: the count of halvings, minus 3.
  std::string why;
  CompiledFn fn = compile("(lambda (x)"
                          "  (let loop ((x x) (n 0))"
                          "    (if (< x 1.) (- n 3) (loop (/ x 2.) (+ n 1)))))",
                          &why);
  ASSERT_NE(fn, nullptr) << why;
  EXPECT_EQ(call(fn, 0.5), -3.0);
  EXPECT_EQ(call(fn, 5.0), 0.0);    // 5 -> 2.5 -> 1.25 -> 0.625
  EXPECT_EQ(call(fn, 1000.0), 7.0); // 2^10 = 1024
}

TEST(CompileForRun, ClosureOverKnownValues) {
  run("(define (make-shifted c) (lambda (x) (- (* x x) c)))");
  std::string why;
  CompiledFn fn = compile("(make-shifted 2)", &why);
  ASSERT_NE(fn, nullptr) << why;
  EXPECT_EQ(call(fn, 3.0), 7.0);
}

TEST(CompileForRun, CheckedOperationLeavesTheValueToTheInterpreter) {
  std::string why;
  CompiledFn fn = compile("(lambda (x) (/ 1. (- x 2.)))", &why);
  ASSERT_NE(fn, nullptr) << why;
  double x = 2.0, out = 0;
  EXPECT_EQ(fn(&x, &out, interrupt_flag()), 1); // division by zero: the interpreter raises it
  x = 3.0;
  EXPECT_EQ(fn(&x, &out, interrupt_flag()), 0);
  EXPECT_EQ(out, 1.0);
  fn = compile("(lambda (x) (sqrt x))", &why);
  ASSERT_NE(fn, nullptr) << why;
  x = -1.0;
  EXPECT_EQ(fn(&x, &out, interrupt_flag()), 1); // a complex number
}

TEST(CompileForRun, InterruptEndsACompiledLoop) {
  // A loop that never ends: Ctrl-C (in the REPL) must still stop it.
  std::string why;
  CompiledFn fn = compile("(lambda (x) (let loop ((y x)) (if (< y 0.) y (loop (+ y 1.)))))", &why);
  ASSERT_NE(fn, nullptr) << why;
  request_interrupt();
  double x = 1.0, out = 0;
  EXPECT_EQ(fn(&x, &out, interrupt_flag()), 1); // given up: the interpreter raises "Interrupted"
  begin_evaluation(SrcLoc{});                   // forgets the request
  x = -1.0;
  EXPECT_EQ(fn(&x, &out, interrupt_flag()), 0);
  EXPECT_EQ(out, -1.0);
}

TEST(CompileForRun, AssignmentOfAnOuterVariableIsRefusedAndNotDone) {
  run("(define calls 0)");
  std::string why;
  EXPECT_EQ(compile("(lambda (x) (set! calls (+ calls 1)) x)", &why), nullptr);
  EXPECT_NE(why.find("set!"), std::string::npos) << why;
  EXPECT_EQ(write_string(run("calls")), "0");
  run("(define (counter) (let ((n 0)) (lambda (x) (set! n (+ n 1)) (- x n))))");
  EXPECT_EQ(compile("(counter)", &why), nullptr);
}

TEST(CompileForRun, MutationOutputAndPromisesAreRefusedAndNotDone) {
  run("(define v (vector 0))");
  std::string why;
  EXPECT_EQ(compile("(lambda (x) (vector-set! v 0 x) x)", &why), nullptr);
  EXPECT_EQ(write_string(run("v")), "#(0)");
  run("(define p (delay (vector-set! v 0 1)))");
  EXPECT_EQ(compile("(lambda (x) (force p) x)", &why), nullptr);
  EXPECT_EQ(write_string(run("v")), "#(0)");
  EXPECT_EQ(compile("(lambda (x) (display x) x)", &why), nullptr);
  EXPECT_EQ(compile("(lambda (x) (+ x (random 1.)))", &why), nullptr);
}

TEST(CompileForRun, OnlyWhatTheProcedureMadeMayChange) {
  run("(define outer (list 1 2))");
  std::string why;
  EXPECT_EQ(compile("(lambda (x) (set-car! outer x) x)", &why), nullptr);
  EXPECT_EQ(write_string(run("outer")), "(1 2)");
  EXPECT_EQ(compile("(lambda (x) (append! outer (list x)) x)", &why), nullptr);
  EXPECT_EQ(write_string(run("outer")), "(1 2)");
  // A pair it makes, even one whose tail is an outer list, it may change.
  CompiledFn fn =
      compile("(lambda (x) (let ((p (cons 0. outer))) (set-car! p x) (* 2. (car p))))", &why);
  ASSERT_NE(fn, nullptr) << why;
  EXPECT_EQ(call(fn, 3.0), 6.0);
}

TEST(CompileForRun, TheInterpreterIsItselfAfterwards) {
  std::string why;
  EXPECT_EQ(compile("(lambda (x) (display x) x)", &why), nullptr);
  // The primitives the trace rebound are the interpreter's again.
  EXPECT_EQ(write_string(run("(with-output-to-string (lambda () (display 1.5)))")), "\"1.5\"");
  EXPECT_EQ(write_string(run("(< 1 2 3)")), "#t");
  EXPECT_EQ(write_string(run("(let ((p (cons 1 2))) (set-car! p 3) p)")), "(3 . 2)");
  EXPECT_FALSE(in_build_mode());
}

TEST(CompileForRun, NumericalPrimitivesInsideAreRefused) {
  std::string why;
  EXPECT_EQ(compile("(lambda (x) (- (definite-integral (lambda (t) (* t t)) 0. x) 1.))", &why),
            nullptr);
  EXPECT_FALSE(in_build_mode());
}

// A system derivative that tests the state: the kernel tracer cannot
// compile it, the partial evaluator can, for states of the given shape.
CompiledFn compile_system(const std::string &proc, const std::string &state, std::string *why) {
  return compile_system_for_run(run(proc), run(state), "state-advancer", why);
}

TEST(CompileSystemForRun, PiecewiseForceTakesTheBranchOfEachState) {
  std::string why;
  CompiledFn fn = compile_system("(lambda (s)"
                                 "  (let ((x (ref s 1)) (v (ref s 2)))"
                                 "    (up 1 v (if (> x 0) (* -1 x) (* -4 x)))))",
                                 "(up 0. 0. 1.)", &why);
  ASSERT_NE(fn, nullptr) << why;
  double out[3] = {0, 0, 0};
  double right[3] = {0.0, 0.5, 2.0};
  ASSERT_EQ(fn(right, out, interrupt_flag()), 0);
  EXPECT_EQ(out[0], 1.0);
  EXPECT_EQ(out[1], 2.0);
  EXPECT_EQ(out[2], -0.5); // x > 0: -x
  double left[3] = {0.0, -0.5, 2.0};
  ASSERT_EQ(fn(left, out, interrupt_flag()), 0);
  EXPECT_EQ(out[2], 2.0); // x < 0: -4x
}

TEST(CompileSystemForRun, EffectsAreRefusedAndNotDone) {
  run("(define evaluations 0)");
  std::string why;
  EXPECT_EQ(compile_system("(lambda (s) (set! evaluations (+ evaluations 1))"
                           "  (up 1 (if (> (ref s 1) 0) 1. 2.)))",
                           "(up 0. 0.)", &why),
            nullptr);
  EXPECT_EQ(write_string(run("evaluations")), "0");
  EXPECT_FALSE(in_build_mode());
}

} // namespace

// The residual program's verifier (codegen/residual_check.hpp): a program as
// the partial evaluator leaves it passes; each broken invariant is named.
#include <gtest/gtest.h>

#include "codegen/residual_check.hpp"

namespace {

using namespace sicm;

// main prints the integral of f1 (x -> x * k) from 0 to 1, where k is
// main's variable r0 = 2.5, captured by f1.
class ResidualCheck : public ::testing::Test {
protected:
  void SetUp() override {
    p.functions.push_back(RFunction{0, -1, "main", {}, {}, {}, {}});
    p.functions.push_back(RFunction{1, 0, "f", {}, {}, {}, {}});
    int k = var(0, RType::Real), x = var(1, RType::Real), r = var(0, RType::Real);
    p.functions[1].inputs = {x};
    p.functions[1].outputs = {expr_apply(Op::Mul, {ref(x), ref(k)})};
    RStmt let{RKind::Let};
    let.var = k;
    let.args = {expr_flonum(2.5)};
    RStmt integral{RKind::Integral};
    integral.args = {expr_flonum(0), expr_flonum(1)};
    integral.outs = {r};
    integral.callee = 1;
    integral.number = 1e-10;
    RStmt print{RKind::Print};
    print.var = r;
    p.functions[0].body = {let, integral, print};
  }

  int var(int function, RType type) {
    int id = static_cast<int>(p.vars.size());
    Symbol *s = make_uninterned_symbol("v" + std::to_string(id)).symbol();
    p.vars.push_back(RVar{s, type, id, function});
    return id;
  }
  ExprId ref(int v) { return expr_symbol(p.vars[static_cast<size_t>(v)].sym); }
  std::vector<RStmt> &main_body() { return p.functions[0].body; }

  ResidualProgram p;
};

TEST_F(ResidualCheck, AcceptsAWellFormedProgram) {
  EXPECT_EQ(residual_violation(p), "");
}

TEST_F(ResidualCheck, AcceptsAVariableOfABranchUsedAfterIt) {
  // What an alternative defines is declared where the function starts.
  int t = var(0, RType::Real);
  RStmt let{RKind::Let};
  let.var = t;
  let.args = {expr_flonum(1)};
  RStmt branch{RKind::If};
  branch.args = {ref(0)};
  branch.then_body = {let};
  RStmt print{RKind::Print};
  print.var = t;
  main_body().push_back(branch);
  main_body().push_back(print);
  EXPECT_EQ(residual_violation(p), "");
}

TEST_F(ResidualCheck, RejectsAUseBeforeTheDefinition) {
  std::swap(main_body()[1], main_body()[2]); // print r2 before the integral defines it
  EXPECT_NE(residual_violation(p).find("r2 is used before it is defined"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsAVariableDefinedTwice) {
  main_body().push_back(main_body()[0]);
  EXPECT_NE(residual_violation(p).find("r0 is defined twice"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsACalleeOutOfRange) {
  main_body()[1].callee = 7;
  EXPECT_NE(residual_violation(p).find("callee f7 is not a function"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsAStatementWithoutItsFields) {
  main_body()[1].args.pop_back(); // an integral over [0, ?]
  EXPECT_NE(residual_violation(p).find("statement 1 (definite-integral): has 1 operands, not 2"),
            std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsAnEnclosingFunctionAfterItsChild) {
  p.functions[1].parent = 1;
  EXPECT_NE(residual_violation(p).find("f1: its enclosing function"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsAContinueOutsideALoop) {
  main_body().push_back(RStmt{RKind::Continue});
  EXPECT_NE(residual_violation(p).find("(continue): is outside a loop"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsAComparisonThatIsNoTruthValue) {
  int b = var(0, RType::Real);
  RStmt less{RKind::Let};
  less.compute = RCompute::Less;
  less.var = b;
  less.args = {ref(0), expr_flonum(3)};
  main_body().push_back(less);
  EXPECT_NE(residual_violation(p).find("is not a truth value"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsADanglingExpression) {
  p.functions[1].outputs = {static_cast<ExprId>(expr_count() + 1000)};
  EXPECT_NE(residual_violation(p).find("is not in the arena"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, RejectsAnInputOfAnotherFunction) {
  p.functions[1].inputs = {0}; // main's r0
  EXPECT_NE(residual_violation(p).find("input r0 belongs to f0"), std::string::npos)
      << residual_violation(p);
}

TEST_F(ResidualCheck, LeavesUserErrorsToTheEmitter) {
  // A symbol with no value is the emitter's "cannot compile", not a
  // broken invariant.
  main_body()[0].args = {expr_symbol(intern("m").symbol())};
  EXPECT_EQ(residual_violation(p), "");
}

} // namespace

// Unit tests that no name the system makes for itself reaches a printed result:
// the literal numbers of compatible-shape and typical-object (x100, x101, ...,
// uninterned, algebra/structure_primitives.cpp) cancel out of the book's
// chapter 5 checks of canonical transformations, which print zeros.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "cas/expr.hpp"
#include "eval/interp.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

// The book's definitions (SICM 5.1-5.3) beyond the library's.
const char *kDefinitions = R"(
(define (p->r local)
  (let ((polar-tuple (coordinate local)))
    (let ((r (ref polar-tuple 0))
          (phi (ref polar-tuple 1)))
      (up (* r (cos phi)) (* r (sin phi))))))
(define ((H-harmonic m k) s)
  (+ (/ (square (momentum s)) (* 2 m))
     (* 1/2 k (square (coordinate s)))))
(define (a-non-canonical-transform H-state)
  (let ((t (time H-state))
        (theta (coordinate H-state))
        (p (momentum H-state)))
    (up t (* p (sin theta)) (* p (cos theta)))))
(define a-polar-state (up 't (up 'r 'phi) (down 'pr 'pphi)))
(define zeta1
  (up 0 (typical-object (coordinate a-polar-state)) (typical-object (momentum a-polar-state))))
(define zeta2
  (up 0 (typical-object (coordinate a-polar-state)) (typical-object (momentum a-polar-state))))
)";

Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<generated_names_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

// Does the simplified value hold an uninterned symbol (a name made by the
// system, not written by the user)?
bool holds_generated_name(Value v) {
  if (v.is(Tag::Symbol)) return v.symbol()->uninterned;
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    for (size_t i = 0; i < s->len; i++)
      if (holds_generated_name(s->items[i])) return true;
    return false;
  }
  if (is_matrix(v)) {
    Matrix *m = as_matrix(v);
    for (size_t i = 0; i < m->rows * m->cols; i++)
      if (holds_generated_name(m->items[i])) return true;
    return false;
  }
  if (!v.is(Tag::Expr)) return false;
  Value s = simplify_value(v);
  if (!s.is(Tag::Expr)) return holds_generated_name(s);
  return !expr_visit({static_cast<ExprId>(s.i)}, [](ExprId id) {
    const ExprNode &n = expr_node(id);
    return !(n.kind == ExprKind::Symbol && n.sym->uninterned);
  });
}

struct Check {
  const char *what;       // the book's section and what it checks
  const char *expression; // evaluated after kDefinitions
  const char *printed;    // what the book prints
};

TEST(GeneratedNames, NeverInTheBooksCanonicalChecks) {
  run(kDefinitions);
  const std::vector<Check> checks = {
      {"5.2.1, p.328: the polar-canonical transformation is canonical",
       "((time-independent-canonical? (polar-canonical 'alpha)) (up 't 'theta 'I))", "(up 0 0 0)"},
      {"5.2.1: the point transformation to polar coordinates is canonical",
       "((time-independent-canonical? (F->CT p->r)) (up 't (up 'r 'phi) (down 'p_r 'p_phi)))",
       "(up 0 (up 0 0) (down 0 0))"},
      {"5.2.2: the polar-canonical transformation is symplectic",
       "((symplectic-transform? (polar-canonical 'alpha)) (up 't 'theta 'I))",
       "(matrix-by-rows (list 0 0) (list 0 0))"},
      {"5.2.2, p.333: the point transformation to polar coordinates is symplectic",
       "((symplectic-transform? (F->CT p->r)) (up 't (up 'r 'theta) (down 'p_r 'p_theta)))",
       "(matrix-by-rows (list 0 0 0 0) (list 0 0 0 0) (list 0 0 0 0) (list 0 0 0 0))"},
      {"5.2.3, p.335: rotating coordinates are symplectic",
       "((symplectic-transform? (C-rotating 'Omega)) (up 't (up 'x 'y 'z) (down 'px 'py 'pz)))",
       "(matrix-by-rows (list 0 0 0 0 0 0) (list 0 0 0 0 0 0) (list 0 0 0 0 0 0) (list 0 0 0 0 0 "
       "0) (list 0 0 0 0 0 0) (list 0 0 0 0 0 0))"},
      {"5.2: the harmonic oscillator in polar-canonical coordinates",
       "((compositional-canonical? (polar-canonical 'alpha) (H-harmonic 'm 'k)) (up 't 'theta "
       "'I))",
       "(up 0 0 0)"},
      {"5.3, p.342: the symplectic 2-form is invariant",
       "(let ((DCs ((D (F->CT p->r)) a-polar-state)))"
       "  (- (omega zeta1 zeta2) (omega (* DCs zeta1) (* DCs zeta2))))",
       "0"},
  };
  for (const Check &c : checks) {
    Value v = run(c.expression);
    EXPECT_FALSE(holds_generated_name(v)) << c.what << ": " << write_string(v);
    EXPECT_EQ(write_string(v), c.printed) << c.what;
  }
}

// The book's non-canonical transform (5.2.1, p.328) leaves a residual that
// holds the generated literals, as the book prints it: the check above
// would see them.
TEST(GeneratedNames, SeenInANonCanonicalResidual) {
  run(kDefinitions);
  Value v = run("((time-independent-canonical? a-non-canonical-transform) (up 't 'theta 'p))");
  EXPECT_TRUE(holds_generated_name(v)) << write_string(v);
  // A user's own symbol of the same spelling is not one.
  EXPECT_FALSE(holds_generated_name(run("(+ 'x101 'x102)")));
}

// Under the test runner (SICM_MARK_GENERATED_NAMES, tests/run) a generated
// name prints marked, so that every test's output is searched for one; a
// user's symbol of the same spelling prints as written.
TEST(GeneratedNames, PrintMarkedForTheTestRunner) {
  run(kDefinitions);
  Value residual =
      run("((time-independent-canonical? a-non-canonical-transform) (up 't 'theta 'p))");
  set_mark_generated_names(true);
  const std::string marked = write_string(residual), user = write_string(run("(list 'x101)"));
  set_mark_generated_names(false);
  EXPECT_NE(marked.find("\u00abx"), std::string::npos) << marked;
  EXPECT_EQ(user, "(x101)");
  EXPECT_EQ(write_string(residual).find("\u00ab"), std::string::npos);
}

} // namespace

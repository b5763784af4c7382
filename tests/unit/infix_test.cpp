// Unit tests of the infix and TeX renderings of expression data and of the book's name conventions.
#include <gtest/gtest.h>

#include "print/display_names.hpp"
#include "print/infix.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

Value datum(const std::string &text) {
  gcvec<ReadForm> forms = read_all(register_source("infix-test.sicm", text));
  EXPECT_EQ(forms.size(), 1u) << text;
  return forms.empty() ? Value::nil() : forms[0].datum;
}

std::string infix(const std::string &text) {
  return datum_to_infix(datum(text));
}

std::string tex(const std::string &text) {
  return datum_to_tex(datum(text));
}

} // namespace

// ---- names -----------------------------------------------------------------

TEST(DisplayNames, PlainNamesUnchanged) {
  EXPECT_EQ(display_name("x"), "x");
  EXPECT_EQ(display_name("m"), "m");
  EXPECT_EQ(display_name("sin"), "sin");
  EXPECT_EQ(display_name("L-free-particle"), "L-free-particle");
  EXPECT_EQ(display_name("dot"), "dot");
  EXPECT_EQ(display_name("betamax"), "betamax");
}

TEST(DisplayNames, Greek) {
  EXPECT_EQ(display_name("theta"), "θ");
  EXPECT_EQ(display_name("alpha"), "α");
  EXPECT_EQ(display_name("epsilon"), "ε");
  EXPECT_EQ(display_name("lambda"), "λ");
  EXPECT_EQ(display_name("omicron"), "ο");
  EXPECT_EQ(display_name("omega"), "ω");
  EXPECT_EQ(display_name("Gamma"), "Γ");
  EXPECT_EQ(display_name("Omega"), "Ω");
  EXPECT_EQ(display_name("theta1"), "θ1");
}

TEST(DisplayNames, Dots) {
  EXPECT_EQ(display_name("xdot"), "x\u0307");
  EXPECT_EQ(display_name("thetadot"), "θ\u0307");
  EXPECT_EQ(display_name("thetadotdot"), "θ\u0308");
  EXPECT_EQ(display_name("rdotdotdot"), "r\u20DB");
  EXPECT_EQ(display_name("dotdot"), "dotdot");
}

TEST(DisplayNames, Subscripts) {
  EXPECT_EQ(display_name("p_x"), "pₓ");
  EXPECT_EQ(display_name("y_s"), "yₛ");
  EXPECT_EQ(display_name("x_10"), "x₁₀");
  EXPECT_EQ(display_name("theta_0"), "θ₀");
  EXPECT_EQ(display_name("p_theta"), "p_θ");
  EXPECT_EQ(display_name("p_phi"), "pᵩ");
  EXPECT_EQ(display_name("p_y"), "p_y"); // no subscript y in Unicode
  EXPECT_EQ(display_name("p_xdot"), "p_x\u0307");
}

TEST(DisplayNames, Superscripts) {
  EXPECT_EQ(display_name("v^0"), "v⁰");
  EXPECT_EQ(display_name("x^n"), "xⁿ");
  EXPECT_EQ(display_name("x^Q"), "x^Q");
  EXPECT_EQ(display_name("p_x^2"), "pₓ²");
}

TEST(DisplayNames, MalformedKeptAsIs) {
  EXPECT_EQ(display_name("_x"), "_x");
  EXPECT_EQ(display_name("x_"), "x_");
  EXPECT_EQ(display_name("x__y"), "x__y");
}

TEST(DisplayNames, Scripts) {
  EXPECT_EQ(to_subscript("12"), "₁₂");
  EXPECT_EQ(to_superscript("2"), "²");
  EXPECT_EQ(to_subscript("q"), std::nullopt);
  EXPECT_EQ(to_subscript(""), std::nullopt);
}

TEST(DisplayNames, Tex) {
  EXPECT_EQ(tex_name("x"), "x");
  EXPECT_EQ(tex_name("theta"), "\\theta");
  EXPECT_EQ(tex_name("Omega"), "\\Omega");
  EXPECT_EQ(tex_name("thetadot"), "\\dot{\\theta}");
  EXPECT_EQ(tex_name("xdotdot"), "\\ddot{x}");
  EXPECT_EQ(tex_name("p_x"), "p_{x}");
  EXPECT_EQ(tex_name("p_theta"), "p_{\\theta}");
  EXPECT_EQ(tex_name("v^0"), "v^{0}");
  EXPECT_EQ(tex_name("y_s"), "y_{s}");
  EXPECT_EQ(tex_name("sin"), "\\mathit{sin}");
  EXPECT_EQ(tex_name("x_"), "\\mathit{x\\_}");
  EXPECT_EQ(tex_name("a&b"), "\\mathit{a\\&b}");
}

// ---- infix -----------------------------------------------------------------

TEST(Infix, Atoms) {
  EXPECT_EQ(infix("42"), "42");
  EXPECT_EQ(infix("-3"), "-3");
  EXPECT_EQ(infix("1/2"), "1/2");
  EXPECT_EQ(infix(".5"), ".5");
  EXPECT_EQ(infix("theta"), "θ");
  EXPECT_EQ(infix("\"text\""), "text");
}

TEST(Infix, Sums) {
  EXPECT_EQ(infix("(+ a b)"), "a + b");
  EXPECT_EQ(infix("(+ a b c)"), "a + b + c");
  EXPECT_EQ(infix("(+ a (* -1 b))"), "a - b");
  EXPECT_EQ(infix("(+ a (* -2 b c))"), "a - 2 b c");
  EXPECT_EQ(infix("(+ a -3)"), "a - 3");
  EXPECT_EQ(infix("(+ (* -1 a) b)"), "-a + b");
  EXPECT_EQ(infix("(+ (* -1/2 a) b)"), "-1/2 a + b");
  EXPECT_EQ(infix("(+ a (- b))"), "a - b");
  EXPECT_EQ(infix("(+ a (- (+ b c)))"), "a - (b + c)");
  EXPECT_EQ(infix("(+ a (/ (* -1 b) c))"), "a - b / c");
  EXPECT_EQ(infix("(+ a)"), "a");
  EXPECT_EQ(infix("(+)"), "0");
}

TEST(Infix, Differences) {
  EXPECT_EQ(infix("(- a b c)"), "a - b - c");
  EXPECT_EQ(infix("(- a (+ b c))"), "a - (b + c)");
  EXPECT_EQ(infix("(- a (- b c))"), "a - (b - c)");
  EXPECT_EQ(infix("(- a (* -1 b))"), "a - (-b)");
  EXPECT_EQ(infix("(- a (* 2 b))"), "a - 2 b");
  EXPECT_EQ(infix("(- x)"), "-x");
  EXPECT_EQ(infix("(- (+ a b))"), "-(a + b)");
  EXPECT_EQ(infix("(- -3)"), "-(-3)");
}

TEST(Infix, Products) {
  EXPECT_EQ(infix("(* a b)"), "a b");
  EXPECT_EQ(infix("(* 1/2 m (expt v 2))"), "1/2 m v^2");
  EXPECT_EQ(infix("(* -1 x)"), "-x");
  EXPECT_EQ(infix("(* -2 x)"), "-2 x");
  EXPECT_EQ(infix("(* -1 (+ a b))"), "-(a + b)");
  EXPECT_EQ(infix("(* a (+ b c))"), "a (b + c)");
  EXPECT_EQ(infix("(* (+ a b) (- c d))"), "(a + b) (c - d)");
  EXPECT_EQ(infix("(* 2 (/ a b))"), "2 (a / b)");
  EXPECT_EQ(infix("(* a 2)"), "a * 2");
  EXPECT_EQ(infix("(* a (- b))"), "a (-b)");
  EXPECT_EQ(infix("(* a)"), "a");
  EXPECT_EQ(infix("(*)"), "1");
  EXPECT_EQ(infix("(* -1. x)"), "-1. x");
}

TEST(Infix, Quotients) {
  EXPECT_EQ(infix("(/ a b)"), "a / b");
  EXPECT_EQ(infix("(/ (+ a b) (* 2 m))"), "(a + b) / (2 m)");
  EXPECT_EQ(infix("(/ (* a b) c)"), "a b / c");
  EXPECT_EQ(infix("(/ a (expt r 2))"), "a / r^2");
  EXPECT_EQ(infix("(/ (* -1 (p_x t)) m)"), "-pₓ(t) / m");
  EXPECT_EQ(infix("(/ (/ a b) c)"), "(a / b) / c");
  EXPECT_EQ(infix("(/ a (/ b c))"), "a / (b / c)");
  EXPECT_EQ(infix("(/ a -2)"), "a / (-2)");
  EXPECT_EQ(infix("(/ a b c)"), "a / b / c");
  EXPECT_EQ(infix("(/ x)"), "1 / x");
}

TEST(Infix, Powers) {
  EXPECT_EQ(infix("(expt x 2)"), "x^2");
  EXPECT_EQ(infix("(expt (+ x y) 2)"), "(x + y)^2");
  EXPECT_EQ(infix("(expt (* 2 x) 2)"), "(2 x)^2");
  EXPECT_EQ(infix("(expt x -1)"), "x^-1");
  EXPECT_EQ(infix("(expt x 1/2)"), "x^(1/2)");
  EXPECT_EQ(infix("(expt x (+ n 1))"), "x^(n + 1)");
  EXPECT_EQ(infix("(expt x n)"), "x^n");
  EXPECT_EQ(infix("(expt (expt x 2) 3)"), "(x^2)^3");
  EXPECT_EQ(infix("(expt -2 x)"), "(-2)^x");
  EXPECT_EQ(infix("(expt 1/2 x)"), "(1/2)^x");
  EXPECT_EQ(infix("(expt (sin theta) 2)"), "sin(θ)^2");
  EXPECT_EQ(infix("(expt ((D x) t) 2)"), "Dx(t)^2");
  EXPECT_EQ(infix("(expt thetadot 2)"), "θ\u0307^2");
}

TEST(Infix, Functions) {
  EXPECT_EQ(infix("(f t)"), "f(t)");
  EXPECT_EQ(infix("(V x y)"), "V(x, y)");
  EXPECT_EQ(infix("(sin theta)"), "sin(θ)");
  EXPECT_EQ(infix("(cos (* omega t))"), "cos(ω t)");
  EXPECT_EQ(infix("(sqrt x)"), "√x");
  EXPECT_EQ(infix("(sqrt (+ x y))"), "√(x + y)");
  EXPECT_EQ(infix("(expt (sqrt x) 3)"), "(√x)^3");
  EXPECT_EQ(infix("(abs (- a b))"), "|a - b|");
  EXPECT_EQ(infix("(y_s t)"), "yₛ(t)");
  EXPECT_EQ(infix("((f a) b)"), "f(a)(b)");
  EXPECT_EQ(infix("((+ f g) t)"), "(f + g)(t)");
}

TEST(Infix, Derivatives) {
  EXPECT_EQ(infix("((D x) t)"), "Dx(t)");
  EXPECT_EQ(infix("(((expt D 2) x) t)"), "D²x(t)");
  EXPECT_EQ(infix("(((expt D n) x) t)"), "D^(n)x(t)");
  EXPECT_EQ(infix("((D theta) t)"), "Dθ(t)");
  EXPECT_EQ(infix("((D p_x) t)"), "Dpₓ(t)");
  EXPECT_EQ(infix("(((partial 0) V) (x t) (y t))"), "∂₀V(x(t), y(t))");
  EXPECT_EQ(infix("(((partial 1 0) H) s)"), "∂₁,₀H(s)");
  EXPECT_EQ(infix("(((partial 12) H) s)"), "∂₁₂H(s)");
  EXPECT_EQ(infix("(((expt (partial 1) 2) L) s)"), "∂₁²L(s)");
  EXPECT_EQ(infix("(((partial 1) ((partial 0) L)) s)"), "∂₁∂₀L(s)");
  EXPECT_EQ(infix("((D (+ f g)) t)"), "D(f + g)(t)");
  EXPECT_EQ(infix("(D f)"), "Df");
  EXPECT_EQ(infix("(expt D 2)"), "D²");
  EXPECT_EQ(infix("(partial 1)"), "∂₁");
  EXPECT_EQ(infix("(* m (((expt D 2) x) t))"), "m D²x(t)");
}

TEST(Infix, Structures) {
  EXPECT_EQ(infix("(up a b)"), "up(a, b)");
  EXPECT_EQ(infix("(down (+ a b) (* -1 c))"), "down(a + b, -c)");
  EXPECT_EQ(infix("(up t (up x y) (down p_x p_y))"), "up(t, up(x, y), down(pₓ, p_y))");
  EXPECT_EQ(infix("(up)"), "up()");
  EXPECT_EQ(infix("(matrix-by-rows (list a b) (list c d))"), "[[a, b], [c, d]]");
  EXPECT_EQ(infix("(matrix-by-rows (list (+ a 1)))"), "[[a + 1]]");
  EXPECT_EQ(infix("(* 2 (up a b))"), "2 up(a, b)");
}

TEST(Infix, PlainLists) {
  EXPECT_EQ(infix("(0 1/4 -1)"), "(0, 1/4, -1)");
  EXPECT_EQ(infix("(1.5 (+ a b))"), "(1.5, a + b)");
  EXPECT_EQ(infix("()"), "()");
  EXPECT_EQ(infix("(a . b)"), "(a . b)");
}

TEST(Infix, Relations) {
  EXPECT_EQ(infix("(= (+ a b) c)"), "a + b = c");
  EXPECT_EQ(infix("(* 2 (= a b))"), "2 (a = b)");
}

TEST(Infix, BookResults) {
  // 1.5.2: the Lagrange equation of the free particle.
  EXPECT_EQ(infix("(* (((expt D 2) x) t) m)"), "D²x(t) m");
  // 1.6: the Lagrangian of the harmonic oscillator.
  EXPECT_EQ(infix("(+ (* 1/2 m (expt ((D x) t) 2)) (* -1/2 k (expt (x t) 2)))"),
            "1/2 m Dx(t)^2 - 1/2 k x(t)^2");
  // 1.6.3: the driven pendulum.
  EXPECT_EQ(infix("(+ (* g l m (cos theta)) (* -1 g m (y_s t)) "
                  "(* 1/2 (expt l 2) m (expt thetadot 2)) "
                  "(* l m thetadot ((D y_s) t) (sin theta)) (* 1/2 m (expt ((D y_s) t) 2)))"),
            "g l m cos(θ) - g m yₛ(t) + 1/2 l^2 m θ\u0307^2 + l m θ\u0307 Dyₛ(t) sin(θ)"
            " + 1/2 m Dyₛ(t)^2");
  // 3.1: Hamilton's equations.
  EXPECT_EQ(infix("(up 0 (up (+ ((D x) t) (/ (* -1 (p_x t)) m)) (+ ((D y) t) (/ (* -1 (p_y t)) "
                  "m))) (down (+ ((D p_x) t) (((partial 0) V) (x t) (y t))) "
                  "(+ ((D p_y) t) (((partial 1) V) (x t) (y t)))))"),
            "up(0, up(Dx(t) - pₓ(t) / m, Dy(t) - p_y(t) / m), "
            "down(Dpₓ(t) + ∂₀V(x(t), y(t)), Dp_y(t) + ∂₁V(x(t), y(t))))");
  // Notation appendix: the derivative of a function of a structure.
  EXPECT_EQ(infix("(down (((partial 0) H) (up t (up x y))) (down (((partial 1 0) H) (up t (up x "
                  "y))) (((partial 1 1) H) (up t (up x y)))))"),
            "down(∂₀H(up(t, up(x, y))), down(∂₁,₀H(up(t, up(x, y))), ∂₁,₁H(up(t, up(x, y)))))");
  // 3.2: the axisymmetric top.
  EXPECT_EQ(infix("(+ (/ (* 1/2 (expt p_psi 2)) C) (/ (* -1 p_phi p_psi (cos theta)) (* A (expt "
                  "(sin theta) 2))) (* gMR (cos theta)))"),
            "1/2 p_ψ^2 / C - pᵩ p_ψ cos(θ) / (A sin(θ)^2) + gMR cos(θ)");
}

// ---- TeX -------------------------------------------------------------------

TEST(Tex, Atoms) {
  EXPECT_EQ(tex("42"), "42");
  EXPECT_EQ(tex("1/2"), "\\frac{1}{2}");
  EXPECT_EQ(tex("-3/4"), "-\\frac{3}{4}");
  EXPECT_EQ(tex("1e-20"), "1 \\times 10^{-20}");
  EXPECT_EQ(tex("theta"), "\\theta");
  EXPECT_EQ(tex("thetadot"), "\\dot{\\theta}");
  EXPECT_EQ(tex("p_x"), "p_{x}");
}

TEST(Tex, Arithmetic) {
  EXPECT_EQ(tex("(+ a (* -1 b))"), "a - b");
  EXPECT_EQ(tex("(* 1/2 m (expt v 2))"), "\\frac{1}{2} m v^{2}");
  EXPECT_EQ(tex("(* -1/2 k)"), "-\\frac{1}{2} k");
  EXPECT_EQ(tex("(* 2 3)"), "2 \\cdot 3");
  EXPECT_EQ(tex("(/ a b)"), "\\frac{a}{b}");
  EXPECT_EQ(tex("(/ (+ a b) (* 2 m))"), "\\frac{a + b}{2 m}");
  EXPECT_EQ(tex("(+ x (/ (* -1 p) m))"), "x - \\frac{p}{m}");
  EXPECT_EQ(tex("(* 2 (/ a b))"), "2 \\frac{a}{b}");
  EXPECT_EQ(tex("(/ a b c)"), "\\frac{\\frac{a}{b}}{c}");
  EXPECT_EQ(tex("(* a (+ b c))"), "a \\left(b + c\\right)");
  EXPECT_EQ(tex("(- a (- b c))"), "a - \\left(b - c\\right)");
}

TEST(Tex, Powers) {
  EXPECT_EQ(tex("(expt x 2)"), "x^{2}");
  EXPECT_EQ(tex("(expt (+ x y) 2)"), "\\left(x + y\\right)^{2}");
  EXPECT_EQ(tex("(expt (/ a b) 2)"), "\\left(\\frac{a}{b}\\right)^{2}");
  EXPECT_EQ(tex("(expt x (+ n 1))"), "x^{n + 1}");
  EXPECT_EQ(tex("(expt x -1)"), "x^{-1}");
  EXPECT_EQ(tex("(expt thetadot 2)"), "\\dot{\\theta}^{2}");
  EXPECT_EQ(tex("(expt v^0 2)"), "{v^{0}}^{2}");
  EXPECT_EQ(tex("(expt (sin theta) 2)"), "\\sin\\left(\\theta\\right)^{2}");
  EXPECT_EQ(tex("(sqrt (+ x y))"), "\\sqrt{x + y}");
}

TEST(Tex, Functions) {
  EXPECT_EQ(tex("(sin theta)"), "\\sin\\left(\\theta\\right)");
  EXPECT_EQ(tex("(atan y x)"), "\\arctan\\left(y, x\\right)");
  EXPECT_EQ(tex("(f t)"), "f\\left(t\\right)");
  EXPECT_EQ(tex("(y_s t)"), "y_{s}\\left(t\\right)");
  EXPECT_EQ(tex("(abs x)"), "\\left|x\\right|");
}

TEST(Tex, Derivatives) {
  EXPECT_EQ(tex("((D x) t)"), "Dx\\left(t\\right)");
  EXPECT_EQ(tex("(((expt D 2) x) t)"), "D^{2}x\\left(t\\right)");
  EXPECT_EQ(tex("((D theta) t)"), "D\\theta\\left(t\\right)");
  EXPECT_EQ(tex("(((partial 1) H) s)"), "\\partial_{1}H\\left(s\\right)");
  EXPECT_EQ(tex("(((partial 1 0) H) s)"), "\\partial_{1,0}H\\left(s\\right)");
  EXPECT_EQ(tex("((D (+ f g)) t)"), "D\\left(f + g\\right)\\left(t\\right)");
}

TEST(Tex, Structures) {
  EXPECT_EQ(tex("(up a b)"), "\\begin{pmatrix} a \\\\ b \\end{pmatrix}");
  EXPECT_EQ(tex("(down a b)"), "\\begin{bmatrix} a & b \\end{bmatrix}");
  EXPECT_EQ(tex("(up (down a b) c)"),
            "\\begin{pmatrix} \\begin{bmatrix} a & b \\end{bmatrix} \\\\ c \\end{pmatrix}");
  EXPECT_EQ(tex("(matrix-by-rows (list a b) (list c d))"),
            "\\begin{bmatrix} a & b \\\\ c & d \\end{bmatrix}");
}

TEST(Tex, PlainLists) {
  EXPECT_EQ(tex("(1/2 x)"), "\\left(\\frac{1}{2}, x\\right)");
}

TEST(Tex, Relations) {
  EXPECT_EQ(tex("(<= a b)"), "a \\le b");
}

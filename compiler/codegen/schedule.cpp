// The scheduler: CSE by use counts, powers as products, sincos pairs, linear solves (see
// schedule.hpp).
//
// The outputs form a DAG in the expression arena, already shared by
// hash-consing. The scheduler walks the nodes reachable from the outputs
// in increasing id order, which is topological (children have smaller
// ids), and gives a temporary to every operation node that is used more
// than once, and to a few more that must be simple operands:
//   - the base of an integer power, computed as repeated products (x*x*x);
//   - the argument of a sin and cos pair, computed by one sincos() call.
// Everything else is a term inline in the tree of its only user, built
// exactly as the node is: floating-point arithmetic is not associative, so
// the tree must be the one to evaluate. Sums with negated terms subtract
// (a + (-b) and a - b are the same IEEE operation). Powers with exponent
// of magnitude 4 to kMaxSquaringPower are computed by repeated squaring
// into temporaries, larger ones by pow; negative integer powers are 1.0
// divided by the positive power.
//
// Numbers are the double they round to (exact rationals correctly
// rounded). The steps come in the order the C emitter prints them, and
// temporaries are numbered in the order they are made, so the C text of a
// schedule is what the emitter printed before the schedule existed.
#include "codegen/schedule.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "algebra/linear_solve.hpp"
#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "codegen/emit_c.hpp"

namespace sicm {

namespace {

// Integer powers up to this are multiplications (six squarings at most);
// above it, pow (see libm_power).
constexpr uint64_t kMaxSquaringPower = 64;

double number_value(ExprId id) {
  const ExprNode &n = expr_node(id);
  return n.kind == ExprKind::Flonum ? n.d : to_double(expr_number_value(id));
}

// (expt b n) with n an exact integer that fits in int64.
bool integer_power(ExprId id, int64_t *n) {
  return expr_is_apply(id, Op::Expt) && expr_get_int64(expr_arg(id, 1), n);
}

// (expt u 0), which inline_form writes as 1.0 without its argument.
bool is_zeroth_power(ExprId id) {
  return expr_is_apply(id, Op::Expt) && expr_is_exact_zero(expr_arg(id, 1));
}

// The nodes a node computes from: an operation's arguments, a solve node's
// matrix and right-hand side (its component index is not a value); none for
// numbers, symbols and other calls.
std::vector<ExprId> operands(ExprId id) {
  if (expr_kind(id) == ExprKind::Apply) return expr_arg_vector(id);
  if (!is_solve_node(id)) return {};
  std::vector<ExprId> v = expr_arg_vector(id);
  v.erase(v.begin());
  return v;
}

bool has_operands(ExprId id) {
  return expr_kind(id) == ExprKind::Apply || is_solve_node(id);
}

class Scheduler {
public:
  Scheduler(std::vector<ExprId> outputs, bool checked)
      : outputs_(std::move(outputs)), checked_(checked) {
    find_exact_zeros();
    collect();
    plan();
  }

  // The steps that compute output j.
  Schedule schedule() {
    for (ExprId id : nodes_)
      if (wants_name_.count(id) && !name_.count(id)) emit_named(id);
    for (size_t j = 0; j < outputs_.size(); ++j) {
      Step s{StepKind::Output};
      s.output = static_cast<uint32_t>(j);
      s.term = ref(outputs_[j]);
      out_.steps.push_back(std::move(s));
    }
    if (!singular_flags_.empty()) {
      Step s{StepKind::SingularCheck};
      s.flags = singular_flags_;
      out_.steps.push_back(std::move(s));
    }
    out_.noutputs = outputs_.size();
    return std::move(out_);
  }

private:
  struct Factors {
    uint32_t array = 0; // the Factor step's temp
    bool symmetric = false;
  };

  // The nodes whose value generic arithmetic gives as the exact 0 whatever
  // the inputs: an exact 0 times anything (even an infinite flonum, as in
  // MIT Scheme), and the exact 0 through the functions that keep it
  // exact ((sin 0), (atan 0 0), (expt 0 3) and (/ 0 x) are the exact 0).
  // C would compute some of them as -0. ((* -1 (* 0 x)) is -(0.0)), which
  // atan2 and 1/x tell from 0 (fuzz emit-5 and emit-11). The arena gives
  // an argument a smaller id than its user, so one pass in id order sees
  // every argument first.
  void find_exact_zeros() {
    std::vector<ExprId> all;
    std::unordered_set<ExprId> seen;
    std::vector<ExprId> stack(outputs_.begin(), outputs_.end());
    while (!stack.empty()) {
      ExprId id = stack.back();
      stack.pop_back();
      if (!seen.insert(id).second || !has_operands(id)) continue;
      if (expr_kind(id) == ExprKind::Apply) all.push_back(id);
      std::vector<ExprId> args = operands(id);
      stack.insert(stack.end(), args.begin(), args.end());
    }
    std::sort(all.begin(), all.end());
    auto zero = [&](ExprId a) { return expr_is_exact_zero(a) || zeros_.count(a) > 0; };
    ConstantValues constants; // see constant_value
    for (ExprId id : all) {
      std::vector<ExprId> args = expr_arg_vector(id);
      if (std::optional<Value> v = constant_value(id, args, constants)) {
        constants.emplace(id, *v);
        if (is_exact(*v) && num_is_zero(*v)) zeros_.insert(id);
        continue;
      }
      bool any = std::any_of(args.begin(), args.end(), zero);
      bool every = std::all_of(args.begin(), args.end(), zero);
      int64_t n;
      bool is_zero = false;
      switch (expr_node(id).op) {
      case Op::Mul: is_zero = any; break;
      case Op::Add:
      case Op::Sin:
      case Op::Tan:
      case Op::Asin:
      case Op::Atan:
      case Op::Sqrt:
      case Op::Abs: is_zero = every; break;
      case Op::Div: is_zero = args.size() == 2 && zero(args[0]); break;
      case Op::Expt: is_zero = zero(args[0]) && integer_power(id, &n) && n > 0; break;
      default: break;
      }
      if (is_zero) zeros_.insert(id);
    }
  }

  // Values of constant nodes; gc_allocator keeps their boxes alive.
  using ConstantValues = std::unordered_map<ExprId, Value, std::hash<ExprId>, std::equal_to<ExprId>,
                                            gc_allocator<std::pair<const ExprId, Value>>>;

  // The value generic arithmetic gives a node of constants only, which
  // nobody folded ((atan 0 (expt 3 -6)) is the exact 0, and so its product
  // with a NaN: emit run H), given its arguments' values in constants;
  // nullopt if an argument is not constant, if generic arithmetic raises
  // or leaves an expression, or if an exact argument or result is larger
  // than kMaxConstantBits (such a node is left to C, as before).
  static std::optional<Value> constant_value(ExprId id, const std::vector<ExprId> &args,
                                             const ConstantValues &constants) {
    constexpr size_t kMaxConstantBits = 256;
    auto small = [](Value v) {
      if (!is_exact(v)) return true;
      mpq_t q;
      mpq_init(q);
      to_mpq(v, q);
      bool fits =
          mpz_sizeinbase(mpq_numref(q), 2) + mpz_sizeinbase(mpq_denref(q), 2) <= kMaxConstantBits;
      mpq_clear(q);
      return fits;
    };
    // Most nodes have an input among their arguments: they are turned away
    // before anything is allocated.
    auto is_constant = [&](ExprId a) {
      ExprKind kind = expr_kind(a);
      return kind == ExprKind::Rational || kind == ExprKind::Flonum || constants.count(a) > 0;
    };
    if (!std::all_of(args.begin(), args.end(), is_constant)) return std::nullopt;
    gcvec<Value> values;
    for (ExprId a : args) {
      auto it = constants.find(a);
      values.push_back(it != constants.end() ? it->second : expr_number_value(a));
      if (!small(values.back())) return std::nullopt;
    }
    Op op = expr_node(id).op;
    // An exact power's size is its base's times the exponent: bound it
    // before computing it.
    if (op == Op::Expt && is_exact(values[0]) && is_exact_integer(values[1])) {
      std::optional<int64_t> n = to_int64(values[1]);
      if (!n || *n > static_cast<int64_t>(kMaxConstantBits) ||
          *n < -static_cast<int64_t>(kMaxConstantBits))
        return std::nullopt;
    }
    try {
      Value v = symbolic_apply(op, values.data(), static_cast<int>(values.size()));
      if (!is_number(v) || !small(v)) return std::nullopt;
      return v;
    } catch (const Error &) {
      return std::nullopt;
    }
  }

  // A node written as a constant without its arguments (1.0 or 0.0):
  // its arguments are not collected, so that none gets a name it would
  // never use (fuzz emit-2: a chain of powers under an (expt ... 0) left
  // `double t33` unread, which -Wall -Werror rejects).
  bool is_constant_form(ExprId id) const { return is_zeroth_power(id) || zeros_.count(id) > 0; }

  // A number < 0, or a product whose leading coefficient is: such a term
  // is written subtracted.
  bool negative_term(ExprId id) const {
    if (expr_is_number(id)) return number_value(id) < 0;
    if (!expr_is_apply(id, Op::Mul) || is_constant_form(id)) return false;
    ExprId c = expr_arg(id, 0);
    return expr_is_number(c) && number_value(c) < 0;
  }

  // The nodes reachable from the outputs, in increasing id order, and how
  // many times each is used (as an argument of a reachable node or as an
  // output).
  void collect() {
    std::unordered_set<ExprId> seen;
    std::vector<ExprId> stack(outputs_.begin(), outputs_.end());
    while (!stack.empty()) {
      ExprId id = stack.back();
      stack.pop_back();
      if (!seen.insert(id).second) continue;
      nodes_.push_back(id);
      if (!has_operands(id) || is_constant_form(id)) continue;
      std::vector<ExprId> args = operands(id);
      stack.insert(stack.end(), args.begin(), args.end());
    }
    std::sort(nodes_.begin(), nodes_.end());
    for (ExprId id : nodes_) {
      if (!has_operands(id) || is_constant_form(id)) continue;
      for (ExprId a : operands(id))
        ++uses_[a];
    }
    for (ExprId id : outputs_)
      ++uses_[id];
  }

  // (* -1 x) of an input x: written in place (a - x in a sum) it costs no
  // more than a name would, so it gets none even when shared (the pair
  // differences q_i - q_j of an N-body kernel share each -q_j).
  static bool is_input_negation(ExprId id) {
    return expr_is_apply(id, Op::Mul) && expr_node(id).nargs == 2 &&
           expr_is_number(expr_arg(id, 0)) && number_value(expr_arg(id, 0)) == -1.0 &&
           expr_kind(expr_arg(id, 1)) == ExprKind::Symbol;
  }

  // (sqrt u)^n for an odd |n| >= 3 is written u^((|n| - 1)/2) sqrt(u) (see
  // power): one multiplication fewer than the cube of the root, and one
  // rounding fewer (the 1/r^3 of a gravitational force is 1/(r2 sqrt(r2))).
  static bool odd_power_of_root(ExprId id) {
    int64_t n;
    return integer_power(id, &n) && n % 2 != 0 && (n >= 3 || n <= -3) &&
           expr_is_apply(expr_arg(id, 0), Op::Sqrt);
  }

  void want_operand(ExprId id) {
    if (expr_kind(id) == ExprKind::Apply) wants_name_.insert(id);
  }

  // Decide which nodes get names: shared ones, power bases, sincos pairs.
  void plan() {
    std::unordered_map<ExprId, ExprId> sin_of, cos_of; // argument -> node
    for (ExprId id : nodes_) {
      if (is_solve_node(id)) wants_name_.insert(id);
      if (expr_kind(id) != ExprKind::Apply || is_constant_form(id)) continue;
      if (uses_[id] >= 2 && !is_input_negation(id)) wants_name_.insert(id);
      int64_t n;
      if (integer_power(id, &n) && (n >= 2 || n <= -2)) {
        want_operand(expr_arg(id, 0));
        if (odd_power_of_root(id)) want_operand(expr_arg(expr_arg(id, 0), 0));
      }
      if (expr_is_apply(id, Op::Sin)) sin_of[expr_arg(id, 0)] = id;
      if (expr_is_apply(id, Op::Cos)) cos_of[expr_arg(id, 0)] = id;
    }
    for (auto [arg, s] : sin_of) {
      auto c = cos_of.find(arg);
      if (c == cos_of.end()) continue;
      partner_[s] = c->second;
      partner_[c->second] = s;
      wants_name_.insert(s);
      wants_name_.insert(c->second);
      want_operand(arg);
    }
  }

  uint32_t add(Term t) {
    out_.terms.push_back(std::move(t));
    return static_cast<uint32_t>(out_.terms.size() - 1);
  }
  const Term &term(uint32_t t) const { return out_.terms[t]; }

  uint32_t literal(double d, std::string text = "") {
    Term t{TermKind::Literal};
    t.value = d;
    t.text = text.empty() ? c_double_literal(d) : std::move(text);
    t.prec = t.text[0] == '-' ? kUnary : kAtom;
    return add(std::move(t));
  }
  uint32_t one() { return literal(1.0); }
  uint32_t temp_term(uint32_t n) {
    Term t{TermKind::Temp};
    t.temp = n;
    return add(std::move(t));
  }
  uint32_t unary(TermKind kind, uint32_t a) {
    Term t{kind};
    t.prec = kind == TermKind::Neg ? kUnary : kAtom;
    t.args = {a};
    return add(std::move(t));
  }
  uint32_t binary(TermKind kind, uint32_t a, uint32_t b) {
    Term t{kind};
    t.prec = kind == TermKind::Add || kind == TermKind::Sub ? kAdd : kMul;
    t.args = {a, b};
    return add(std::move(t));
  }
  uint32_t call_term(TermKind kind, std::string fn, std::vector<uint32_t> args) {
    Term t{kind};
    t.text = std::move(fn);
    t.args = std::move(args);
    if (kind == TermKind::CheckedCall || kind == TermKind::CheckedQuotient) t.source = inlining_;
    return add(std::move(t));
  }

  uint32_t temp() { return out_.ntemps++; }

  // Give id a name, adding the step that computes it. Every node it uses
  // that has a name already has one (smaller ids were handled first).
  void emit_named(ExprId id) {
    if (is_solve_node(id)) {
      uint32_t x = is_interpreted_solve(id) ? interpreted_solution(id) : solution(id);
      Term t{TermKind::Element};
      t.temp = x;
      t.element = static_cast<uint32_t>(solve_component(id));
      name_[id] = add(std::move(t));
      return;
    }
    auto p = partner_.find(id);
    if (p != partner_.end()) {
      ExprId s = expr_is_apply(id, Op::Sin) ? id : p->second;
      ExprId c = p->second == s ? id : p->second;
      Step step{StepKind::SinCos};
      step.temp = temp();
      step.temp2 = temp();
      step.term = operand(expr_arg(s, 0));
      name_[s] = temp_term(step.temp);
      name_[c] = temp_term(step.temp2);
      out_.steps.push_back(std::move(step));
      return;
    }
    uint32_t c = inline_form(id); // may add temporaries of its own first
    if (term(c).kind == TermKind::Temp) {
      name_[id] = c; // a power by repeated squaring can end in a temporary
      return;
    }
    Step step{StepKind::Define};
    step.temp = temp();
    step.term = c;
    uint32_t t = temp_term(step.temp);
    out_.steps.push_back(std::move(step));
    name_[id] = t;
    int64_t n;
    if (integer_power(id, &n) && n >= 2) powers_[{expr_arg(id, 0), static_cast<uint64_t>(n)}] = t;
  }

  // The Factor step of the solve node's matrix, added on first use: LDL^T
  // when it is symmetric node for node (a mass matrix), else LU with
  // partial pivoting. Each factorization's flag says whether the matrix was
  // singular (see the SingularCheck step).
  const Factors &factors(ExprId solve) {
    size_t n = solve_dimension(solve);
    std::vector<ExprId> key;
    bool symmetric = true;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) {
        key.push_back(solve_matrix_entry(solve, i, j));
        symmetric = symmetric && key.back() == solve_matrix_entry(solve, j, i);
      }
    auto hit = factors_.find(key);
    if (hit != factors_.end()) return hit->second;
    Factors f;
    f.symmetric = symmetric;
    f.array = temp();
    Step step{StepKind::Factor};
    step.temp = f.array;
    step.n = static_cast<uint32_t>(n);
    step.symmetric = symmetric;
    for (size_t k = 0; k < key.size(); ++k)
      step.terms.push_back(ref(key[k]));
    out_.steps.push_back(std::move(step));
    singular_flags_.push_back(f.array);
    return factors_.emplace(std::move(key), f).first->second;
  }

  // The array that holds the solution of the solve node's system, solved on
  // first use.
  uint32_t solution(ExprId solve) {
    size_t n = solve_dimension(solve);
    std::vector<ExprId> key;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        key.push_back(solve_matrix_entry(solve, i, j));
    for (size_t i = 0; i < n; ++i)
      key.push_back(solve_rhs_entry(solve, i));
    auto hit = solutions_.find(key);
    if (hit != solutions_.end()) return hit->second;
    Factors f = factors(solve);
    Step step{StepKind::Solve};
    step.temp = temp();
    step.temp2 = f.array;
    step.n = static_cast<uint32_t>(n);
    step.symmetric = f.symmetric;
    for (size_t i = 0; i < n; ++i)
      step.terms.push_back(ref(solve_rhs_entry(solve, i)));
    uint32_t x = step.temp;
    out_.steps.push_back(std::move(step));
    solutions_.emplace(std::move(key), x);
    return x;
  }

  // The array that holds the solution of an interpreted solve node's system
  // (linear_solve.hpp), computed on first use by the runtime as the
  // interpreter computes it.
  uint32_t interpreted_solution(ExprId solve) {
    size_t n = solve_dimension(solve);
    std::vector<ExprId> key{solve_head()};
    std::vector<uint32_t> terms;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) {
        key.push_back(solve_matrix_entry(solve, i, j));
        terms.push_back(ref(key.back()));
      }
    for (size_t i = 0; i < n; ++i) {
      key.push_back(solve_rhs_entry(solve, i));
      terms.push_back(ref(key.back()));
    }
    auto hit = solutions_.find(key);
    if (hit != solutions_.end()) return hit->second;
    Step step{StepKind::SolveInterpreted};
    step.temp = temp();
    step.n = static_cast<uint32_t>(n);
    step.terms = std::move(terms);
    uint32_t x = step.temp;
    out_.steps.push_back(std::move(step));
    solutions_.emplace(std::move(key), x);
    return x;
  }

  // The node as a term of its user.
  uint32_t ref(ExprId id) {
    auto n = name_.find(id);
    if (n != name_.end()) return n->second;
    const ExprNode &node = expr_node(id);
    switch (node.kind) {
    case ExprKind::Rational:
    case ExprKind::Flonum: return literal(number_value(id));
    case ExprKind::Symbol: {
      Term t{TermKind::Symbol};
      t.symbol = node.sym;
      return add(std::move(t));
    }
    case ExprKind::Apply: return inline_form(id);
    case ExprKind::Call: break; // solve nodes are named; trace_procedure refuses other Calls
    }
    internal_failure(__FILE__, __LINE__, "a Call node reached the C emitter");
  }

  // A node that must be a simple operand (a name, an input or a literal).
  uint32_t operand(ExprId id) {
    uint32_t t = ref(id);
    return term(t).prec > kAtom ? unary(TermKind::Paren, t) : t;
  }

  // a0 * a1 * ...: the grouping of a left fold.
  uint32_t product(const std::vector<uint32_t> &factors) {
    uint32_t p = factors[0];
    for (size_t i = 1; i < factors.size(); ++i)
      p = binary(TermKind::Mul, p, factors[i]);
    return p;
  }

  // -term for a term with negative_term(term).
  uint32_t negated(ExprId id) {
    if (expr_is_number(id)) return literal(-number_value(id));
    std::vector<ExprId> args = expr_arg_vector(id);
    double c = number_value(args[0]);
    std::vector<uint32_t> factors;
    if (c != -1.0) factors.push_back(literal(-c));
    for (size_t i = 1; i < args.size(); ++i)
      factors.push_back(ref(args[i]));
    return product(factors);
  }

  uint32_t sum(const std::vector<ExprId> &args) {
    uint32_t s = ref(args[0]);
    for (size_t i = 1; i < args.size(); ++i) {
      if (!name_.count(args[i]) && negative_term(args[i]))
        s = binary(TermKind::Sub, s, negated(args[i]));
      else
        s = binary(TermKind::Add, s, ref(args[i]));
    }
    return s;
  }

  // A product; its factors that are negative integer powers (and have no
  // name of their own) divide: a * b^-2 is a / (b * b), one division and
  // no reciprocal.
  uint32_t mul(const std::vector<ExprId> &args) {
    bool negate = expr_is_number(args[0]) && number_value(args[0]) == -1.0 && args.size() > 1;
    std::vector<uint32_t> numerator, denominator;
    for (size_t i = negate ? 1 : 0; i < args.size(); ++i) {
      int64_t n;
      if (!name_.count(args[i]) && !is_constant_form(args[i]) && integer_power(args[i], &n) &&
          n < 0 && n > INT64_MIN && args.size() > 1)
        denominator.push_back(power(expr_arg(args[i], 0), static_cast<uint64_t>(-n)));
      else
        numerator.push_back(ref(args[i]));
    }
    uint32_t c = numerator.empty() ? one() : product(numerator);
    if (!denominator.empty()) c = quotient("expt", c, product(denominator));
    if (negate) return unary(TermKind::Neg, c);
    return c;
  }

  // base^m for m >= 1: small powers as products, larger ones by repeated
  // squaring into temporaries, reusing every square of this base computed
  // so far (and named powers); the product of the squares that the binary
  // digits of m select.
  uint32_t power(ExprId base, uint64_t m) {
    if (m == 1) return ref(base);
    auto hit = powers_.find({base, m});
    if (hit != powers_.end()) return hit->second;
    if (m > kMaxSquaringPower) return libm_power(base, m);
    if (m % 2 == 1 && expr_is_apply(base, Op::Sqrt)) { // see odd_power_of_root
      ExprId radicand = expr_arg(base, 0);
      uint32_t r = m == 3 ? operand(radicand) : power(radicand, m / 2);
      return binary(TermKind::Mul, r, operand(base));
    }
    uint32_t b = operand(base);
    if (m == 2) return binary(TermKind::Mul, b, b);
    if (m == 3) {
      auto square = powers_.find({base, 2});
      if (square != powers_.end()) return binary(TermKind::Mul, square->second, b);
      return binary(TermKind::Mul, binary(TermKind::Mul, b, b), b);
    }
    std::vector<uint32_t> parts;
    uint32_t square = b;
    for (uint64_t e = 1;;) {
      if (m & 1) parts.push_back(square);
      m >>= 1;
      if (m == 0) break;
      e *= 2;
      auto s = powers_.find({base, e});
      if (s == powers_.end()) {
        Step step{StepKind::Define};
        step.temp = temp();
        step.term = binary(TermKind::Mul, square, square);
        uint32_t t = temp_term(step.temp);
        out_.steps.push_back(std::move(step));
        s = powers_.emplace(std::make_pair(base, e), t).first;
      }
      square = s->second;
    }
    return product(parts);
  }

  // base^m by pow: within an ulp, where squaring rounds once a step, and
  // what gcc -O2 folds at once for a constant base, where it ran for
  // minutes folding fifty squarings (fuzz emit-1). An m past 2^53 is
  // rounded to the nearest double, which is even: the sign of an odd
  // power is put back with copysign.
  uint32_t libm_power(ExprId base, uint64_t m) {
    char exponent[32];
    std::snprintf(exponent, sizeof exponent, "%.17g.0", static_cast<double>(m));
    if (std::strchr(exponent, 'e')) // past 1e17 %.17g switches to an exponent
      std::snprintf(exponent, sizeof exponent, "%.17g", static_cast<double>(m));
    uint32_t b = ref(base);
    uint32_t p = call_term(TermKind::Call, "pow", {b, literal(static_cast<double>(m), exponent)});
    if ((m & 1) && m > (uint64_t(1) << 53)) p = call_term(TermKind::Call, "copysign", {p, b});
    return p;
  }

  uint32_t call(const char *fn, const std::vector<ExprId> &args) {
    std::vector<uint32_t> terms;
    for (ExprId a : args)
      terms.push_back(ref(a));
    return call_term(TermKind::Call, fn, std::move(terms));
  }

  // The runtime's checked form of fn ("sqrt" -> sicm_checked_sqrt(site, x)).
  uint32_t checked_call(const char *fn, const std::vector<ExprId> &args) {
    std::vector<uint32_t> terms;
    for (ExprId a : args)
      terms.push_back(ref(a));
    return call_term(TermKind::CheckedCall, fn, std::move(terms));
  }

  // a / b, checked when the schedule is (unless b is a nonzero literal: the
  // 2pi of a map's angles costs nothing).
  uint32_t quotient(const char *who, uint32_t a, uint32_t b) {
    const Term &d = term(b);
    if (!checked_ || (d.kind == TermKind::Literal && d.value != 0))
      return binary(TermKind::Div, a, b);
    return call_term(TermKind::CheckedQuotient, who, {a, b});
  }

  // An operation node written out in full (its arguments by ref).
  uint32_t inline_form(ExprId id) {
    // The node being written out, for the checked terms it makes.
    struct Inlining {
      ExprId &current, outer;
      Inlining(ExprId &c, ExprId id) : current(c), outer(c) { current = id; }
      ~Inlining() { current = outer; }
    } inlining(inlining_, id);
    if (zeros_.count(id)) return literal(0.0); // see find_exact_zeros
    Op op = expr_node(id).op;
    std::vector<ExprId> args = expr_arg_vector(id);
    switch (op) {
    case Op::Add: return sum(args);
    case Op::Mul: return mul(args);
    case Op::Sub: {
      if (args.size() == 1) return unary(TermKind::Neg, ref(args[0]));
      uint32_t s = ref(args[0]);
      for (size_t i = 1; i < args.size(); ++i)
        s = binary(TermKind::Sub, s, ref(args[i]));
      return s;
    }
    case Op::Div: {
      if (args.size() == 1) return quotient("/", one(), ref(args[0]));
      uint32_t q = ref(args[0]);
      for (size_t i = 1; i < args.size(); ++i)
        q = quotient("/", q, ref(args[i]));
      return q;
    }
    case Op::Expt: {
      int64_t n;
      if (!integer_power(id, &n)) return checked_ ? checked_call("pow", args) : call("pow", args);
      if (n == 0) return one();
      uint64_t m = n < 0 ? 0 - static_cast<uint64_t>(n) : static_cast<uint64_t>(n);
      uint32_t p = power(args[0], m);
      if (n > 0) return p;
      return quotient("expt", one(), p);
    }
    case Op::Atan: return call(args.size() == 2 ? "atan2" : "atan", args);
    case Op::Sqrt:
    case Op::Log:
    case Op::Asin:
    case Op::Acos:
      SICM_ASSERT(args.size() == 1);
      if (checked_) return checked_call(op_info(op).c_name, args);
      return call(op_info(op).c_name, args);
    case Op::Exp:
    case Op::Sin:
    case Op::Cos:
    case Op::Tan:
    case Op::Sinh:
    case Op::Cosh:
    case Op::Abs: SICM_ASSERT(args.size() == 1); return call(op_info(op).c_name, args);
    }
    internal_failure(__FILE__, __LINE__, "an operator without a C form");
  }

  std::vector<ExprId> outputs_;
  bool checked_;
  ExprId inlining_ = kNoExpr; // the node inline_form is writing out
  std::vector<ExprId> nodes_; // reachable from the outputs, increasing ids
  std::unordered_map<ExprId, uint32_t> uses_;
  std::unordered_set<ExprId> wants_name_;
  std::unordered_set<ExprId> zeros_;                       // see find_exact_zeros
  std::unordered_map<ExprId, ExprId> partner_;             // sin node <-> cos node of one argument
  std::unordered_map<ExprId, uint32_t> name_;              // node -> its Temp or Element term
  std::map<std::pair<ExprId, uint64_t>, uint32_t> powers_; // (base, m) -> a term of base^m
  std::map<std::vector<ExprId>, Factors> factors_;         // matrix entries -> factors
  std::map<std::vector<ExprId>, uint32_t> solutions_;      // matrix and rhs -> solution array
  std::vector<uint32_t> singular_flags_;
  Schedule out_;
};

} // namespace

Schedule schedule_outputs(const std::vector<ExprId> &outputs, bool checked) {
  return Scheduler(outputs, checked).schedule();
}

} // namespace sicm

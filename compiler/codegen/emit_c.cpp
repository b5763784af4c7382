// The C emitter: CSE by use counts, powers as products, sincos pairs (see emit_c.hpp).
//
// The outputs of a trace form a DAG in the expression arena, already shared
// by hash-consing. The emitter walks the nodes reachable from the outputs in
// increasing id order, which is topological (children have smaller ids), and
// gives a name (a `double tN`) to every operation node that is used
// more than once, and to a few more that must be simple operands:
//   - the base of an integer power, written as repeated products (x*x*x);
//   - the argument of a sin and cos pair, computed by one sincos() call.
// Everything else is written inline in the expression of its only user, with
// parentheses exactly where C's precedence would otherwise regroup an
// operation: floating-point arithmetic is not associative, so the C must
// evaluate the tree as built. Sums with negated terms are written with `-`
// (a + (-b) and a - b are the same IEEE operation). Powers with exponent of
// magnitude 4 to kMaxSquaringPower are computed by repeated squaring into
// temporaries, larger ones by pow; negative integer powers are 1.0 divided
// by the positive power.
//
// Temporaries are plain `double`, not `const double`: when optimizing,
// gcc's C front end substitutes a const local's initializer wherever the
// local is read, and an initializer it may not fold (1.0 / 0.0, or a
// product that overflows, under the default -ftrapping-math) then grows
// as a tree that doubles with each squaring: thirty squarings of such a
// constant kept gcc -O2 busy for minutes and gigabytes (fuzz emit-1,
// emit-14). In SSA form the two spellings compile to the same code.
//
// Numbers are emitted as the double they round to (exact rationals correctly
// rounded), in the shortest form that reads back exactly. No user text
// reaches the C: inputs are in[i], temporaries tN, and names are sanitized
// (and, by c_kernel_name, kept distinct). No string literal is ever emitted.
#include "codegen/emit_c.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "algebra/linear_solve.hpp"
#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "codegen/jit.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// Integer powers up to this are multiplications (six squarings at most);
// above it, pow (see libm_power).
constexpr uint64_t kMaxSquaringPower = 64;

// C precedence levels of the forms the emitter writes, tightest first.
enum Prec : int { kAtom = 0, kUnary = 1, kMul = 2, kAdd = 3 };

struct Code {
  std::string text;
  int prec;
};

// c's text, parenthesized if its precedence is looser than max_prec allows.
std::string wrap(const Code &c, int max_prec) {
  return c.prec > max_prec ? "(" + c.text + ")" : c.text;
}

double number_value(ExprId id) {
  const ExprNode &n = expr_node(id);
  return n.kind == ExprKind::Flonum ? n.d : to_double(expr_number_value(id));
}

Code literal(double d) {
  std::string s = c_double_literal(d);
  return {s, s[0] == '-' ? kUnary : kAtom};
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

class Emitter {
public:
  // spell gives the C text of a symbol (an atom); temporaries are named
  // temp_prefix followed by a number. With a checked_site (a C expression
  // of type const sicm_site *), division, sqrt, log, asin, acos and pow
  // call the runtime's checked forms, which fail there as the interpreter
  // would instead of giving an infinity or a NaN.
  Emitter(std::vector<ExprId> outputs, std::function<std::string(Symbol *)> spell,
          std::string temp_prefix = "t", std::string checked_site = "")
      : outputs_(std::move(outputs)), spell_(std::move(spell)),
        temp_prefix_(std::move(temp_prefix)), checked_site_(std::move(checked_site)) {
    find_exact_zeros();
    collect();
    plan();
  }

  // Statements that compute output j into targets[j].
  std::string assignments(const std::vector<std::string> &targets, const std::string &indent) {
    for (ExprId id : nodes_)
      if (wants_name_.count(id) && !name_.count(id)) emit_named(id);
    for (size_t j = 0; j < outputs_.size(); ++j) {
      Code c = ref(outputs_[j]);
      body_ += "  " + targets[j] + " = " + c.text + ";\n";
    }
    if (!singular_flags_.empty()) {
      // A singular matrix: every output is the NaN that says so (sicm/error.h).
      std::string any;
      for (const std::string &f : singular_flags_)
        any += (any.empty() ? "" : " | ") + f;
      body_ += "  if (" + any + ") {\n";
      for (const std::string &t : targets)
        body_ += "    " + t + " = sicm_singular_nan();\n";
      body_ += "  }\n";
    }
    std::string out;
    size_t start = 0;
    while (start < body_.size()) {
      size_t end = body_.find('\n', start);
      out += indent + body_.substr(start, end - start) + "\n";
      start = end + 1;
    }
    return out;
  }

private:
  struct Factors {
    std::string array, pivots; // pivots: LU only
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
      if (integer_power(id, &n) && (n >= 2 || n <= -2)) want_operand(expr_arg(id, 0));
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

  std::string temp() { return temp_prefix_ + std::to_string(ntemps_++); }
  bool is_temporary(const std::string &s) const {
    return s.size() > temp_prefix_.size() && s.compare(0, temp_prefix_.size(), temp_prefix_) == 0 &&
           s.find_first_not_of("0123456789", temp_prefix_.size()) == std::string::npos;
  }

  // Give id a name, emitting the statement that computes it. Every node it
  // uses that has a name already has one (smaller ids were handled first).
  void emit_named(ExprId id) {
    if (is_solve_node(id)) {
      std::string x = is_interpreted_solve(id) ? interpreted_solution(id) : solution(id);
      name_[id] = x + "[" + std::to_string(solve_component(id)) + "]";
      return;
    }
    auto p = partner_.find(id);
    if (p != partner_.end()) {
      ExprId s = expr_is_apply(id, Op::Sin) ? id : p->second;
      ExprId c = p->second == s ? id : p->second;
      std::string ts = temp(), tc = temp();
      body_ += "  double " + ts + ", " + tc + ";\n";
      body_ += "  sincos(" + operand(expr_arg(s, 0)) + ", &" + ts + ", &" + tc + ");\n";
      name_[s] = ts;
      name_[c] = tc;
      return;
    }
    Code c = inline_form(id); // may emit temporaries of its own first
    if (is_temporary(c.text)) {
      name_[id] = c.text; // a power by repeated squaring can end in a temporary
      return;
    }
    std::string t = temp();
    body_ += "  double " + t + " = " + c.text + ";\n";
    name_[id] = t;
    int64_t n;
    if (integer_power(id, &n) && n >= 2) powers_[{expr_arg(id, 0), static_cast<uint64_t>(n)}] = t;
  }

  // The array that holds the factors of the solve node's matrix, factoring
  // it on first use: LDL^T when it is symmetric node for node (a mass
  // matrix), else LU with partial pivoting. Each factorization's flag says
  // whether the matrix was singular (see assignments).
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
    std::string entries;
    for (size_t k = 0; k < key.size(); ++k)
      entries += (k ? ", " : "") + ref(key[k]).text;
    std::string dim = std::to_string(n);
    body_ += "  double " + f.array + "[" + std::to_string(n * n) + "] = {" + entries + "};\n";
    std::string flag = f.array + "_singular";
    if (symmetric) {
      body_ += "  int " + flag + " = sicm_ldlt_factor(" + dim + ", " + f.array + ");\n";
    } else {
      f.pivots = f.array + "_pivots";
      body_ += "  int " + f.pivots + "[" + dim + "];\n";
      body_ +=
          "  int " + flag + " = sicm_lu_factor(" + dim + ", " + f.array + ", " + f.pivots + ");\n";
    }
    singular_flags_.push_back(flag);
    return factors_.emplace(std::move(key), std::move(f)).first->second;
  }

  // The array that holds the solution of the solve node's system, solved on
  // first use.
  std::string solution(ExprId solve) {
    size_t n = solve_dimension(solve);
    std::vector<ExprId> key;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        key.push_back(solve_matrix_entry(solve, i, j));
    for (size_t i = 0; i < n; ++i)
      key.push_back(solve_rhs_entry(solve, i));
    auto hit = solutions_.find(key);
    if (hit != solutions_.end()) return hit->second;
    const Factors &f = factors(solve);
    std::string x = temp(), rhs;
    for (size_t i = 0; i < n; ++i)
      rhs += (i ? ", " : "") + ref(solve_rhs_entry(solve, i)).text;
    std::string dim = std::to_string(n);
    body_ += "  double " + x + "[" + dim + "] = {" + rhs + "};\n";
    if (f.symmetric)
      body_ += "  sicm_ldlt_solve(" + dim + ", " + f.array + ", " + x + ");\n";
    else
      body_ += "  sicm_lu_solve(" + dim + ", " + f.array + ", " + f.pivots + ", " + x + ");\n";
    solutions_.emplace(std::move(key), x);
    return x;
  }

  // The array that holds the solution of an interpreted solve node's system
  // (linear_solve.hpp), computed on first use by the runtime as the
  // interpreter computes it.
  std::string interpreted_solution(ExprId solve) {
    size_t n = solve_dimension(solve);
    std::vector<ExprId> key{solve_head()};
    std::string matrix, rhs;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) {
        key.push_back(solve_matrix_entry(solve, i, j));
        matrix += (matrix.empty() ? "" : ", ") + ref(key.back()).text;
      }
    for (size_t i = 0; i < n; ++i) {
      key.push_back(solve_rhs_entry(solve, i));
      rhs += (i ? ", " : "") + ref(key.back()).text;
    }
    auto hit = solutions_.find(key);
    if (hit != solutions_.end()) return hit->second;
    std::string x = temp(), dim = std::to_string(n);
    body_ += "  double " + x + "[" + dim + "];\n";
    body_ += "  sicm_linalg_solve_as_interpreted(" + dim + ", (const double[]){" + matrix +
             "}, (const double[]){" + rhs + "}, " + x + ");\n";
    solutions_.emplace(std::move(key), x);
    return x;
  }

  // The node as it appears in an expression of its user.
  Code ref(ExprId id) {
    auto n = name_.find(id);
    if (n != name_.end()) return {n->second, kAtom};
    const ExprNode &node = expr_node(id);
    switch (node.kind) {
    case ExprKind::Rational:
    case ExprKind::Flonum: return literal(number_value(id));
    case ExprKind::Symbol: return {spell_(node.sym), kAtom};
    case ExprKind::Apply: return inline_form(id);
    case ExprKind::Call: break; // solve nodes are named; trace_procedure refuses other Calls
    }
    internal_failure(__FILE__, __LINE__, "a Call node reached the C emitter");
  }

  // A node that must be a simple operand (a name, an input or a literal).
  std::string operand(ExprId id) { return wrap(ref(id), kAtom); }

  // a0 * a1 * ...: the grouping of a left fold.
  Code product(const std::vector<Code> &factors) {
    if (factors.size() == 1) return factors[0];
    std::string s = wrap(factors[0], kMul);
    for (size_t i = 1; i < factors.size(); ++i)
      s += " * " + wrap(factors[i], kUnary);
    return {s, kMul};
  }

  // -term for a term with negative_term(term).
  Code negated(ExprId id) {
    if (expr_is_number(id)) return literal(-number_value(id));
    std::vector<ExprId> args = expr_arg_vector(id);
    double c = number_value(args[0]);
    std::vector<Code> factors;
    if (c != -1.0) factors.push_back(literal(-c));
    for (size_t i = 1; i < args.size(); ++i)
      factors.push_back(ref(args[i]));
    return product(factors);
  }

  Code sum(const std::vector<ExprId> &args) {
    std::string s = wrap(ref(args[0]), kAdd);
    for (size_t i = 1; i < args.size(); ++i) {
      if (!name_.count(args[i]) && negative_term(args[i]))
        s += " - " + wrap(negated(args[i]), kMul);
      else
        s += " + " + wrap(ref(args[i]), kMul);
    }
    return {s, kAdd};
  }

  // A product; its factors that are negative integer powers (and have no
  // name of their own) divide: a * b^-2 is a / (b * b), one division and
  // no reciprocal.
  Code mul(const std::vector<ExprId> &args) {
    bool negate = expr_is_number(args[0]) && number_value(args[0]) == -1.0 && args.size() > 1;
    std::vector<Code> numerator, denominator;
    for (size_t i = negate ? 1 : 0; i < args.size(); ++i) {
      int64_t n;
      if (!name_.count(args[i]) && !is_constant_form(args[i]) && integer_power(args[i], &n) &&
          n < 0 && n > INT64_MIN && args.size() > 1)
        denominator.push_back(power(expr_arg(args[i], 0), static_cast<uint64_t>(-n)));
      else
        numerator.push_back(ref(args[i]));
    }
    Code c = numerator.empty() ? Code{"1.0", kAtom} : product(numerator);
    if (!denominator.empty()) c = quotient("expt", c, product(denominator));
    if (negate) return {"-" + wrap(c, kAtom), kUnary};
    return c;
  }

  // base^m for m >= 1: small powers as products, larger ones by repeated
  // squaring into temporaries, reusing every square of this base computed
  // so far (and named powers); the product of the squares that the binary
  // digits of m select.
  Code power(ExprId base, uint64_t m) {
    if (m == 1) return ref(base);
    auto hit = powers_.find({base, m});
    if (hit != powers_.end()) return {hit->second, kAtom};
    if (m > kMaxSquaringPower) return libm_power(base, m);
    std::string b = operand(base);
    if (m == 2) return {b + " * " + b, kMul};
    if (m == 3) {
      auto square = powers_.find({base, 2});
      if (square != powers_.end()) return {square->second + " * " + b, kMul};
      return {b + " * " + b + " * " + b, kMul};
    }
    std::vector<Code> parts;
    std::string square = b;
    for (uint64_t e = 1;;) {
      if (m & 1) parts.push_back({square, kAtom});
      m >>= 1;
      if (m == 0) break;
      e *= 2;
      auto s = powers_.find({base, e});
      if (s == powers_.end()) {
        std::string t = temp();
        body_ += "  double " + t + " = " + square + " * " + square + ";\n";
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
  Code libm_power(ExprId base, uint64_t m) {
    char exponent[32];
    std::snprintf(exponent, sizeof exponent, "%.17g.0", static_cast<double>(m));
    if (std::strchr(exponent, 'e')) // past 1e17 %.17g switches to an exponent
      std::snprintf(exponent, sizeof exponent, "%.17g", static_cast<double>(m));
    std::string b = ref(base).text;
    std::string p = "pow(" + b + ", " + exponent + ")";
    if ((m & 1) && m > (uint64_t(1) << 53)) p = "copysign(" + p + ", " + b + ")";
    return {p, kAtom};
  }

  Code call(const char *fn, const std::vector<ExprId> &args) {
    std::string s = std::string(fn) + "(";
    for (size_t i = 0; i < args.size(); ++i)
      s += (i ? ", " : "") + ref(args[i]).text;
    return {s + ")", kAtom};
  }

  // The runtime's checked form of fn ("sqrt" -> sicm_checked_sqrt(site, x)).
  Code checked_call(const char *fn, const std::vector<ExprId> &args) {
    std::string s = std::string("sicm_checked_") + fn + "(" + checked_site_;
    for (ExprId a : args)
      s += ", " + ref(a).text;
    return {s + ")", kAtom};
  }

  // Is c a number literal other than zero ("6.283185307179586", "-2.0")?
  static bool nonzero_literal(const Code &c) {
    const char *text = c.text.c_str();
    char *end = nullptr;
    double value = std::strtod(text, &end);
    return end != text && *end == '\0' && value != 0;
  }

  // a / b, checked when the emitter is (unless b is a nonzero literal: the
  // 2pi of a map's angles costs nothing).
  Code quotient(const std::string &who, const Code &a, const Code &b) {
    if (checked_site_.empty() || nonzero_literal(b))
      return {wrap(a, kMul) + " / " + wrap(b, kUnary), kMul};
    return {"sicm_checked_quotient(" + checked_site_ + ", \"" + who + "\", " + a.text + ", " +
                b.text + ")",
            kAtom};
  }

  // An operation node written out in full (its arguments by ref).
  Code inline_form(ExprId id) {
    if (zeros_.count(id)) return literal(0.0); // see find_exact_zeros
    Op op = expr_node(id).op;
    std::vector<ExprId> args = expr_arg_vector(id);
    switch (op) {
    case Op::Add: return sum(args);
    case Op::Mul: return mul(args);
    case Op::Sub: {
      if (args.size() == 1) return {"-" + wrap(ref(args[0]), kAtom), kUnary};
      std::string s = wrap(ref(args[0]), kAdd);
      for (size_t i = 1; i < args.size(); ++i)
        s += " - " + wrap(ref(args[i]), kMul);
      return {s, kAdd};
    }
    case Op::Div: {
      if (args.size() == 1) return quotient("/", {"1.0", kAtom}, ref(args[0]));
      Code q = ref(args[0]);
      for (size_t i = 1; i < args.size(); ++i)
        q = quotient("/", q, ref(args[i]));
      return q;
    }
    case Op::Expt: {
      int64_t n;
      if (!integer_power(id, &n))
        return checked_site_.empty() ? call("pow", args) : checked_call("pow", args);
      if (n == 0) return {"1.0", kAtom};
      uint64_t m = n < 0 ? 0 - static_cast<uint64_t>(n) : static_cast<uint64_t>(n);
      Code p = power(args[0], m);
      if (n > 0) return p;
      return quotient("expt", {"1.0", kAtom}, p);
    }
    case Op::Atan: return call(args.size() == 2 ? "atan2" : "atan", args);
    case Op::Sqrt:
    case Op::Log:
    case Op::Asin:
    case Op::Acos:
      SICM_ASSERT(args.size() == 1);
      if (!checked_site_.empty()) return checked_call(op_info(op).c_name, args);
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
  std::function<std::string(Symbol *)> spell_;
  std::string temp_prefix_;
  std::string checked_site_;  // empty: plain C operations (kernels)
  std::vector<ExprId> nodes_; // reachable from the outputs, increasing ids
  std::unordered_map<ExprId, uint32_t> uses_;
  std::unordered_set<ExprId> wants_name_;
  std::unordered_set<ExprId> zeros_;           // see find_exact_zeros
  std::unordered_map<ExprId, ExprId> partner_; // sin node <-> cos node of one argument
  std::unordered_map<ExprId, std::string> name_;
  std::map<std::pair<ExprId, uint64_t>, std::string> powers_; // (base, m) -> a name of base^m
  std::map<std::vector<ExprId>, Factors> factors_;            // matrix entries -> factors
  std::map<std::vector<ExprId>, std::string> solutions_;      // matrix and rhs -> solution array
  std::vector<std::string> singular_flags_;
  std::string body_;
  size_t ntemps_ = 0;
};

} // namespace

std::string c_sanitize(std::string_view s, size_t max_len) {
  std::string out;
  for (char ch : s.substr(0, max_len)) {
    bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9');
    out += ok ? ch : '_';
  }
  return out.empty() ? "anonymous" : out;
}

namespace {

// c_kernel_name's bounds: a name is kept as it is up to kReadableMax bytes,
// and a hashed one keeps that much of itself, sanitized, before its hash.
constexpr size_t kReadableMax = 40;
constexpr size_t kHashDigits = 16;

bool is_identifier_tail(std::string_view s) {
  for (char ch : s)
    if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
          ch == '_'))
      return false;
  return true;
}

// Does s end as c_kernel_name's hashed form does: "_h" and kHashDigits
// lowercase hex digits?
bool looks_hashed(std::string_view s) {
  if (s.size() < kHashDigits + 2) return false;
  std::string_view tail = s.substr(s.size() - kHashDigits - 2);
  return tail.substr(0, 2) == "_h" &&
         tail.find_first_not_of("0123456789abcdef", 2) == std::string_view::npos;
}

} // namespace

// The C name of the kernel for the procedure named `name`: "sicm_kernel_"
// and the name itself if it is a short C identifier tail, else the name
// sanitized and cut, "_h" and 16 hex digits of its SHA-256. c_sanitize alone
// is not one-to-one (x-y, x_y and x?y all give x_y; long names lose their
// ends), so two kernels in one translation unit (`sicm emit-c`) could clash.
// Here the two forms cannot meet, since a kept name never ends like a hashed
// one, and hashed ones differ in their hash unless SHA-256 collides in 64
// bits; the result is at most 12 + 40 + 2 + 16 = 70 bytes. The prefix keeps
// every result clear of C keywords, `main` and reserved identifiers.
std::string c_kernel_name(std::string_view name) {
  std::string out = "sicm_kernel_";
  if (!name.empty() && name.size() <= kReadableMax && is_identifier_tail(name) &&
      !looks_hashed(name))
    return out.append(name);
  return out + c_sanitize(name, kReadableMax) + "_h" + jit_hash(name).substr(0, kHashDigits);
}

std::string c_double_literal(double d) {
  if (std::isnan(d)) return "NAN";
  if (std::isinf(d)) return d > 0 ? "INFINITY" : "-INFINITY";
  char buf[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(buf, d);
  std::string s = buf; // MIT's shortest form: ".5", "1.", "-1.5e-14", "1e21"
  size_t lead = s[0] == '-' ? 1 : 0;
  if (s[lead] == '.') s.insert(lead, "0");
  size_t mantissa_end = s.find('e');
  if (mantissa_end == std::string::npos) mantissa_end = s.size();
  if (s[mantissa_end - 1] == '.') s.insert(mantissa_end, "0");
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string emit_kernel_function(const Trace &t, const std::string &c_name, bool is_static) {
  std::unordered_map<Symbol *, size_t> input;
  for (size_t i = 0; i < t.inputs.size(); ++i)
    input[t.inputs[i]] = i;
  bool uses_in = false;
  std::unordered_map<Symbol *, size_t> param;
  for (size_t j = 0; j < t.param_symbols.size(); ++j)
    param[t.param_symbols[j]] = j;
  auto spell = [&](Symbol *s) {
    auto k = param.find(s);
    if (k != param.end()) return "p[" + std::to_string(k->second) + "]";
    auto in = input.find(s);
    SICM_ASSERT(in != input.end()); // trace_procedure checked the symbols
    uses_in = true;
    return "in[" + std::to_string(in->second) + "]";
  };
  std::vector<std::string> targets;
  for (size_t j = 0; j < t.outputs.size(); ++j)
    targets.push_back("out[" + std::to_string(j) + "]");
  std::string body = Emitter(t.outputs, spell).assignments(targets, "");
  std::string f = is_static ? "static " : "";
  f += "void " + c_name + "(const double *in, double *out, const double *p) {\n";
  if (!uses_in) f += "  (void)in;\n";
  if (t.outputs.empty()) f += "  (void)out;\n";
  f += "  (void)p;\n";
  f += body;
  f += "}\n";
  return f;
}

std::string emit_c_assignments(const std::vector<ExprId> &values,
                               const std::vector<std::string> &targets,
                               const std::function<std::string(Symbol *)> &spell,
                               const std::string &temp_prefix, const std::string &indent,
                               const std::string &checked_site) {
  return Emitter(values, spell, temp_prefix, checked_site).assignments(targets, indent);
}

bool uses_linear_solve(const std::vector<ExprId> &outputs) {
  return !expr_visit(outputs, [](ExprId id) { return !is_solve_node(id); });
}

// The factorizations are loops over n rather than unrolled code: their
// cost is O(n^3) flops either way, and loops keep the C of a 24-link chain
// small. A pivot is taken as zero when it is below kSingularPivot (times
// n) relative to the matrix's scale: a rank-deficient matrix of doubles
// leaves pivots of a few ulps, not exact zeros.
std::string c_linear_solve_support() {
  char bits[64];
  std::snprintf(bits, sizeof bits, "0x%llxULL",
                static_cast<unsigned long long>(SICM_SINGULAR_NAN_BITS));
  return std::string(R"(/* Linear solves of the kernel (sicm's C emitter). */
static inline double sicm_singular_nan(void) {
  union { unsigned long long bits; double d; } u = {)") +
         bits + R"(};
  return u.d;
}

/* a (n x n, row-major, symmetric: only its lower triangle is read) becomes
   L D L^T in place: L below the diagonal, D on it. Nonzero when a pivot is
   not positive (a singular or indefinite matrix). */
static inline int sicm_ldlt_factor(int n, double *a) {
  int singular = 0;
  for (int j = 0; j < n; ++j) {
    double scale = fabs(a[j * n + j]), d = a[j * n + j];
    for (int k = 0; k < j; ++k) {
      a[k * n + j] = a[j * n + k] * a[k * n + k]; /* L_jk d_k, kept above the diagonal */
      d -= a[j * n + k] * a[k * n + j];
    }
    if (!(d > 4 * n * 2.220446049250313e-16 * scale)) singular = 1;
    a[j * n + j] = d;
    for (int i = j + 1; i < n; ++i) {
      double s = a[i * n + j];
      for (int k = 0; k < j; ++k) s -= a[i * n + k] * a[k * n + j];
      a[i * n + j] = s / d;
    }
  }
  return singular;
}

static inline void sicm_ldlt_solve(int n, const double *a, double *x) {
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < i; ++k) x[i] -= a[i * n + k] * x[k];
  for (int i = 0; i < n; ++i) x[i] /= a[i * n + i];
  for (int i = n - 1; i >= 0; --i)
    for (int k = i + 1; k < n; ++k) x[i] -= a[k * n + i] * x[k];
}

/* a becomes L U in place with rows exchanged as pivots[] says (partial
   pivoting). Nonzero when a pivot is zero to working precision. */
static inline int sicm_lu_factor(int n, double *a, int *pivots) {
  int singular = 0;
  double scale = 0;
  for (int i = 0; i < n * n; ++i)
    if (fabs(a[i]) > scale) scale = fabs(a[i]);
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (fabs(a[i * n + k]) > fabs(a[p * n + k])) p = i;
    pivots[k] = p;
    if (p != k)
      for (int j = 0; j < n; ++j) {
        double t = a[k * n + j];
        a[k * n + j] = a[p * n + j];
        a[p * n + j] = t;
      }
    if (!(fabs(a[k * n + k]) > 4 * n * 2.220446049250313e-16 * scale)) singular = 1;
    for (int i = k + 1; i < n; ++i) {
      double f = a[i * n + k] / a[k * n + k];
      a[i * n + k] = f;
      for (int j = k + 1; j < n; ++j) a[i * n + j] -= f * a[k * n + j];
    }
  }
  return singular;
}

static inline void sicm_lu_solve(int n, const double *a, const int *pivots, double *x) {
  for (int k = 0; k < n; ++k) {
    double t = x[k];
    x[k] = x[pivots[k]];
    x[pivots[k]] = t;
  }
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < i; ++k) x[i] -= a[i * n + k] * x[k];
  for (int i = n - 1; i >= 0; --i) {
    for (int k = i + 1; k < n; ++k) x[i] -= a[i * n + k] * x[k];
    x[i] /= a[i * n + i];
  }
}

)";
}

std::string emit_kernel_unit(const Trace &t, const std::string &c_name,
                             std::string_view source_name) {
  std::string s = "/* sicm kernel " + c_sanitize(source_name, 64) + ": " +
                  std::to_string(t.inputs.size()) + " inputs, " + std::to_string(t.outputs.size()) +
                  " outputs. Generated by the sicm compiler; do not edit. */\n";
  s += "#define _GNU_SOURCE\n#include <math.h>\n\n";
  if (uses_linear_solve(t.outputs)) s += c_linear_solve_support();
  s += "void " + c_name + "(const double *in, double *out, const double *p);\n\n";
  s += emit_kernel_function(t, c_name, false);
  return s;
}

} // namespace sicm

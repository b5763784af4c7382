// The one walker over the terms of prefix expression data (see term_walker.hpp).
#include "print/term_walker.hpp"

#include "base/number.hpp"
#include "print/infix.hpp"

namespace sicm {

using namespace expr_shape;

namespace {

bool g_dot_notation = false;

// Functions of the numbers, whose argument the dot notation always shows.
bool is_elementary_function(const std::string &name) {
  static const char *const kNames[] = {"sin",    "cos",  "tan",    "cot",  "sec",       "csc",
                                       "exp",    "log",  "sinh",   "cosh", "tanh",      "asin",
                                       "acos",   "atan", "sqrt",   "abs",  "arcsin",    "arccos",
                                       "arctan", "cube", "square", "expt", "magnitude", "angle"};
  for (const char *n : kNames)
    if (name == n) return true;
  return false;
}

// f with n time derivatives as a name the name printers show with dots:
// theta -> thetadot, p_x -> pdot_x (the dots belong to the base).
std::string dotted_name(const std::string &f, int n) {
  size_t base_end = f.find_first_of("_^");
  if (base_end == std::string::npos) base_end = f.size();
  std::string dots;
  for (int i = 0; i < n; ++i)
    dots += "dot";
  return f.substr(0, base_end) + dots + f.substr(base_end);
}

// How many times op differentiates: D -> 1, (expt D n) -> n; 0 for any
// other operator (a partial derivative).
int time_derivatives(Value op) {
  if (is_symbol(op)) return symbol_name(op) == "D" ? 1 : 0;
  if (head_is(op, "expt") && list_length(op) == 3 && is_symbol(car(cdr(op))) &&
      symbol_name(car(cdr(op))) == "D" && car(cdr(cdr(op))).is(Tag::Fixnum) &&
      car(cdr(cdr(op))).i >= 1 && car(cdr(cdr(op))).i <= 3)
    return static_cast<int>(car(cdr(cdr(op))).i);
  return 0;
}

} // namespace

void set_dot_notation(bool on) {
  g_dot_notation = on;
}

// The dot notation's name for (head t), or "" when it does not apply
// (print/infix.hpp): (theta t) -> theta, ((D theta) t) -> thetadot.
std::string TermWalker::dotted(Value head, const gcvec<Value> &args) {
  if (!g_dot_notation || args.size() != 1 || !is_symbol(args[0]) || symbol_name(args[0]) != "t")
    return "";
  if (is_symbol(head)) return is_elementary_function(symbol_name(head)) ? "" : symbol_name(head);
  if (!is_operator_application(head)) return "";
  Value op = car(head), f = car(cdr(head));
  int n = time_derivatives(op);
  if (!is_symbol(f) || n < 1 || n > 3 || is_elementary_function(symbol_name(f))) return "";
  return dotted_name(symbol_name(f), n);
}

std::string TermWalker::wrap(const Text &t, int min, bool paren_neg) {
  if (t.prec < min || (paren_neg && t.neg)) return paren(t.s);
  return t.s;
}

std::string TermWalker::join(const gcvec<Value> &items, const char *sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i) out += sep;
    out += render(items[i]).s;
  }
  return out;
}

// -x for a negative term: -3, (* -2 x), (- x), a quotient of one.
TermWalker::Text TermWalker::negation(Value d) {
  return {"-" + wrap(render(negate_term(d)), kProduct, true), kProduct, true};
}

TermWalker::Text TermWalker::sum(const gcvec<Value> &args) {
  Text out{"", kSum};
  for (size_t i = 0; i < args.size(); ++i) {
    if (is_negative_term(args[i])) {
      out.s += (i ? " - " : "-") + wrap(render(negate_term(args[i])), kProduct, true);
      if (i == 0) out.neg = true;
    } else {
      Text t = render(args[i]);
      out.s += i ? " + " + wrap(t, kSum, true) : wrap(t, kSum);
      if (i == 0) out.neg = t.neg;
    }
  }
  return out;
}

TermWalker::Text TermWalker::difference(const gcvec<Value> &args) {
  if (args.size() == 1) return {"-" + wrap(render(args[0]), kProduct, true), kProduct, true};
  Text out = render(args[0]);
  out.s = wrap(out, kSum);
  out.prec = kSum;
  for (size_t i = 1; i < args.size(); ++i)
    out.s += " - " + wrap(render(args[i]), kProduct, true);
  return out;
}

TermWalker::Text TermWalker::product(Value d, const gcvec<Value> &args) {
  if (is_negative_term(d)) return negation(d);
  Text out{"", kProduct};
  for (size_t i = 0; i < args.size(); ++i) {
    Text t = render(args[i]);
    std::string f = factor(t, args[i], i > 0);
    if (i == 0) {
      out.neg = t.neg;
    } else {
      out.s += factor_separator((f[0] >= '0' && f[0] <= '9') || f[0] == '.');
    }
    out.s += f;
  }
  return out;
}

// Dx, D²θ, ∂₁∂₀L, D(f + g).
TermWalker::Text TermWalker::operator_application(Value op, Value f) {
  std::string operand;
  if (is_symbol(f))
    operand = name_text(symbol_name(f));
  else if (is_operator_application(f))
    operand = render(f).s;
  else
    operand = paren(render(f).s);
  return {operator_text(op) + operand, kAtom};
}

// f(a, b), Dx(t), (f + g)(t).
TermWalker::Text TermWalker::application(Value head, const gcvec<Value> &args) {
  if (std::string name = dotted(head, args); !name.empty()) return {name_text(name), kAtom};
  std::string h =
      is_symbol(head) ? function_text(symbol_name(head)) : wrap(render(head), kAtom, true);
  return {h + paren(join(args, ", ")), kAtom};
}

TermWalker::Text TermWalker::render_list(Value d) {
  Value head = car(d);
  gcvec<Value> args = list_to_vector(cdr(d));
  size_t n = args.size();
  if (is_operator(d)) return {operator_text(d), kAtom};
  if (n == 1 && is_operator(head)) return operator_application(head, args[0]);
  if (is_symbol(head)) {
    const std::string &name = symbol_name(head);
    if (name == "+") return n == 0 ? Text{"0"} : n == 1 ? render(args[0]) : sum(args);
    if (name == "*") return n == 0 ? Text{"1"} : n == 1 ? render(args[0]) : product(d, args);
    if (name == "-" && n >= 1) return difference(args);
    if (name == "/" && n >= 1) return is_negative_term(d) ? negation(d) : quotient(args);
    if (name == "expt" && n == 2) return power(args[0], args[1]);
    if (name == "sqrt" && n == 1) return square_root(args[0]);
    if (name == "abs" && n == 1) return absolute_value(args[0]);
    if (name == "up" || name == "down") return structure(name == "up", args);
    if (name == "matrix-by-rows")
      if (std::optional<Text> m = matrix(args)) return *m;
    if (std::optional<std::string> rel = relation(name); rel && n == 2)
      return {wrap(render(args[0]), kSum) + " " + *rel + " " + wrap(render(args[1]), kSum),
              kRelation};
  }
  if (!is_symbol(head) && !is_pair(head)) // plain data such as (1 2 3): a tuple
    return {paren(join(list_to_vector(d), ", ")), kAtom};
  return application(head, args);
}

TermWalker::Text TermWalker::render(Value d) {
  if (is_number(d)) return number_text(d);
  if (is_symbol(d)) return {name_text(symbol_name(d)), kAtom};
  if (is_pair(d) && list_length(d) > 0) return render_list(d);
  return {other_text(d), kAtom};
}

} // namespace sicm

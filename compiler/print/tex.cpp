// Prefix expression data as TeX math (see print/infix.hpp for the forms).
//
// Follows the infix renderer's structure: each subexpression is rendered with
// its precedence and whether it begins with a minus, and the parent brackets
// it with \left( \right) only where needed. Quotients are \frac, which is
// self-delimiting, so they need brackets only as the base of a power.
#include <optional>

#include "base/number.hpp"
#include "print/display_names.hpp"
#include "print/infix.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

using namespace expr_shape;

enum Prec { kRelation, kSum, kProduct, kPower, kAtom };

struct Text {
  std::string s;
  int prec = kAtom;
  bool neg = false; // begins with a minus sign
};

Text render(Value d);

std::string paren(const std::string &s) {
  return "\\left(" + s + "\\right)";
}

std::string wrap(const Text &t, int min, bool paren_neg = false) {
  return t.prec < min || (paren_neg && t.neg) ? paren(t.s) : t.s;
}

// 1/2 as \frac{1}{2}; 1e-20 as 1 \times 10^{-20}; otherwise Scheme's text.
Text number_text(Value d) {
  bool neg = is_real(d) && num_sign(d) < 0;
  Text t{"", kAtom, neg};
  if (d.is(Tag::Ratnum)) {
    Value a = num_abs(d);
    t.s = std::string(neg ? "-" : "") + "\\frac{" + number_to_string(num_numerator(a)) + "}{" +
          number_to_string(num_denominator(a)) + "}";
  } else {
    t.s = number_to_string(d);
    size_t e = t.s.find('e');
    if (d.is(Tag::Flonum) && e != std::string::npos) {
      t.s = t.s.substr(0, e) + " \\times 10^{" + t.s.substr(e + 1) + "}";
      t.prec = kProduct;
    }
  }
  if (neg) t.prec = kProduct;
  if (is_recnum(d)) t.prec = kSum; // 1+2i reads as a sum
  return t;
}

std::string join(const gcvec<Value> &items, const char *sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i) out += sep;
    out += render(items[i]).s;
  }
  return out;
}

Text negation(Value d) {
  return {"-" + wrap(render(negate_term(d)), kProduct, true), kProduct, true};
}

Text sum(const gcvec<Value> &args) {
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

Text difference(const gcvec<Value> &args) {
  if (args.size() == 1) return {"-" + wrap(render(args[0]), kProduct, true), kProduct, true};
  Text out = render(args[0]);
  out.s = wrap(out, kSum);
  out.prec = kSum;
  for (size_t i = 1; i < args.size(); ++i)
    out.s += " - " + wrap(render(args[i]), kProduct, true);
  return out;
}

Text product(Value d, const gcvec<Value> &args) {
  if (is_negative_term(d)) return negation(d);
  Text out{"", kProduct};
  for (size_t i = 0; i < args.size(); ++i) {
    Text t = render(args[i]);
    std::string f = wrap(t, kProduct, i > 0);
    if (i == 0) {
      out.neg = t.neg;
    } else {
      // Juxtaposed digits would merge into one number: 2 \cdot 3.
      bool digit = (f[0] >= '0' && f[0] <= '9') || f[0] == '.';
      out.s += digit ? " \\cdot " : " ";
    }
    out.s += f;
  }
  return out;
}

// (/ a b c) is (a/b)/c, so it nests: \frac{\frac{a}{b}}{c}.
Text quotient(Value d, const gcvec<Value> &args) {
  if (is_negative_term(d)) return negation(d);
  std::string out = args.size() == 1 ? "1" : render(args[0]).s;
  for (size_t i = args.size() == 1 ? 0 : 1; i < args.size(); ++i)
    out = "\\frac{" + out + "}{" + render(args[i]).s + "}";
  return {out, kPower};
}

Text power(Value base, Value expo) {
  Text b = render(base);
  std::string bs = wrap(b, kAtom, true);
  // v^0 squared: TeX rejects v^{0}^{2}, so the name becomes one group.
  if (is_symbol(base) && bs.find('^') != std::string::npos) bs = "{" + bs + "}";
  return {bs + "^{" + render(expo).s + "}", kPower};
}

// TeX's own operator names for the functions that have one.
std::optional<std::string> tex_function(const std::string &name) {
  static const char *const kNames[][2] = {
      {"sin", "\\sin"},      {"cos", "\\cos"},     {"tan", "\\tan"},       {"cot", "\\cot"},
      {"sec", "\\sec"},      {"csc", "\\csc"},     {"exp", "\\exp"},       {"log", "\\log"},
      {"sinh", "\\sinh"},    {"cosh", "\\cosh"},   {"tanh", "\\tanh"},     {"asin", "\\arcsin"},
      {"acos", "\\arccos"},  {"atan", "\\arctan"}, {"arcsin", "\\arcsin"}, {"arccos", "\\arccos"},
      {"arctan", "\\arctan"}};
  for (auto &entry : kNames)
    if (name == entry[0]) return std::string(entry[1]);
  return std::nullopt;
}

// D, D^{2}, \partial_{1}, \partial_{1,0}.
std::string operator_text(Value op) {
  if (is_symbol(op)) return symbol_name(op);
  if (head_is(op, "partial")) {
    std::string out = "\\partial_{";
    for (Value i = cdr(op); is_pair(i); i = cdr(i)) {
      if (!eq(i, cdr(op))) out += ",";
      out += number_to_string(car(i));
    }
    return out + "}";
  }
  return operator_text(car(cdr(op))) + "^{" + render(car(cdr(cdr(op)))).s + "}";
}

Text operator_application(Value op, Value f) {
  std::string operand;
  if (is_symbol(f))
    operand = tex_name(symbol_name(f));
  else if (is_operator_application(f))
    operand = render(f).s;
  else
    operand = paren(render(f).s);
  return {operator_text(op) + operand, kAtom};
}

Text application(Value head, const gcvec<Value> &args) {
  std::string h;
  if (is_symbol(head))
    h = tex_function(symbol_name(head)).value_or(tex_name(symbol_name(head)));
  else
    h = wrap(render(head), kAtom, true);
  return {h + paren(join(args, ", ")), kAtom};
}

Text structure(const std::string &env, const gcvec<Value> &items, const char *sep) {
  return {"\\begin{" + env + "} " + join(items, sep) + " \\end{" + env + "}", kAtom};
}

std::optional<Text> matrix(const gcvec<Value> &rows) {
  std::string out = "\\begin{bmatrix} ";
  for (size_t i = 0; i < rows.size(); ++i) {
    if (!head_is(rows[i], "list") || list_length(rows[i]) < 0) return std::nullopt;
    if (i) out += " \\\\ ";
    out += join(list_to_vector(cdr(rows[i])), " & ");
  }
  return Text{out + " \\end{bmatrix}", kAtom};
}

std::optional<std::string> relation(const std::string &name) {
  if (name == "=" || name == "<" || name == ">") return name;
  if (name == "<=") return "\\le";
  if (name == ">=") return "\\ge";
  return std::nullopt;
}

Text render_list(Value d) {
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
    if (name == "/" && n >= 1) return quotient(d, args);
    if (name == "expt" && n == 2) return power(args[0], args[1]);
    if (name == "sqrt" && n == 1) return {"\\sqrt{" + render(args[0]).s + "}", kAtom};
    if (name == "abs" && n == 1) return {"\\left|" + render(args[0]).s + "\\right|", kAtom};
    if (name == "up") return structure("pmatrix", args, " \\\\ ");
    if (name == "down") return structure("bmatrix", args, " & ");
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

Text render(Value d) {
  if (is_number(d)) return number_text(d);
  if (is_symbol(d)) return {tex_name(symbol_name(d)), kAtom};
  if (is_pair(d) && list_length(d) > 0) return render_list(d);
  return {"\\mathrm{" + tex_escape(display_string(d)) + "}", kAtom};
}

} // namespace

std::string datum_to_tex(Value datum) {
  return render(datum).s;
}

} // namespace sicm

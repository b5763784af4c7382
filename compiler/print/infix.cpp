// Prefix expression data as conventional infix text (see print/infix.hpp).
//
// Each subexpression is rendered to a Text that remembers how tightly it
// binds (its precedence) and whether it begins with a minus sign; the parent
// adds parentheses only where reading the text without them would change its
// meaning or where a minus would sit right after another operator.
#include "print/infix.hpp"

#include "base/number.hpp"
#include "print/display_names.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace expr_shape {

bool head_is(Value d, const char *name) {
  return is_pair(d) && is_symbol(car(d)) && symbol_name(car(d)) == name;
}

bool is_natural(Value d) {
  return is_exact_integer(d) && num_sign(d) >= 0;
}

bool is_negative_term(Value d) {
  if (is_number(d)) return is_real(d) && num_sign(d) < 0;
  if (!is_pair(d) || list_length(d) < 2) return false;
  Value first = car(cdr(d));
  if (head_is(d, "*")) return is_real(first) && num_sign(first) < 0;
  if (head_is(d, "-")) return list_length(d) == 2;
  if (head_is(d, "/")) return is_negative_term(first);
  return false;
}

Value negate_term(Value d) {
  if (is_number(d)) return num_neg(d);
  if (head_is(d, "-")) return car(cdr(d));
  Value first = car(cdr(d)), rest = cdr(cdr(d));
  if (head_is(d, "/")) return cons(car(d), cons(negate_term(first), rest));
  // (* c f ...): a coefficient of exactly 1 is dropped, as the product
  // would never be written with it.
  Value c = num_neg(first);
  if (is_null(rest)) return c;
  if (c.is(Tag::Fixnum) && c.i == 1) return is_null(cdr(rest)) ? car(rest) : cons(car(d), rest);
  return cons(car(d), cons(c, rest));
}

bool is_operator(Value d) {
  if (is_symbol(d)) return symbol_name(d) == "D";
  long n = list_length(d);
  if (head_is(d, "partial") && n >= 2) {
    for (Value i = cdr(d); is_pair(i); i = cdr(i))
      if (!is_natural(car(i))) return false;
    return true;
  }
  return head_is(d, "expt") && n == 3 && is_operator(car(cdr(d)));
}

bool is_operator_application(Value d) {
  return list_length(d) == 2 && is_operator(car(d));
}

} // namespace expr_shape

namespace {

using namespace expr_shape;

enum Prec { kRelation, kSum, kProduct, kPower, kAtom };

struct Text {
  std::string s;
  int prec = kAtom;
  bool neg = false; // begins with a minus sign
};

Text render(Value d);

// t's text, parenthesized if it binds more loosely than min, or if it
// begins with a minus and paren_neg says a minus may not appear here.
std::string wrap(const Text &t, int min, bool paren_neg = false) {
  if (t.prec < min || (paren_neg && t.neg)) return "(" + t.s + ")";
  return t.s;
}

Text number_text(Value d) {
  Text t{number_to_string(d), kAtom, is_real(d) && num_sign(d) < 0};
  // 1/2 reads as a quotient, so (1/2)^2; a negative number as a negation;
  // a complex number 1+2i as a sum.
  if (t.neg || d.is(Tag::Ratnum)) t.prec = kProduct;
  if (is_recnum(d)) t.prec = kSum;
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
  if (is_negative_term(d))
    return {"-" + wrap(render(negate_term(d)), kProduct, true), kProduct, true};
  Text out{"", kProduct};
  for (size_t i = 0; i < args.size(); ++i) {
    Text t = render(args[i]);
    // A quotient among factors is bracketed: "a b / c d" would be unclear.
    std::string f = head_is(args[i], "/") ? "(" + t.s + ")" : wrap(t, kProduct, i > 0);
    if (i == 0) {
      out.neg = t.neg;
    } else {
      // "2 3" would read as one number, so factors after the first that
      // begin with a digit are marked with an explicit "*".
      bool digit = (f[0] >= '0' && f[0] <= '9') || f[0] == '.';
      out.s += digit ? " * " : " ";
    }
    out.s += f;
  }
  return out;
}

Text quotient(Value d, const gcvec<Value> &args) {
  if (is_negative_term(d))
    return {"-" + wrap(render(negate_term(d)), kProduct, true), kProduct, true};
  Text out{"1", kProduct};
  size_t first_den = 0;
  if (args.size() > 1) {
    Text num = render(args[0]);
    out.s = head_is(args[0], "/") ? "(" + num.s + ")" : wrap(num, kProduct);
    out.neg = num.neg;
    first_den = 1;
  }
  for (size_t i = first_den; i < args.size(); ++i)
    out.s += " / " + wrap(render(args[i]), kPower, true);
  return out;
}

Text power(Value base, Value expo) {
  Text b = render(base);
  std::string e;
  if (is_natural(expo) || is_symbol(expo))
    e = render(expo).s;
  else if (is_exact_integer(expo))
    e = number_to_string(expo); // x^-1 is unambiguous
  else
    e = "(" + render(expo).s + ")";
  return {wrap(b, kAtom, true) + "^" + e, kPower};
}

// D, D², ∂₁, ∂₁,₀ (Unicode has no subscript comma, so a plain one).
std::string operator_text(Value op) {
  if (is_symbol(op)) return symbol_name(op);
  if (head_is(op, "partial")) {
    std::string out = "∂";
    for (Value i = cdr(op); is_pair(i); i = cdr(i)) {
      std::string index = number_to_string(car(i));
      if (!eq(i, cdr(op))) out += ",";
      out += to_subscript(index).value_or(index);
    }
    return out;
  }
  Value expo = car(cdr(cdr(op)));
  std::optional<std::string> sup;
  if (is_natural(expo)) sup = to_superscript(number_to_string(expo));
  return operator_text(car(cdr(op))) + sup.value_or("^(" + render(expo).s + ")");
}

// Dx, D²θ, ∂₁∂₀L, D(f + g).
Text operator_application(Value op, Value f) {
  std::string operand;
  if (is_symbol(f))
    operand = display_name(symbol_name(f));
  else if (is_operator_application(f))
    operand = render(f).s;
  else
    operand = "(" + render(f).s + ")";
  return {operator_text(op) + operand, kAtom};
}

// f(a, b), Dx(t), (f + g)(t).
Text application(Value head, const gcvec<Value> &args) {
  std::string h =
      is_symbol(head) ? display_name(symbol_name(head)) : wrap(render(head), kAtom, true);
  return {h + "(" + join(args, ", ") + ")", kAtom};
}

// [[a, b], [c, d]] when every argument is a (list ...) row; nullopt otherwise.
std::optional<Text> matrix(const gcvec<Value> &rows) {
  std::string out = "[";
  for (size_t i = 0; i < rows.size(); ++i) {
    if (!head_is(rows[i], "list") || list_length(rows[i]) < 0) return std::nullopt;
    if (i) out += ", ";
    out += "[" + join(list_to_vector(cdr(rows[i])), ", ") + "]";
  }
  return Text{out + "]", kAtom};
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
    if (name == "sqrt" && n == 1) {
      Text t = render(args[0]);
      return {"√" + (t.prec == kAtom && !t.neg ? t.s : "(" + t.s + ")"), kPower};
    }
    if (name == "abs" && n == 1) return {"|" + render(args[0]).s + "|", kAtom};
    if (name == "up" || name == "down") return {name + "(" + join(args, ", ") + ")", kAtom};
    if (name == "matrix-by-rows")
      if (std::optional<Text> m = matrix(args)) return *m;
    if ((name == "=" || name == "<" || name == ">" || name == "<=" || name == ">=") && n == 2)
      return {wrap(render(args[0]), kSum) + " " + name + " " + wrap(render(args[1]), kSum),
              kRelation};
  }
  if (!is_symbol(head) && !is_pair(head)) // plain data such as (1 2 3): a tuple
    return {"(" + join(list_to_vector(d), ", ") + ")", kAtom};
  return application(head, args);
}

Text render(Value d) {
  if (is_number(d)) return number_text(d);
  if (is_symbol(d)) return {display_name(symbol_name(d)), kAtom};
  if (is_pair(d) && list_length(d) > 0) return render_list(d);
  return {display_string(d), kAtom};
}

} // namespace

std::string datum_to_infix(Value datum) {
  return render(datum).s;
}

} // namespace sicm

// Prefix expression data as conventional infix text (see print/infix.hpp):
// the infix notation of the one walker over terms (print/term_walker.hpp),
// and the shapes of data both notations recognize.
#include "print/infix.hpp"

#include "base/number.hpp"
#include "print/display_names.hpp"
#include "print/printer.hpp"
#include "print/term_walker.hpp"

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

// Infix text: one line of UTF-8.
class InfixWalker final : public TermWalker {
  std::string paren(const std::string &s) override { return "(" + s + ")"; }

  Text number_text(Value d) override {
    Text t{number_to_string(d), kAtom, is_real(d) && num_sign(d) < 0};
    // 1/2 reads as a quotient, so (1/2)^2; a negative number as a negation;
    // a complex number 1+2i as a sum.
    if (t.neg || d.is(Tag::Ratnum)) t.prec = kProduct;
    if (is_recnum(d)) t.prec = kSum;
    return t;
  }

  std::string name_text(const std::string &name) override { return display_name(name); }

  // A quotient among factors is bracketed: "a b / c d" would be unclear.
  std::string factor(const Text &t, Value arg, bool later) override {
    return head_is(arg, "/") ? "(" + t.s + ")" : wrap(t, kProduct, later);
  }

  // "2 3" would read as one number, so factors after the first that begin
  // with a digit are marked with an explicit "*".
  std::string factor_separator(bool digit) override { return digit ? " * " : " "; }

  Text quotient(const gcvec<Value> &args) override {
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

  Text power(Value base, Value expo) override {
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

  Text square_root(Value arg) override {
    Text t = render(arg);
    return {"√" + (t.prec == kAtom && !t.neg ? t.s : "(" + t.s + ")"), kPower};
  }

  Text absolute_value(Value arg) override { return {"|" + render(arg).s + "|", kAtom}; }

  Text structure(bool up, const gcvec<Value> &items) override {
    return {std::string(up ? "up" : "down") + "(" + join(items, ", ") + ")", kAtom};
  }

  // [[a, b], [c, d]].
  std::optional<Text> matrix(const gcvec<Value> &rows) override {
    std::string out = "[";
    for (size_t i = 0; i < rows.size(); ++i) {
      if (!head_is(rows[i], "list") || list_length(rows[i]) < 0) return std::nullopt;
      if (i) out += ", ";
      out += "[" + join(list_to_vector(cdr(rows[i])), ", ") + "]";
    }
    return Text{out + "]", kAtom};
  }

  std::optional<std::string> relation(const std::string &name) override {
    if (name == "=" || name == "<" || name == ">" || name == "<=" || name == ">=") return name;
    return std::nullopt;
  }

  // D, D², ∂₁, ∂₁,₀ (Unicode has no subscript comma, so a plain one).
  std::string operator_text(Value op) override {
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

  std::string other_text(Value d) override { return display_string(d); }
};

} // namespace

std::string datum_to_infix(Value datum) {
  InfixWalker walker;
  return walker.render(datum).s;
}

} // namespace sicm

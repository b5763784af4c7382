// Prefix expression data as TeX math (see print/infix.hpp for the forms): the
// TeX notation of the one walker over terms (print/term_walker.hpp).
#include <optional>

#include "base/number.hpp"
#include "print/display_names.hpp"
#include "print/infix.hpp"
#include "print/printer.hpp"
#include "print/term_walker.hpp"

namespace sicm {

namespace {

using namespace expr_shape;

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

// TeX math: \left( \right) brackets; quotients are \frac, which is
// self-delimiting, so they need brackets only as the base of a power.
class TexWalker final : public TermWalker {
  std::string paren(const std::string &s) override { return "\\left(" + s + "\\right)"; }

  // 1/2 as \frac{1}{2}; 1e-20 as 1 \times 10^{-20}; otherwise Scheme's text.
  Text number_text(Value d) override {
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

  std::string name_text(const std::string &name) override { return tex_name(name); }

  std::string function_text(const std::string &name) override {
    return tex_function(name).value_or(tex_name(name));
  }

  std::string factor(const Text &t, Value, bool later) override { return wrap(t, kProduct, later); }

  // Juxtaposed digits would merge into one number: 2 \cdot 3.
  std::string factor_separator(bool digit) override { return digit ? " \\cdot " : " "; }

  // (/ a b c) is (a/b)/c, so it nests: \frac{\frac{a}{b}}{c}.
  Text quotient(const gcvec<Value> &args) override {
    std::string out = args.size() == 1 ? "1" : render(args[0]).s;
    for (size_t i = args.size() == 1 ? 0 : 1; i < args.size(); ++i)
      out = "\\frac{" + out + "}{" + render(args[i]).s + "}";
    return {out, kPower};
  }

  Text power(Value base, Value expo) override {
    Text b = render(base);
    std::string bs = wrap(b, kAtom, true);
    // v^0 squared: TeX rejects v^{0}^{2}, so the name becomes one group.
    if (is_symbol(base) && bs.find('^') != std::string::npos) bs = "{" + bs + "}";
    return {bs + "^{" + render(expo).s + "}", kPower};
  }

  Text square_root(Value arg) override { return {"\\sqrt{" + render(arg).s + "}", kAtom}; }

  Text absolute_value(Value arg) override {
    return {"\\left|" + render(arg).s + "\\right|", kAtom};
  }

  // up as a column (pmatrix), down as a row (bmatrix).
  Text structure(bool up, const gcvec<Value> &items) override {
    std::string env = up ? "pmatrix" : "bmatrix";
    return {"\\begin{" + env + "} " + join(items, up ? " \\\\ " : " & ") + " \\end{" + env + "}",
            kAtom};
  }

  std::optional<Text> matrix(const gcvec<Value> &rows) override {
    std::string out = "\\begin{bmatrix} ";
    for (size_t i = 0; i < rows.size(); ++i) {
      if (!head_is(rows[i], "list") || list_length(rows[i]) < 0) return std::nullopt;
      if (i) out += " \\\\ ";
      out += join(list_to_vector(cdr(rows[i])), " & ");
    }
    return Text{out + " \\end{bmatrix}", kAtom};
  }

  std::optional<std::string> relation(const std::string &name) override {
    if (name == "=" || name == "<" || name == ">") return name;
    if (name == "<=") return "\\le";
    if (name == ">=") return "\\ge";
    return std::nullopt;
  }

  // D, D^{2}, \partial_{1}, \partial_{1,0}.
  std::string operator_text(Value op) override {
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

  std::string other_text(Value d) override {
    return "\\mathrm{" + tex_escape(display_string(d)) + "}";
  }
};

} // namespace

std::string datum_to_tex(Value datum) {
  TexWalker walker;
  return walker.render(datum).s;
}

} // namespace sicm

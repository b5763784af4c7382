// The one walker over the terms of prefix expression data, shared by the
// infix and TeX renderings (print/infix.hpp describes both).
//
// Each subexpression is rendered to a Text that remembers how tightly it
// binds (its precedence) and whether it begins with a minus sign; the parent
// adds brackets only where reading the text without them would change its
// meaning or where a minus would sit right after another operator. What is
// common to both notations (sums, differences, products, negative terms,
// operators applied to functions, function calls, the order of the cases)
// is here; each notation says how it writes brackets, numbers, names,
// quotients, powers, roots and the rest (infix.cpp, tex.cpp).
#pragma once

#include <optional>
#include <string>

#include "base/value.hpp"

namespace sicm {

class TermWalker {
public:
  enum Prec { kRelation, kSum, kProduct, kPower, kAtom };

  struct Text {
    std::string s;
    int prec = kAtom;
    bool neg = false; // begins with a minus sign
  };

  virtual ~TermWalker() = default;

  Text render(Value d);

protected:
  // t's text, bracketed if it binds more loosely than min, or if it begins
  // with a minus and paren_neg says a minus may not appear here.
  std::string wrap(const Text &t, int min, bool paren_neg = false);
  std::string join(const gcvec<Value> &items, const char *sep);

  // ---- what each notation writes its own way
  virtual std::string paren(const std::string &s) = 0;
  virtual Text number_text(Value d) = 0;
  // A symbol as a name (θ, \theta) and as the head of a call (sin, \sin).
  virtual std::string name_text(const std::string &name) = 0;
  virtual std::string function_text(const std::string &name) { return name_text(name); }
  // Factor t (of arg) of a product, after the first one if later.
  virtual std::string factor(const Text &t, Value arg, bool later) = 0;
  // What separates a factor from the one before it (begins_with_digit: the
  // factor's text starts with a digit, which would merge with a number).
  virtual std::string factor_separator(bool begins_with_digit) = 0;
  virtual Text quotient(const gcvec<Value> &args) = 0; // not a negative term
  virtual Text power(Value base, Value expo) = 0;
  virtual Text square_root(Value arg) = 0;
  virtual Text absolute_value(Value arg) = 0;
  virtual Text structure(bool up, const gcvec<Value> &items) = 0;
  // (matrix-by-rows (list a b) ...), or nullopt when a row is not a list.
  virtual std::optional<Text> matrix(const gcvec<Value> &rows) = 0;
  // The relation's symbol, or nullopt if `name` is not a relation.
  virtual std::optional<std::string> relation(const std::string &name) = 0;
  virtual std::string operator_text(Value op) = 0; // D, D², ∂₁,₀
  virtual std::string other_text(Value d) = 0;     // a value that is not data

private:
  Text negation(Value d);
  Text sum(const gcvec<Value> &args);
  Text difference(const gcvec<Value> &args);
  Text product(Value d, const gcvec<Value> &args);
  Text operator_application(Value op, Value f);
  Text application(Value head, const gcvec<Value> &args);
  std::string dotted(Value head, const gcvec<Value> &args);
  Text render_list(Value d);
};

} // namespace sicm

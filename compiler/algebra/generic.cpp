// Generic arithmetic: the dispatch table, the symbolic type, and the + - * / ... primitives.
#include "algebra/generic.hpp"

#include <algorithm>
#include <string>

#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/primitive.hpp"

namespace sicm {

// ---- names ------------------------------------------------------------------------------------

namespace {

struct UnaryNames {
  const char *scheme, *error;
};

// Indexed by UnaryOp. MIT's errors name integer-negate and friends for the
// operations that reach integer arithmetic, and the procedure otherwise.
const UnaryNames kUnaryNames[] = {
    {"negate", "integer-negate"},
    {"invert", "/"},
    {"sqrt", "sqrt"},
    {"exp", "exp"},
    {"log", "log"},
    {"sin", "sin"},
    {"cos", "cos"},
    {"tan", "tan"},
    {"asin", "asin"},
    {"acos", "acos"},
    {"atan", "atan"},
    {"abs", "integer-abs"},
    {"magnitude", "magnitude"},
    {"square", "integer-multiply"},
    {"cube", "integer-multiply"},
    {"zero?", "zero?"},
};

// Indexed by BinaryOp.
const UnaryNames kBinaryNames[] = {
    {"+", "integer-add"}, {"-", "integer-subtract"}, {"*", "integer-multiply"}, {"/", "/"},
    {"expt", "expt"},     {"atan", "atan"},          {"=", "integer-equal?"},
};

} // namespace

const char *op_scheme_name(UnaryOp op) {
  return kUnaryNames[static_cast<int>(op)].scheme;
}
const char *op_scheme_name(BinaryOp op) {
  return kBinaryNames[static_cast<int>(op)].scheme;
}
const char *op_error_name(UnaryOp op) {
  return kUnaryNames[static_cast<int>(op)].error;
}
const char *op_error_name(BinaryOp op) {
  return kBinaryNames[static_cast<int>(op)].error;
}

void arith_wrong_type(UnaryOp op, Value x) {
  wrong_type(x, 1, op_error_name(op));
}
void arith_wrong_type(BinaryOp op, Value obj, int argpos) {
  wrong_type(obj, argpos, op_error_name(op));
}

// ---- the type table ---------------------------------------------------------------------------

namespace {

constexpr int kMaxArithTypes = 16;
const ArithType *g_types[kMaxArithTypes]; // sorted by rank, highest first
int g_ntypes = 0;

const ArithType *higher_rank(const ArithType *a, const ArithType *b) {
  if (!a) return b;
  if (!b) return a;
  return b->rank > a->rank ? b : a;
}

} // namespace

void register_arith_type(const ArithType *type) {
  SICM_ASSERT(g_ntypes < kMaxArithTypes);
  for (int i = 0; i < g_ntypes; ++i)
    if (g_types[i] == type) return; // installing twice is harmless
  g_types[g_ntypes++] = type;
  std::stable_sort(g_types, g_types + g_ntypes,
                   [](const ArithType *x, const ArithType *y) { return x->rank > y->rank; });
}

const ArithType *arith_type_of(Value v) {
  if (is_number(v)) return nullptr;
  for (int i = 0; i < g_ntypes; ++i)
    if (g_types[i]->member(v)) return g_types[i];
  return nullptr;
}

bool is_arithmetic(Value v) {
  return is_number(v) || arith_type_of(v) != nullptr;
}

bool is_exact_zero(Value v) {
  return v.is(Tag::Fixnum) && v.i == 0;
}
bool is_exact_one(Value v) {
  return v.is(Tag::Fixnum) && v.i == 1;
}

// ---- numbers ----------------------------------------------------------------------------------

namespace {

// The numeric tower's operations; they raise MIT's errors for non-numbers.
Value number_unary(UnaryOp op, Value x) {
  switch (op) {
  case UnaryOp::Neg: return num_neg(x);
  case UnaryOp::Invert: return num_div(Value::fixnum(1), x);
  case UnaryOp::Sqrt: return num_sqrt(x);
  case UnaryOp::Exp: return num_exp(x);
  case UnaryOp::Log: return num_log(x);
  case UnaryOp::Sin: return num_sin(x);
  case UnaryOp::Cos: return num_cos(x);
  case UnaryOp::Tan: return num_tan(x);
  case UnaryOp::Asin: return num_asin(x);
  case UnaryOp::Acos: return num_acos(x);
  case UnaryOp::Atan: return num_atan(x);
  case UnaryOp::Abs: return num_abs(x); // of a real number only, as MIT
  case UnaryOp::Magnitude: return num_magnitude(x);
  case UnaryOp::Square: return num_mul(x, x);
  case UnaryOp::Cube: return num_mul(x, num_mul(x, x));
  case UnaryOp::ZeroP: return Value::boolean(num_is_zero(x));
  }
  SICM_ASSERT(false);
  return x;
}

Value number_binary(BinaryOp op, Value a, Value b) {
  switch (op) {
  case BinaryOp::Add: return num_add(a, b);
  case BinaryOp::Sub: return num_sub(a, b);
  case BinaryOp::Mul: return num_mul(a, b);
  case BinaryOp::Div: return num_div(a, b);
  case BinaryOp::Expt: return num_expt(a, b);
  case BinaryOp::Atan2: return num_atan2(a, b);
  case BinaryOp::Equal: return Value::boolean(num_equal(a, b));
  }
  SICM_ASSERT(false);
  return a;
}

// scmutils' identities: exact 0 added to, and exact 1 multiplying, any
// arithmetic value leave it unchanged, whatever its type. Returns true and
// sets *out when one applies.
bool identity_shortcut(BinaryOp op, Value a, Value b, const ArithType *ta, const ArithType *tb,
                       Value *out) {
  switch (op) {
  case BinaryOp::Add:
    if (tb && is_exact_zero(a)) return *out = b, true;
    if (ta && is_exact_zero(b)) return *out = a, true;
    return false;
  case BinaryOp::Sub:
    if (ta && is_exact_zero(b)) return *out = a, true;
    if (tb && is_exact_zero(a)) return *out = g_neg(b), true;
    return false;
  case BinaryOp::Mul:
    if (tb && is_exact_one(a)) return *out = b, true;
    if (ta && is_exact_one(b)) return *out = a, true;
    return false;
  case BinaryOp::Div:
    if (ta && is_exact_one(b)) return *out = a, true;
    return false;
  default: return false;
  }
}

} // namespace

// ---- dispatch ---------------------------------------------------------------------------------

Value g_unary(UnaryOp op, Value x) {
  const ArithType *t = arith_type_of(x);
  return t ? t->unary(op, x) : number_unary(op, x);
}

Value g_binary(BinaryOp op, Value a, Value b) {
  if (is_number(a) && is_number(b)) return number_binary(op, a, b);
  const ArithType *ta = arith_type_of(a), *tb = arith_type_of(b);
  Value out;
  if (identity_shortcut(op, a, b, ta, tb, &out)) return out;
  const ArithType *t = higher_rank(ta, tb);
  return t ? t->binary(op, a, b) : number_binary(op, a, b);
}

Value g_expt(Value base, Value exponent) {
  if (is_number(base) && is_number(exponent)) return num_expt(base, exponent);
  return g_binary(BinaryOp::Expt, base, exponent);
}

Value g_square(Value x) {
  return is_number(x) ? num_mul(x, x) : g_unary(UnaryOp::Square, x);
}

bool g_zero_p(Value x) {
  if (is_number(x)) return num_is_zero(x);
  return g_unary(UnaryOp::ZeroP, x).truthy();
}

bool g_equal(Value a, Value b) {
  if (is_number(a) && is_number(b)) return num_equal(a, b);
  return g_binary(BinaryOp::Equal, a, b).truthy();
}

// ---- the symbolic type ------------------------------------------------------------------------
//
// Symbols used as numbers and expressions: every operation builds an
// expression through symbolic_apply. Tests (= and zero?) simplify first, so
// they are exact for what the simplifier brings to a canonical form (rational
// functions of kernels) and answer "not equal" otherwise.

namespace {

Op symbolic_op(UnaryOp op) {
  switch (op) {
  case UnaryOp::Sqrt: return Op::Sqrt;
  case UnaryOp::Exp: return Op::Exp;
  case UnaryOp::Log: return Op::Log;
  case UnaryOp::Sin: return Op::Sin;
  case UnaryOp::Cos: return Op::Cos;
  case UnaryOp::Tan: return Op::Tan;
  case UnaryOp::Asin: return Op::Asin;
  case UnaryOp::Acos: return Op::Acos;
  case UnaryOp::Atan: return Op::Atan;
  default: return Op::Abs; // Abs and Magnitude: sicm's numbers are real
  }
}

Value apply2(Op op, Value a, Value b) {
  Value args[2] = {a, b};
  return symbolic_apply(op, args, 2);
}

bool simplifies_to_zero(Value x) {
  Value s = simplify_value(x);
  return is_number(s) && num_is_zero(s);
}

Value symbolic_unary(UnaryOp op, Value x) {
  switch (op) {
  case UnaryOp::Neg: return apply2(Op::Mul, Value::fixnum(-1), x);
  case UnaryOp::Invert: return apply2(Op::Div, Value::fixnum(1), x);
  case UnaryOp::Square: return apply2(Op::Expt, x, Value::fixnum(2));
  case UnaryOp::Cube: return apply2(Op::Expt, x, Value::fixnum(3));
  case UnaryOp::ZeroP: return Value::boolean(simplifies_to_zero(x));
  default: return symbolic_apply(symbolic_op(op), &x, 1);
  }
}

Value symbolic_binary(BinaryOp op, Value a, Value b) {
  if (!is_number(a) && !is_symbolic(a)) arith_wrong_type(op, a, 1);
  if (!is_number(b) && !is_symbolic(b)) arith_wrong_type(op, b, 2);
  switch (op) {
  case BinaryOp::Add: return apply2(Op::Add, a, b);
  case BinaryOp::Sub: return apply2(Op::Sub, a, b);
  case BinaryOp::Mul: return apply2(Op::Mul, a, b);
  case BinaryOp::Div: return apply2(Op::Div, a, b);
  case BinaryOp::Expt: return apply2(Op::Expt, a, b);
  case BinaryOp::Atan2: return apply2(Op::Atan, a, b);
  case BinaryOp::Equal: return Value::boolean(simplifies_to_zero(apply2(Op::Sub, a, b)));
  }
  SICM_ASSERT(false);
  return a;
}

const ArithType kSymbolicType = {"symbolic", 10, is_symbolic, symbolic_unary, symbolic_binary};

} // namespace

void register_symbolic_arith() {
  register_arith_type(&kSymbolicType);
}

// ---- primitives -------------------------------------------------------------------------------

namespace {

// The argument of a one-argument (+ x) or (* x): returned as it is, if it is
// something arithmetic can take.
Value lone_argument(Value x, BinaryOp op) {
  if (!is_arithmetic(x)) arith_wrong_type(op, x, 1);
  return x;
}

// Left folds, so that the accumulated value is the first argument of the
// binary operation in error messages, as in MIT.
Value prim_add(Value *args, int n) {
  if (n == 0) return Value::fixnum(0);
  Value acc = lone_argument(args[0], BinaryOp::Add);
  for (int i = 1; i < n; ++i)
    acc = g_add(acc, args[i]);
  return acc;
}

Value prim_mul(Value *args, int n) {
  if (n == 0) return Value::fixnum(1);
  Value acc = lone_argument(args[0], BinaryOp::Mul);
  for (int i = 1; i < n; ++i)
    acc = g_mul(acc, args[i]);
  return acc;
}

Value prim_sub(Value *args, int n) {
  if (n == 1) return g_neg(args[0]);
  Value acc = args[0];
  for (int i = 1; i < n; ++i)
    acc = g_sub(acc, args[i]);
  return acc;
}

Value prim_div(Value *args, int n) {
  if (n == 1) return g_unary(UnaryOp::Invert, args[0]);
  Value acc = args[0];
  for (int i = 1; i < n; ++i)
    acc = g_div(acc, args[i]);
  return acc;
}

// (= a b c): pairwise, stopping at the first unequal pair.
Value prim_equal(Value *args, int n) {
  if (n == 1) lone_argument(args[0], BinaryOp::Equal);
  for (int i = 0; i + 1 < n; ++i)
    if (!g_equal(args[i], args[i + 1])) return Value::boolean(false);
  return Value::boolean(true);
}

template <UnaryOp Op> Value prim_unary(Value *args, int) {
  return g_unary(Op, args[0]);
}

Value prim_zero_p(Value *args, int) {
  return Value::boolean(g_zero_p(args[0]));
}

Value prim_atan(Value *args, int n) {
  return n == 2 ? g_binary(BinaryOp::Atan2, args[0], args[1]) : g_unary(UnaryOp::Atan, args[0]);
}

Value prim_expt(Value *args, int) {
  return g_expt(args[0], args[1]);
}

Value prim_one_plus(Value *args, int) {
  return g_add(args[0], Value::fixnum(1));
}

Value prim_minus_one_plus(Value *args, int) {
  return g_sub(args[0], Value::fixnum(1));
}

Value prim_compose(Value *args, int n) {
  for (int i = 0; i < n; ++i)
    if (!is_procedure(args[i]) && !args[i].is(Tag::Structure)) // structures apply componentwise
      wrong_type(args[i], i + 1, "compose");
  return compose_procedures(args, static_cast<size_t>(n));
}

struct GenericSpec {
  const char *name;
  int min_args, max_args;
  PrimFn fn;
};

const GenericSpec kGenericPrimitives[] = {
    {"+", 0, kVariadic, prim_add},
    {"*", 0, kVariadic, prim_mul},
    {"-", 1, kVariadic, prim_sub},
    {"/", 1, kVariadic, prim_div},
    {"=", 1, kVariadic, prim_equal},
    {"zero?", 1, 1, prim_zero_p},
    {"negate", 1, 1, prim_unary<UnaryOp::Neg>},
    {"invert", 1, 1, prim_unary<UnaryOp::Invert>},
    {"square", 1, 1, prim_unary<UnaryOp::Square>},
    {"cube", 1, 1, prim_unary<UnaryOp::Cube>},
    {"expt", 2, 2, prim_expt},
    {"sqrt", 1, 1, prim_unary<UnaryOp::Sqrt>},
    {"exp", 1, 1, prim_unary<UnaryOp::Exp>},
    {"log", 1, 1, prim_unary<UnaryOp::Log>},
    {"sin", 1, 1, prim_unary<UnaryOp::Sin>},
    {"cos", 1, 1, prim_unary<UnaryOp::Cos>},
    {"tan", 1, 1, prim_unary<UnaryOp::Tan>},
    {"asin", 1, 1, prim_unary<UnaryOp::Asin>},
    {"acos", 1, 1, prim_unary<UnaryOp::Acos>},
    {"atan", 1, 2, prim_atan},
    {"abs", 1, 1, prim_unary<UnaryOp::Abs>},
    {"magnitude", 1, 1, prim_unary<UnaryOp::Magnitude>},
    {"1+", 1, 1, prim_one_plus},
    {"-1+", 1, 1, prim_minus_one_plus},
    {"1-", 1, 1, prim_minus_one_plus},
    {"compose", 0, kVariadic, prim_compose},
};

} // namespace

void install_generic_primitives() {
  register_symbolic_arith();
  register_structure_arith();
  register_function_arith();
  // Generic arithmetic: every row computes from its arguments alone.
  for (const GenericSpec &p : kGenericPrimitives)
    define_primitive(p.name, p.min_args, p.max_args, Stage::Pure, p.fn);
  install_differential_comparisons();
  install_structure_primitives();
}

} // namespace sicm

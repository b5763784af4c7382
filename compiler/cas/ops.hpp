// The algebraic operators (cas/ops.def) as an enum, with their Scheme names,
// arities and C names: shared by the expression DAG, the simplifier, the
// generic arithmetic, the partial evaluator and the C emitters.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sicm {

enum class Op : uint8_t {
#define SICM_OP(name, scheme, arity, c) name,
#include "cas/ops.def"
#undef SICM_OP
};

struct OpInfo {
  const char *scheme_name;
  int arity; // -1: n-ary
  const char *c_name;
};
const OpInfo &op_info(Op op);

// Every operator's OpInfo, in the order of Op.
const OpInfo *op_table(size_t *count);

} // namespace sicm

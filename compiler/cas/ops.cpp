// The table of the algebraic operators (see ops.hpp).
#include "cas/ops.hpp"

#include <iterator>

namespace sicm {

namespace {

constexpr OpInfo kOpInfo[] = {
#define SICM_OP(name, scheme, arity, c) {scheme, arity, c},
#include "cas/ops.def"
#undef SICM_OP
};

} // namespace

const OpInfo &op_info(Op op) {
  return kOpInfo[static_cast<size_t>(op)];
}

const OpInfo *op_table(size_t *count) {
  *count = std::size(kOpInfo);
  return kOpInfo;
}

} // namespace sicm

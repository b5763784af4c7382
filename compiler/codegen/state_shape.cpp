// States as kernels take and give them (see state_shape.hpp).
#include "codegen/state_shape.hpp"

#include "algebra/generic.hpp"
#include "algebra/structure.hpp"

namespace sicm {

Value *container_items(Value v, size_t *len) {
  if (is_structure(v)) {
    *len = as_structure(v)->len;
    return as_structure(v)->items;
  }
  if (v.is(Tag::Vector)) {
    *len = v.vector()->len;
    return v.vector()->items;
  }
  return nullptr;
}

void state_leaves(Value v, gcvec<Value> &out) {
  size_t len;
  Value *items = container_items(v, &len);
  if (!items) {
    out.push_back(v);
    return;
  }
  for (size_t i = 0; i < len; ++i)
    state_leaves(items[i], out);
}

namespace {
void leaf_paths(Value v, const std::string &indices, const std::string &root,
                std::vector<std::string> &out) {
  size_t len;
  Value *items = container_items(v, &len);
  if (!items) {
    out.push_back(indices.empty() ? root : "(ref " + root + indices + ")");
    return;
  }
  for (size_t i = 0; i < len; ++i)
    leaf_paths(items[i], indices + " " + std::to_string(i), root, out);
}
} // namespace

std::vector<std::string> state_leaf_paths(Value v, const std::string &root) {
  std::vector<std::string> out;
  leaf_paths(v, "", root, out);
  return out;
}

size_t state_dimension(Value v) {
  gcvec<Value> leaves;
  state_leaves(v, leaves);
  return leaves.size();
}

Value state_like(Value shape, const Value *&leaves, PartFn part) {
  size_t len;
  Value *items = container_items(shape, &len);
  if (!items) return *leaves++;
  gcvec<Value> parts;
  for (size_t i = 0; i < len; ++i)
    parts.push_back(part(items[i], leaves));
  if (is_structure(shape))
    return make_structure_from(as_structure(shape)->up, parts.data(), parts.size());
  Value v = make_vector(parts.size(), Value::fixnum(0));
  for (size_t i = 0; i < parts.size(); ++i)
    v.vector()->items[i] = parts[i];
  return v;
}

namespace {
Value state_part(Value shape, const Value *&leaves) {
  return state_like(shape, leaves, state_part);
}
} // namespace

Value state_from_leaves(Value shape, const gcvec<Value> &leaves) {
  const Value *p = leaves.data();
  return state_part(shape, p);
}

bool derivative_leaves(Value d, Value shape, gcvec<Value> &out, bool (*is_leaf)(Value)) {
  size_t n, m;
  Value *shape_items = container_items(shape, &n);
  if (!shape_items) {
    if (!is_leaf(d)) return false;
    out.push_back(d);
    return true;
  }
  if (is_exact_zero(d)) {
    for (size_t i = state_dimension(shape); i > 0; --i)
      out.push_back(d);
    return true;
  }
  Value *d_items = container_items(d, &m);
  if (!d_items || m != n) return false;
  for (size_t i = 0; i < n; ++i)
    if (!derivative_leaves(d_items[i], shape_items[i], out, is_leaf)) return false;
  return true;
}

} // namespace sicm

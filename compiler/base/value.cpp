// Symbols, strings, vectors and list helpers.
#include "base/value.hpp"

#include <algorithm>
#include <string>
#include <unordered_map>

namespace sicm {

namespace {
// Symbols are never collected: the table holds them in uncollectable memory,
// which the collector scans (their global bindings live inside them).
std::unordered_map<std::string, Symbol *> &symbol_table() {
  static auto *table = new std::unordered_map<std::string, Symbol *>();
  return *table;
}

Symbol *new_symbol(std::string_view name) {
  void *mem = GC_MALLOC_UNCOLLECTABLE(sizeof(Symbol));
  if (!mem) throw std::bad_alloc();
  Symbol *s = new (mem) Symbol();
  s->name = std::string(name);
  return s;
}
} // namespace

Value intern(std::string_view name) {
  auto &table = symbol_table();
  auto it = table.find(std::string(name));
  if (it != table.end()) return Value::object(Tag::Symbol, it->second);
  Symbol *s = new_symbol(name);
  table.emplace(s->name, s);
  return Value::object(Tag::Symbol, s);
}

std::vector<std::string> bound_global_names() {
  std::vector<std::string> names;
  for (auto &[name, s] : symbol_table())
    if (s->bound) names.push_back(name);
  std::sort(names.begin(), names.end());
  return names;
}

Value make_uninterned_symbol(std::string_view name) {
  Symbol *s = new_symbol(name);
  s->uninterned = true;
  return Value::object(Tag::Symbol, s);
}

Value make_string(std::string_view s) {
  return Value::object(Tag::String, gc_new<String>(String{gc_strdup(s), s.size()}));
}

namespace {
ValueWriter g_value_writer = nullptr;
} // namespace

std::string written(Value v) {
  return g_value_writer ? g_value_writer(v) : "#[value]";
}

void set_value_writer(ValueWriter writer) {
  g_value_writer = writer;
}

Value make_vector(size_t n, Value fill) {
  Value *items = static_cast<Value *>(GC_MALLOC(sizeof(Value) * (n ? n : 1)));
  if (!items) throw std::bad_alloc();
  for (size_t i = 0; i < n; ++i)
    items[i] = fill;
  return Value::object(Tag::Vector, gc_new<Vector>(Vector{items, n}));
}

long list_length(Value v) {
  // Floyd's cycle detection: a circular list is not a proper list.
  long n = 0;
  Value slow = v;
  while (is_pair(v)) {
    v = cdr(v);
    ++n;
    if (!is_pair(v)) break;
    v = cdr(v);
    ++n;
    slow = cdr(slow);
    if (eq(v, slow)) return -1;
  }
  return is_null(v) ? n : -1;
}

Value list_from(const Value *items, size_t n, Value tail) {
  Value result = tail;
  for (size_t i = n; i-- > 0;)
    result = cons(items[i], result);
  return result;
}

gcvec<Value> list_to_vector(Value list) {
  gcvec<Value> out;
  for (; is_pair(list); list = cdr(list))
    out.push_back(car(list));
  return out;
}

} // namespace sicm

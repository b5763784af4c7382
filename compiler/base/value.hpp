// Scheme values: a 16-byte tagged word, and the heap objects it may point to.
//
// A Value is a tag plus a payload. Immediates (fixnums, flonums, characters,
// booleans, the empty list, ...) live in the payload; everything else is a
// pointer to an object allocated on the garbage-collected heap (Boehm GC).
// The tag alone says what the pointee is, so objects carry no header.
//
// Memory: every heap object is allocated with gc_new<T>() and never freed by
// hand. The collector is conservative, so a Value on the C++ stack, in a
// GC-allocated object, or in a gcvec keeps its object alive. Containers that
// hold Values must use gc_allocator (see gcvec) and must never keep Values in
// malloc'd memory (std::vector<Value>, std::string buffers, exceptions).
#pragma once

#define GC_THREADS
#include <gc/gc.h>
#include <gc/gc_allocator.h>

#include <cstdint>
#include <cstring>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/error.hpp"
#include "base/srcloc.hpp"

namespace sicm {

template <class T> using gcvec = std::vector<T, gc_allocator<T>>;

enum class Tag : uint8_t {
  // immediates
  Nil,         // the empty list ()
  Bool,        // #t / #f
  Unspecified, // the value of set!, display, ... (never printed at top level)
  Default,     // #!default: a missing #!optional argument
  Unassigned,  // the contents of a letrec/internal-define variable before its init
  Eof,         // end of file object
  Char,        // a Unicode code point
  Fixnum,      // exact integer that fits in int64_t
  Flonum,      // IEEE double
  Expr,        // a symbolic expression: an id (payload i) into the algebra's DAG
  // heap objects
  Bignum,    // exact integer outside int64_t (GMP mpz)
  Ratnum,    // exact non-integer rational (GMP mpq), always in lowest terms
  Recnum,    // a complex number that is not real: two real parts (base/number.hpp)
  Symbol,    // interned
  String,    // mutable byte string (UTF-8)
  Pair,      // cons cell
  Vector,    // #( ... )
  Closure,   // a lambda with its environment
  Primitive, // a procedure written in C++
  Promise,   // delay / cons-stream
  Values,    // multiple return values
  Record,    // an instance of a define-record-type type
  RecordType,
  Environment, // a first-class environment (the-environment)
  Parameter,   // reserved for later issues
  Structure,   // an up or down tuple (algebra/structure.hpp)
  Matrix,      // a matrix (algebra/structure.hpp)
  Opaque,      // extension objects of later layers (operators, series, plots, ...)
};

struct Bignum;
struct Ratnum;
struct Symbol;
struct String;
struct Pair;
struct Vector;
struct Closure;
struct Primitive;
struct Promise;
struct MultipleValues;
struct Record;
struct RecordType;

struct Value {
  Tag tag = Tag::Unspecified;
  union {
    int64_t i;
    double d;
    uint32_t ch;
    bool b;
    void *p;
  };

  Value() : i(0) {}
  static Value fixnum(int64_t v) {
    Value x;
    x.tag = Tag::Fixnum;
    x.i = v;
    return x;
  }
  static Value flonum(double v) {
    Value x;
    x.tag = Tag::Flonum;
    x.d = v;
    return x;
  }
  static Value boolean(bool v) {
    Value x;
    x.tag = Tag::Bool;
    x.i = 0;
    x.b = v;
    return x;
  }
  static Value character(uint32_t c) {
    Value x;
    x.tag = Tag::Char;
    x.i = 0;
    x.ch = c;
    return x;
  }
  static Value nil() {
    Value x;
    x.tag = Tag::Nil;
    return x;
  }
  static Value unspecified() { return Value(); }
  static Value default_object() {
    Value x;
    x.tag = Tag::Default;
    return x;
  }
  static Value eof() {
    Value x;
    x.tag = Tag::Eof;
    return x;
  }
  static Value object(Tag t, const void *ptr) {
    Value x;
    x.tag = t;
    x.p = const_cast<void *>(ptr);
    return x;
  }

  bool is(Tag t) const { return tag == t; }
  bool is_false() const { return tag == Tag::Bool && !b; }
  bool truthy() const { return !is_false(); }
  bool is_heap() const { return tag >= Tag::Bignum; }

  template <class T> T *as() const { return static_cast<T *>(p); }
  Pair *pair() const { return static_cast<Pair *>(p); }
  Symbol *symbol() const { return static_cast<Symbol *>(p); }
  String *string() const { return static_cast<String *>(p); }
  Vector *vector() const { return static_cast<Vector *>(p); }
};

// eq?: same tag and same payload bits.
inline bool eq(Value a, Value b) {
  return a.tag == b.tag && a.i == b.i;
}

// Allocate a T on the collected heap. T's destructor never runs.
template <class T, class... Args> T *gc_new(Args &&...args) {
  void *mem = GC_MALLOC(sizeof(T));
  if (!mem) throw std::bad_alloc();
  return new (mem) T(std::forward<Args>(args)...);
}

// A GC-allocated, NUL-terminated copy of s (pointer-free memory).
inline char *gc_strdup(std::string_view s) {
  char *mem = static_cast<char *>(GC_MALLOC_ATOMIC(s.size() + 1));
  if (!mem) throw std::bad_alloc();
  std::memcpy(mem, s.data(), s.size());
  mem[s.size()] = '\0';
  return mem;
}

// The heap's clock: frames made so far. Frames, pairs and vectors record it
// when made (their serial), so sicm build can tell what a procedure made
// from what existed before it was called. It wraps; compare with made_since.
extern uint32_t g_frame_serial;

// Was an object of this serial made after the clock read `start`? (Modulo
// 2^32: right unless 2^32 frames have been made since.)
inline bool made_since(uint32_t serial, uint32_t start) {
  return serial - start - 1 < g_frame_serial - start;
}

struct Pair {
  Value car, cdr;
  SrcLoc loc; // where the reader saw this pair's car (unknown for built pairs)
  uint32_t serial = g_frame_serial; // in the padding: no larger
};
static_assert(sizeof(Pair) == 48, "a pair's serial must fit in its padding");

struct Symbol {
  std::string name; // symbols are never collected, so std::string is fine
  Value global;     // the global binding, valid when `bound`
  bool bound = false;
  bool uninterned = false; // made by generate-uninterned-symbol
  int special_form = -1;   // index into the special-form table, or -1
};

struct String {
  char *data; // GC atomic memory, NUL-terminated
  size_t len;
};

struct Vector {
  Value *items; // GC memory
  size_t len;
  uint32_t serial = g_frame_serial;
};

// SICM's up and down tuples and matrices (their operations are
// algebra/structure.hpp's).
struct Structure {
  bool up;
  Value *items; // GC memory, `len` components
  size_t len;
};

struct Matrix {
  size_t rows, cols;
  Value *items; // GC memory, row-major: entry (i, j) is items[i * cols + j]
};

struct Promise {
  bool forced;
  Value value;       // the value once forced
  struct Node *expr; // the delayed expression, until forced
  struct Frame *env;
};

struct MultipleValues {
  Value *items;
  size_t len;
};

struct RecordType {
  Symbol *name;
  gcvec<Symbol *> fields;
};

struct Record {
  RecordType *type;
  Value *fields;
};

// Extension objects for later layers: a tagged pointer with a kind name, a
// printer and, for objects that act as procedures (sums of functions,
// operators such as D), an apply function.
struct OpaqueKind {
  const char *name;
  void (*write)(std::string &out, const void *obj, bool display);
  Value (*apply)(void *obj, Value *args, int nargs); // null: not applicable
};
struct Opaque {
  const OpaqueKind *kind;
  void *obj;
};

// ---- writing values in messages --------------------------------------------

// A value as MIT Scheme writes it, for the messages of the layers below
// print/ (argument errors, the analyzer's syntax errors). print/ installs
// its writer (write_string) when the interpreter starts; before that a
// value is written as #[value].
std::string written(Value v);
using ValueWriter = std::string (*)(Value v);
void set_value_writer(ValueWriter writer);

// ---- constructors --------------------------------------------------------

Value intern(std::string_view name);
// Names of every interned symbol that has a global binding, sorted.
std::vector<std::string> bound_global_names();
Value make_uninterned_symbol(std::string_view name);
Value make_string(std::string_view s);
Value make_vector(size_t n, Value fill);
inline Value cons(Value a, Value d, SrcLoc loc = {}) {
  return Value::object(Tag::Pair, gc_new<Pair>(Pair{a, d, loc}));
}

// ---- list helpers --------------------------------------------------------

inline Value car(Value v) {
  return v.pair()->car;
}
inline Value cdr(Value v) {
  return v.pair()->cdr;
}
inline bool is_pair(Value v) {
  return v.tag == Tag::Pair;
}
inline bool is_null(Value v) {
  return v.tag == Tag::Nil;
}
inline bool is_symbol(Value v) {
  return v.tag == Tag::Symbol;
}
inline bool is_string(Value v) {
  return v.tag == Tag::String;
}

// Length of a proper list, or -1 if v is improper or circular.
long list_length(Value v);
Value list_from(const Value *items, size_t n, Value tail = Value::nil());
inline Value list(std::initializer_list<Value> xs) {
  return list_from(xs.begin(), xs.size());
}
gcvec<Value> list_to_vector(Value list); // caller checks properness first

inline std::string_view string_view(Value s) {
  return std::string_view(s.string()->data, s.string()->len);
}
inline const std::string &symbol_name(Value s) {
  return s.symbol()->name;
}

} // namespace sicm

// Fuzz target: the reader. Any bytes are read as a source file, every datum in turn.
//
// Property: reading never crashes, hangs or trips a sanitizer; malformed
// input ends in a sicm::Error (a Syntax error with a position), the only
// exception the reader may throw. Each datum read is also written with
// `write` and read back, and the result must print the same: the printer
// and the reader agree on every datum the reader can produce.
#include <string>
#include <vector>

#include "base/srcloc.hpp"
#include "base/value.hpp"
#include "common.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

// Inputs longer than this are not tried: the reader is linear, and short
// inputs reach every path.
constexpr size_t kMaxInput = 4096;

// Data with no readable written form: the end-of-file object (#!eof)
// writes as #[eof], in MIT Scheme too.
bool has_unwritable_datum(Value d, int depth = 0) {
  if (depth > kMaxReadDepth) return false;
  if (d.is(Tag::Eof)) return true;
  if (d.is(Tag::Pair)) {
    for (; d.is(Tag::Pair); d = d.pair()->cdr)
      if (has_unwritable_datum(d.pair()->car, depth + 1)) return true;
    return has_unwritable_datum(d, depth + 1);
  }
  if (d.is(Tag::Vector))
    for (size_t i = 0; i < d.vector()->len; ++i)
      if (has_unwritable_datum(d.vector()->items[i], depth + 1)) return true;
  return false;
}

// Written text that re-reads to itself: write(read(write(d))) == write(d),
// for every datum of the input at once (one source registered per input:
// the registry keeps every text for the life of the process).
void check_round_trip(const gcvec<ReadForm> &forms) {
  std::vector<std::string> once;
  std::string text;
  for (const ReadForm &f : forms) {
    if (has_unwritable_datum(f.datum)) continue;
    once.push_back(write_string(f.datum));
    text += once.back() + "\n";
  }
  if (once.empty()) return;
  gcvec<ReadForm> again;
  try {
    again = read_all(register_source("<fuzz reader: re-read>", text));
  } catch (const Error &e) {
    fuzz::fail("the written form of the data does not read back:\n  written: " + text +
               "\n  error: " + e.what());
  }
  if (again.size() != once.size())
    fuzz::fail("the written forms of " + std::to_string(once.size()) + " data read back as " +
               std::to_string(again.size()) + " data:\n  written: " + text);
  for (size_t i = 0; i < once.size(); ++i) {
    std::string twice = write_string(again[i].datum);
    if (twice != once[i])
      fuzz::fail("a datum written, read back and written again changes:\n  first:  " + once[i] +
                 "\n  second: " + twice);
  }
}

} // namespace

void fuzz_setup() {}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > kMaxInput) return -1;
  uint32_t file =
      register_source("<fuzz reader>", std::string(reinterpret_cast<const char *>(data), size));
  gcvec<ReadForm> forms;
  try {
    forms = read_all(file);
  } catch (const Error &) {
    return 0; // malformed input, reported as it should be
  }
  check_round_trip(forms);
  return 0;
}

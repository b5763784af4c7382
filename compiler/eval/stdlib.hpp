// The standard library's sources, embedded in the binary at build time
// (scripts/embed-stdlib generates the definition from stdlib/*.sicm).
#pragma once

namespace sicm {

struct EmbeddedSource {
  const char *name; // file name under stdlib/; null ends the table
  const char *text;
};

// The table of embedded sources, in load order, ending with {nullptr, nullptr}.
const EmbeddedSource *embedded_stdlib();

} // namespace sicm

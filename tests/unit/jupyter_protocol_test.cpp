// The framing of `sicm repl --kernel` (driver/jupyter_protocol.hpp): requests
// read by their byte count, whatever they hold, and JSON text that any JSON
// reader takes back unchanged.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "driver/jupyter_protocol.hpp"

using namespace sicm;

namespace {

// A FILE* reading the given bytes.
std::FILE *reading(const std::string &bytes) {
  std::FILE *f = std::tmpfile();
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::rewind(f);
  return f;
}

TEST(JupyterProtocol, RequestsAreReadByTheirLength) {
  std::string cell = "(display \"a\nb\")\n(car '())"; // newlines inside the text
  std::FILE *in =
      reading("execute " + std::to_string(cell.size()) + " In[3]\n" + cell + "complete 4\nLagr");
  JupyterRequest r = read_jupyter_request(in);
  EXPECT_EQ(r.verb, "execute");
  EXPECT_EQ(r.text, cell);
  EXPECT_EQ(r.name, "In[3]");
  r = read_jupyter_request(in);
  EXPECT_EQ(r.verb, "complete");
  EXPECT_EQ(r.text, "Lagr");
  EXPECT_EQ(r.name, "");
  EXPECT_EQ(read_jupyter_request(in).verb, ""); // end of input
  std::fclose(in);
}

TEST(JupyterProtocol, MalformedHeadersEndTheSession) {
  for (const char *bad :
       {"execute\n", "execute x\n", "execute 10\nshort", "execute 99999999999\n"}) {
    std::FILE *in = reading(bad);
    EXPECT_EQ(read_jupyter_request(in).verb, "") << bad;
    std::fclose(in);
  }
}

TEST(JupyterProtocol, JsonStringsEscapeWhatJsonRequires) {
  EXPECT_EQ(json_string("a\"b\\c\nd\te\x01"), "\"a\\\"b\\\\c\\nd\\te\\u0001\"");
  EXPECT_EQ(json_string("θ̇"), "\"θ̇\""); // UTF-8 passes through
  EXPECT_EQ(json_strings({"x", "y"}), "[\"x\",\"y\"]");
  EXPECT_EQ(json_object({{"type", json_string("done")}, {"line", "3"}}),
            "{\"type\":\"done\",\"line\":3}");
}

} // namespace

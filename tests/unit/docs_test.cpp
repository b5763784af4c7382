// docs/reference.md and the tests of its examples (tests/docs/) are generated
// by scripts/gen-reference from the doc comments in stdlib/*.sicm and
// stdlib/doc/*.txt, and the tutorial's snippets from docs/tutorial.md. These
// tests keep them from drifting: the generated files must be up to date, and
// every primitive of the interpreter must be documented (the script itself
// insists that every definition of the library is). Unit tests run from the
// repository root.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "base/value.hpp"
#include "eval/interp.hpp"

namespace {

struct ScriptRun {
  int status = -1; // exit status, or -1 when the command did not exit normally
  std::string output;
};

// Runs scripts/gen-reference with the given option, collecting stdout and stderr.
ScriptRun gen_reference(const std::string &option) {
  ScriptRun r;
  std::string cmd = "python3 scripts/gen-reference " + option + " 2>&1";
  FILE *p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0)
    r.output.append(buf, n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

bool in_repository_root() {
  return access("scripts/gen-reference", R_OK) == 0 && access("stdlib", R_OK) == 0;
}

TEST(Docs, GeneratedFilesAreUpToDate) {
  ASSERT_TRUE(in_repository_root()) << "run the unit tests from the repository root";
  ScriptRun r = gen_reference("--check");
  EXPECT_EQ(r.status, 0) << "scripts/gen-reference --check:\n"
                         << r.output
                         << "(edit the doc comments, then run `python3 scripts/gen-reference`)";
}

TEST(Docs, EveryPrimitiveIsDocumented) {
  ASSERT_TRUE(in_repository_root()) << "run the unit tests from the repository root";
  ScriptRun r = gen_reference("--list-names");
  ASSERT_EQ(r.status, 0) << r.output;
  std::set<std::string> documented;
  std::istringstream lines(r.output);
  for (std::string name; std::getline(lines, name);)
    if (!name.empty()) documented.insert(name);

  std::vector<std::string> undocumented;
  std::set<std::string> bound;
  for (const std::string &name : sicm::bound_global_names()) {
    bound.insert(name);
    sicm::Symbol *s = sicm::intern(name).symbol();
    // Internal primitives (%exit, ...) are named with a leading %.
    if (s->global.is(sicm::Tag::Primitive) && name[0] != '%' && !documented.count(name))
      undocumented.push_back(name);
  }
  std::string missing;
  for (const std::string &n : undocumented)
    missing += " " + n;
  EXPECT_TRUE(undocumented.empty())
      << "primitives without a doc comment in stdlib/doc/core.txt:" << missing
      << "\n(add ';;;' doc comments, then run `python3 scripts/gen-reference`)";

  std::string unbound;
  for (const std::string &n : documented)
    if (!bound.count(n)) unbound += " " + n;
  EXPECT_TRUE(unbound.empty()) << "documented but not defined:" << unbound;
}

} // namespace

// ARCHITECTURE.md lists every source file of the compiler, the runtime and
// the library (one line each, in its folder's table), so a new file must be
// placed on the map when it is added.
TEST(Docs, ArchitectureListsEverySourceFile) {
  if (!in_repository_root()) GTEST_SKIP() << "not run from the repository root";
  std::ifstream in("ARCHITECTURE.md");
  ASSERT_TRUE(in) << "ARCHITECTURE.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  const std::string map = text.str();
  int checked = 0;
  for (const char *dir : {"compiler", "runtime", "stdlib"}) {
    for (const auto &entry : std::filesystem::recursive_directory_iterator(dir)) {
      const std::string ext = entry.path().extension().string();
      if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".hpp" && ext != ".c" &&
                                       ext != ".h" && ext != ".def" && ext != ".sicm"))
        continue;
      const std::string name = entry.path().filename().string();
      EXPECT_NE(map.find("`" + name + "`"), std::string::npos)
          << entry.path().string() << " is not in ARCHITECTURE.md";
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

// The folders of the compiler are layers, in the order ARCHITECTURE.md lists
// them: no file includes a header of a folder listed after its own.
TEST(Docs, NoFolderIncludesALaterOne) {
  if (!in_repository_root()) GTEST_SKIP() << "not run from the repository root";
  std::ifstream in("ARCHITECTURE.md");
  ASSERT_TRUE(in) << "ARCHITECTURE.md is missing";
  std::vector<std::string> order;
  const std::string heading = "### `compiler/";
  for (std::string line; std::getline(in, line);)
    if (line.rfind(heading, 0) == 0)
      order.push_back(line.substr(heading.size(), line.find('/', heading.size()) - heading.size()));
  ASSERT_GE(order.size(), 8u);
  auto rank = [&](const std::string &folder) -> int {
    for (size_t i = 0; i < order.size(); ++i)
      if (order[i] == folder) return static_cast<int>(i);
    return -1;
  };
  int checked = 0;
  for (const auto &entry : std::filesystem::recursive_directory_iterator("compiler")) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".hpp")) continue;
    std::string folder = entry.path().parent_path().filename().string();
    int own = rank(folder);
    EXPECT_GE(own, 0) << folder << " is not a section of ARCHITECTURE.md";
    std::ifstream file(entry.path());
    for (std::string line; std::getline(file, line);) {
      if (line.rfind("#include \"", 0) != 0) continue;
      std::string included = line.substr(10, line.find('/', 10) - 10);
      int theirs = rank(included);
      EXPECT_FALSE(theirs > own) << entry.path().string() << " includes " << line.substr(9)
                                 << ", of a later layer";
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
}

// The last pass of `sicm build`: the generated C compiled by the system C
// compiler against the runtime (see build_exe.hpp).
#include "driver/build_exe.hpp"

#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "base/error.hpp"
#include "base/temporary_files.hpp"
#include "codegen/jit.hpp"

extern char **environ;

namespace sicm {

namespace {

constexpr int kExitCantCreat = 73; // EX_CANTCREAT

bool exists(const std::string &path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

std::string dir_of(const std::string &path) {
  size_t slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

std::string self_dir() {
  char buf[4096];
  ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  buf[n] = '\0';
  return dir_of(buf);
}

// Where the runtime's headers and library are: beside the executable in the
// build tree, or in the installation prefix.
bool find_runtime(std::string *include_dir, std::string *library) {
  std::string bin = self_dir();
  const std::pair<std::string, std::string> places[] = {
      {bin + "/../runtime/include", bin + "/libsicmrt.a"},
      {bin + "/../include", bin + "/../lib/libsicmrt.a"},
  };
  for (const auto &[inc, lib] : places)
    if (exists(inc + "/sicm/runtime.h") && exists(lib)) {
      *include_dir = inc;
      *library = lib;
      return true;
    }
  return false;
}

std::vector<std::string> compiler_command() {
  std::vector<std::string> words;
  const char *cc = std::getenv("CC");
  std::istringstream in(cc ? cc : "");
  for (std::string w; in >> w;)
    words.push_back(w);
  if (words.empty()) words.push_back("cc");
  return words;
}

// Run argv (stdout and stderr inherited); the exit status, or -1.
int run(const std::vector<std::string> &argv) {
  std::vector<char *> cargv;
  for (const std::string &a : argv)
    cargv.push_back(const_cast<char *>(a.c_str()));
  cargv.push_back(nullptr);
  pid_t pid;
  if (posix_spawnp(&pid, cargv[0], nullptr, nullptr, cargv.data(), environ) != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

} // namespace

int check_output_writable(const BuildOptions &o) {
  const std::string &path = o.output;
  struct stat st;
  int error = 0;
  if (stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode))
      error = EISDIR;
    else if (access(path.c_str(), W_OK) != 0)
      error = errno;
  } else if (errno != ENOENT) {
    error = errno;
  } else if (access(dir_of(path).c_str(), W_OK) != 0) {
    error = errno; // the directory is missing or closed to us
  }
  if (error == 0) return 0;
  std::fprintf(stderr, "sicm: error: cannot write the executable %s: %s\n", path.c_str(),
               std::strerror(error));
  return kExitCantCreat;
}

int compile_executable(const std::string &c, const BuildOptions &o) {
  std::string include_dir, library;
  if (!find_runtime(&include_dir, &library)) {
    std::fprintf(stderr,
                 "sicm: error: cannot find the runtime library (libsicmrt.a and sicm/runtime.h) "
                 "beside %s\n",
                 self_dir().c_str());
    return kExitCantCreat;
  }
  std::string c_path = o.output + ".c";
  bool keep = o.keep_c;
  if (!keep) { // $TMPDIR/sicm-build-XXXXXX.c, made here so no other can take the name
    std::string pattern = temporary_directory() + "/sicm-build-XXXXXX.c";
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    int fd = mkstemps(name.data(), 2);
    if (fd < 0) {
      std::fprintf(stderr, "sicm: error: cannot create a temporary file in %s: %s\n",
                   temporary_directory().c_str(), std::strerror(errno));
      return kExitCantCreat;
    }
    close(fd);
    c_path = name.data();
  }
  // Interrupted or killed (but by SIGKILL) from here on, the C goes too.
  std::optional<RemovedIfInterrupted> removed_if_interrupted;
  if (!keep) removed_if_interrupted.emplace(c_path);
  {
    std::ofstream out(c_path, std::ios::binary);
    out << c;
    if (!out) {
      std::fprintf(stderr, "sicm: error: cannot write %s\n", c_path.c_str());
      return kExitCantCreat;
    }
  }
  std::vector<std::string> argv = compiler_command();
  std::vector<std::string> mpi_flags;
  if (o.mpi) {
    // Open MPI's wrapper compiler adds its headers and libraries to the
    // C compiler the user chose ($CC is passed on as OMPI_CC).
    std::string mpi_library = dir_of(library) + "/libsicmrt_mpi.a";
    if (!exists(mpi_library)) {
      std::fprintf(stderr,
                   "sicm: error: --mpi: this sicm was built without MPI (%s is missing); install "
                   "libopenmpi-dev and rebuild sicm\n",
                   mpi_library.c_str());
      if (!keep) std::remove(c_path.c_str());
      return kExitCantCreat;
    }
    const char *mpicc = std::getenv("SICM_MPICC");
    if (const char *cc = std::getenv("CC")) setenv("OMPI_CC", cc, 0);
    argv = {mpicc && *mpicc ? mpicc : "mpicc"};
    mpi_flags = {"-DSICM_MPI", mpi_library};
  }
  // The generated C never needs to shadow a name: a declaration that hides a
  // hoisted variable once made a built program print 0. where sicm run
  // printed the value. -Werror=shadow makes such a bug fail the build.
  // -ffp-contract=off: no multiply and add fused into one rounding, as in
  // sicm run's kernels, JIT'ed or interpreted (codegen/kernel_interpreter.hpp).
  argv.insert(argv.end(), {"-std=c11", "-Werror=shadow", "-ffp-contract=off", o.opt_level, "-o",
                           o.output, c_path, "-I" + include_dir});
  argv.insert(argv.end(), mpi_flags.begin(), mpi_flags.end());
  argv.insert(argv.end(), {library, "-lsundials_cvode", "-lsundials_nvecserial", "-lgsl",
                           "-lgslcblas", "-lm", "-lpthread"});
  std::vector<std::string> sanitize = sanitizer_flags();
  argv.insert(argv.begin() + 1, sanitize.begin(), sanitize.end());
  int status = run(argv);
  if (!keep) std::remove(c_path.c_str());
  if (status != 0) {
    std::fprintf(stderr, "sicm: error: the C compiler '%s' %s\n", argv[0].c_str(),
                 status < 0 ? "could not be started" : "failed on the generated C");
    return kExitCantCreat;
  }
  return 0;
}

} // namespace sicm

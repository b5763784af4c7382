# sicm: build, test, install, demo.
#
#   make            build build/sicm and build/libsicmrt.a (and, when mpicc
#                   is found, build/libsicmrt_mpi.a for sicm build --mpi)
#   make check      install missing Debian packages, build, run every test
#   make demo       install missing Debian packages, build, compile an example
#                   scene with sicm build and run it (writes its SVG)
#   make stability  run the hard cases of tests/stability/ at full size, built,
#                   and write docs/stability.md
#   make accuracy   work-precision diagrams of four scenes (sicm bench), into
#                   docs/accuracy.md
#   make examples   build every figure scene at full size with sicm build,
#                   run it, and write its plot into build/figures
#   make fuzz-differential  random programs run and built, compared byte for
#                   byte (SEED=1 COUNT=500 JOBS=1; fuzz/README.md)
#   make jupyter    install the Jupyter kernel `sicm` (and ipykernel) where the
#                   jupyter on PATH looks: the active virtual environment, else
#                   a project one, build/jupyter-venv (jupyter/install says how)
#   make install    install sicm under $(PREFIX)
#   make clean
#
# Variables: WERROR=1 adds -Werror (CI), UPDATE=1 makes `make check` rewrite
# expectations for review, SANITIZE=1 builds with ASan and UBSan.

PREFIX   ?= /usr/local
BUILD    ?= build
CXX      ?= g++
CC       ?= gcc

# GCC's sanitizer instrumentation makes -Wmaybe-uninitialized report false
# positives inside libstdc++'s <regex>, so SANITIZE=1 turns that one off.
WARN      := -Wall -Wextra $(if $(WERROR),-Werror) $(if $(SANITIZE),-Wno-maybe-uninitialized)
OPT       ?= -O2
comma     := ,
SANFLAGS  := $(if $(SANITIZE),-fsanitize=address$(comma)undefined -fno-omit-frame-pointer)
# The generated C (JIT kernels, `sicm build` executables) is compiled with the
# same flags, so that a sanitized sicm loads sanitized kernels and a sanitized
# libsicmrt.a is linked with its sanitizer runtimes.
SANDEF    := $(if $(SANITIZE),-DSICM_SANITIZE_FLAGS='"$(SANFLAGS)"')
CPPFLAGS  := -Icompiler -Iruntime/include -MMD -MP
CXXFLAGS  := -std=c++20 $(OPT) -g $(WARN) $(SANFLAGS) $(SANDEF)
CFLAGS    := -std=c11 $(OPT) -g $(WARN) $(SANFLAGS)
LDFLAGS   := $(SANFLAGS)
# The MPI wrapper compiler, for libsicmrt_mpi.a (sicm build --mpi); empty
# when Open MPI's development files are not installed, and then no MPI.
MPICC    ?= $(shell command -v mpicc 2>/dev/null)
LIBS      := -lflint -lgc -lgmp -lreadline -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -lm -lpthread -ldl

# ---- sources, per component --------------------------------------------
COMPILER_SRCS := $(wildcard compiler/*.cpp compiler/*/*.cpp)
RUNTIME_SRCS  := $(wildcard runtime/src/*.c)
# The runtime's C++17 files (Eigen): C functions implemented in C++.
RUNTIME_CXX_SRCS := $(wildcard runtime/src/*.cpp)
UNIT_SRCS     := $(wildcard tests/unit/*.cpp)

# The standard library, embedded in the binary; listed in load order.
STDLIB_FILES  := $(addprefix stdlib/,prelude.sicm local.sicm numerics.sicm lagrangian.sicm \
                   rigid-body.sicm hamiltonian.sicm maps.sicm stability.sicm canonical.sicm \
                   lie.sicm effects.sicm vector-calculus.sicm plotting.sicm)
STDLIB_GEN    := $(BUILD)/gen/stdlib_embed.cpp

# The linear solves of kernels, as C text for the C emitter (codegen/emit_c.cpp).
KERNEL_SOLVE_GEN := $(BUILD)/gen/kernel_solve_text.cpp

COMPILER_OBJS := $(COMPILER_SRCS:%.cpp=$(BUILD)/%.o) $(BUILD)/gen/stdlib_embed.o \
                 $(BUILD)/gen/kernel_solve_text.o
RUNTIME_OBJS  := $(RUNTIME_SRCS:%.c=$(BUILD)/%.o) $(RUNTIME_CXX_SRCS:%.cpp=$(BUILD)/%.o)
UNIT_OBJS     := $(UNIT_SRCS:%.cpp=$(BUILD)/%.o)
# Everything of the compiler except its entry point, for the unit tests.
LIB_OBJS      := $(filter-out $(BUILD)/compiler/driver/main.o,$(COMPILER_OBJS))

SICM    := $(BUILD)/sicm
RTLIB   := $(BUILD)/libsicmrt.a
UNITBIN := $(BUILD)/unit-tests
# sicm_mpi_start and the sweeps' MPI exchange (runtime/mpi/), linked before
# libsicmrt.a into the executables of sicm build --mpi.
MPILIB  := $(if $(MPICC),$(BUILD)/libsicmrt_mpi.a)
MPI_OBJS := $(if $(MPICC),$(BUILD)/runtime/mpi/parallel_mpi.o)

.PHONY: jupyter all check demo examples stability accuracy effects install clean deps unit fuzz-smoke fuzz-differential
all: $(SICM) $(RTLIB) $(MPILIB)

$(BUILD)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) -c $< -o $@

$(STDLIB_GEN): $(STDLIB_FILES) scripts/embed-stdlib scripts/embedding.py
	@python3 scripts/embed-stdlib $@ $(STDLIB_FILES)

$(BUILD)/gen/stdlib_embed.o: $(STDLIB_GEN)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) -c $< -o $@

$(KERNEL_SOLVE_GEN): compiler/codegen/kernel_solve.inc scripts/embed-text scripts/embedding.py
	@python3 scripts/embed-text $@ kKernelSolveSource $<

$(BUILD)/gen/kernel_solve_text.o: $(KERNEL_SOLVE_GEN)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) -c $< -o $@

# The kernel interpreter computes what the JIT'ed C computes only if no
# multiply and add of it fuse into one rounding (the C is compiled with
# -ffp-contract=off too: codegen/jit.cpp, driver/build_exe.cpp).
$(BUILD)/compiler/codegen/kernel_interpreter.o: CXXFLAGS += -ffp-contract=off

$(BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

# The runtime's C++ files are C++17 (not the compiler's C++20) and see Eigen's
# headers as system headers (no warnings from them). They define C functions
# only, each in an archive member of its own, so the executables of `sicm
# build` (linked by cc, without libstdc++) pull them in only if they call them.
EIGEN_INC ?= /usr/include/eigen3
RTCXXFLAGS := -std=c++17 $(OPT) -g $(WARN) $(SANFLAGS) -isystem $(EIGEN_INC)
$(BUILD)/runtime/src/%.o: runtime/src/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CPPFLAGS) $(RTCXXFLAGS) -c $< -o $@

$(RTLIB): $(RUNTIME_OBJS)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

# runtime/mpi/ needs mpi.h, which only the wrapper compiler finds.
$(BUILD)/runtime/mpi/%.o: runtime/mpi/%.c
	@mkdir -p $(dir $@)
	$(MPICC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

$(BUILD)/libsicmrt_mpi.a: $(MPI_OBJS)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(SICM): $(COMPILER_OBJS) $(RTLIB)
	$(CXX) $(LDFLAGS) $(COMPILER_OBJS) $(RTLIB) $(LIBS) -o $@

$(UNITBIN): $(UNIT_OBJS) $(LIB_OBJS) $(RTLIB)
	$(CXX) $(LDFLAGS) $(UNIT_OBJS) $(LIB_OBJS) $(RTLIB) $(LIBS) -lgtest -lgtest_main -o $@

unit: $(UNITBIN)

deps:
	@scripts/install-deps

# How sanitized programs run under `make check SANITIZE=1` (every process the
# tests start inherits it: sicm, the unit tests, built executables):
#   abort_on_error=1            a finding ends the program with SIGABRT, which the
#                               runner always counts as a failure (ASan's usual
#                               exit status 1 could pass as an expected error)
#   halt_on_error=1             UBSan stops at its first finding instead of
#                               printing it and going on with status 0
#   print_stacktrace=1          UBSan shows where the undefined behaviour was
#   detect_leaks=0              the Boehm GC owns the heap and frees by
#                               collecting, so LeakSanitizer would report the
#                               malloc'd memory that only the GC heap refers to
#   detect_stack_use_after_return=0
#                               the GC scans the stacks for pointers; ASan's fake
#                               stack frames would hide live objects from it
#   LSAN_OPTIONS                where LeakSanitizer runs all the same (the
#                               ranks mpirun starts), leaks inside Open MPI's
#                               own libraries are not findings
#                               (tests/sanitizer/openmpi-leaks.supp)
#   SICM_TEST_TIMEOUT_SCALE=10  sanitized code computes 5-10 times slower
SANENV := $(if $(SANITIZE),\
  ASAN_OPTIONS=abort_on_error=1:detect_leaks=0:detect_stack_use_after_return=0 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizer/openmpi-leaks.supp \
  UBSAN_OPTIONS=halt_on_error=1:abort_on_error=1:print_stacktrace=1 \
  SICM_TEST_TIMEOUT_SCALE=10)

# FUZZ=0 leaves out the short fuzz runs (and the clang build they need).
FUZZ ?= 1
# The Python that runs the Jupyter kernel's tests (tests/jupyter/run): Debian's,
# which has the packages scripts/install-deps installs (python3-ipykernel,
# python3-jupyter-client, python3-nbclient, python3-nbformat), whatever
# python3 comes first on PATH (a pyenv one, say). JUPYTER_PYTHON= (empty)
# leaves those tests out.
JUPYTER_PYTHON ?= /usr/bin/python3
check: deps
	@$(MAKE) --no-print-directory all $(UNITBIN)
	@$(SANENV) python3 tests/run --sicm $(SICM) --unit $(UNITBIN) $(if $(UPDATE),--update) \
	  --differential scripts/fuzz-differential $(if $(filter 1,$(FUZZ)),--fuzz scripts/fuzz) \
	  $(if $(JUPYTER_PYTHON),--jupyter $(JUPYTER_PYTHON))

demo: deps
	@$(MAKE) --no-print-directory all
	@mkdir -p $(BUILD)/demo
	$(SICM) build examples/driven-pendulum.sicm -o $(BUILD)/demo/driven-pendulum
	$(BUILD)/demo/driven-pendulum --plot-dir $(BUILD)/demo
	@echo "plot: $(BUILD)/demo/driven-pendulum.svg (data: $(BUILD)/demo/driven-pendulum.tsv)"

# The hard cases at full size, built; writes docs/stability.md (never edit it
# by hand) and fails if a bound does not hold.
stability: deps
	@$(MAKE) --no-print-directory all
	@scripts/stability-report --sicm $(SICM)

# What accuracy costs in time: sicm bench on four scenes, into docs/accuracy.md
# (generated; never edit it by hand).
accuracy: deps
	@$(MAKE) --no-print-directory all
	@bench/work-precision/run --sicm $(SICM)

# What each effect of a scene costs: every subset built and timed, into docs/effects.md
effects: deps
	@$(MAKE) --no-print-directory all
	@bench/effects/run --sicm $(SICM)

# Every figure scene at full size, built with sicm build and run, into
# $(BUILD)/figures (scripts/run-examples without --build interprets them).
examples: deps
	@$(MAKE) --no-print-directory all
	@scripts/run-examples --build --sicm $(SICM) --out $(BUILD)/figures

# The libFuzzer targets of fuzz/, each for a few thousand inputs (needs clang).
fuzz-smoke: deps
	@$(MAKE) --no-print-directory all
	@scripts/fuzz smoke

# Random mechanics programs run with sicm run and built with sicm build,
# compared byte for byte (fuzz/README.md): SEED, COUNT programs, JOBS at once.
SEED ?= 1
COUNT ?= 500
JOBS ?= 1
fuzz-differential: deps
	@$(MAKE) --no-print-directory all
	@scripts/fuzz-differential --sicm $(SICM) --seed $(SEED) --count $(COUNT) --jobs $(JOBS)

# The kernel spec `sicm` and what the kernel needs (jupyter/install).
jupyter: deps
	@$(MAKE) --no-print-directory all
	@jupyter/install

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib $(DESTDIR)$(PREFIX)/include/sicm
	install -m 755 $(SICM) $(DESTDIR)$(PREFIX)/bin/sicm
	install -m 644 $(RTLIB) $(DESTDIR)$(PREFIX)/lib/libsicmrt.a
	$(if $(MPILIB),install -m 644 $(MPILIB) $(DESTDIR)$(PREFIX)/lib/libsicmrt_mpi.a)
	install -m 644 runtime/include/sicm/*.h $(DESTDIR)$(PREFIX)/include/sicm/

clean:
	rm -rf $(BUILD)

-include $(COMPILER_OBJS:.o=.d) $(RUNTIME_OBJS:.o=.d) $(UNIT_OBJS:.o=.d) $(MPI_OBJS:.o=.d)

# The fuzz targets' build: read after the top-level Makefile by scripts/fuzz,
#   make -f Makefile -f fuzz/fuzz.mk BUILD=build/fuzz CXX=clang++ CC=clang \
#        OPT=-O1 SANFLAGS='-fsanitize=fuzzer-no-link,address,undefined ...' fuzz-targets
# so the compiler's and the runtime's objects are built by the top-level
# rules from the top-level source lists, with clang and the fuzzer's
# instrumentation, into a build directory of their own.

FUZZ_TARGETS := reader eval simplify emit
FUZZ_BINS    := $(FUZZ_TARGETS:%=$(BUILD)/fuzz-%)
FUZZ_OBJS    := $(FUZZ_TARGETS:%=$(BUILD)/fuzz/%.o) $(BUILD)/fuzz/common.o

# The targets have their own main() (common.cpp runs libFuzzer on a thread
# with a big stack), so they link libFuzzer's runtime without its main.
FUZZ_SAN     ?= address,undefined
FUZZ_LIBFUZZER := $(shell $(CXX) --print-runtime-dir)/libclang_rt.fuzzer_no_main-$(shell uname -m).a

.PHONY: fuzz-targets
fuzz-targets: $(FUZZ_BINS)

.SECONDARY: $(FUZZ_OBJS)

# The coverage ignore list is part of every object's flags.
$(LIB_OBJS) $(RUNTIME_OBJS) $(FUZZ_OBJS): fuzz/coverage-ignore.txt

$(BUILD)/fuzz-%: $(BUILD)/fuzz/%.o $(BUILD)/fuzz/common.o $(LIB_OBJS) $(RUNTIME_OBJS)
	$(CXX) -fsanitize=fuzzer-no-link,$(FUZZ_SAN) $^ $(FUZZ_LIBFUZZER) $(LIBS) -o $@

-include $(FUZZ_OBJS:.o=.d)

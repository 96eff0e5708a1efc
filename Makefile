# Discrete ray tracing of implicit surfaces (Stolte & Caubet): build, test, demo.
#
#   make                 bin/rasterize and bin/render
#   make test            every cmocka suite and CLI test (-O2 build); make check
#                        is the same
#   make test SANITIZE=1 the same under ASan + UBSan, no recovery
#   make demo            rasterize every example and render it into demo/: the
#                        paper's plain rule and --aa 4 --shadows --ao 16 --exact
#                        (DOCS=1: the README's pictures in docs/images/ too)
#   make pgo             bin/rasterize and bin/render built with profile
#                        feedback (GCC; a training run, then checked)
#   make bench           benchmark, full, on make pgo's programs
#                        (make bench-quick: short; see bench/README.md)
#   make fuzz            libFuzzer targets for a bounded time (clang)
#   make install         programs and man pages under DESTDIR/PREFIX
#                        (default /usr/local); make uninstall removes them

PREFIX   ?= /usr/local
SANITIZE ?= 0
WERROR   ?= 0

CC       ?= cc
PKGS     := libpng zlib
ARCH     := $(shell uname -m)
ifeq ($(ARCH),x86_64)
  ARCHFLAGS ?= -march=x86-64-v2
endif

WARN := -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes \
        -Wpointer-arith -Wformat=2 -Wundef -Wvla -Wcast-align
ifeq ($(WERROR),1)
  WARN += -Werror
endif

# -ffp-contract=off: no fused multiply-add, so interval and DDA arithmetic
# round exactly as written, whatever the compiler or target.
BASEFLAGS := -std=c11 -D_GNU_SOURCE -g -ffp-contract=off -fno-fast-math \
             $(ARCHFLAGS) $(WARN) -I. $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
LDLIBS   := $(shell pkg-config --libs $(PKGS) 2>/dev/null || echo -lpng -lz) -lm -lpthread

ifeq ($(FUZZ),1)
  VARIANT  := fuzz
  SANFLAGS := -fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=all -fno-omit-frame-pointer
  CFLAGS   ?= -O1
else ifeq ($(SANITIZE),1)
  VARIANT  := san
  SANFLAGS := -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all \
              -fno-omit-frame-pointer
  CFLAGS   ?= -O1
else ifneq ($(filter gen use,$(PGO)),)
  # make pgo's two builds (see there): the release flags, plus the
  # instrumentation, then the counts it left
  VARIANT  := pgo
  SANFLAGS :=
  CFLAGS   ?= -O2
  LTOFLAGS ?= -flto=auto
  AR       := gcc-ar
  PGOFLAGS := $(if $(filter gen,$(PGO)),-fprofile-generate -fprofile-update=prefer-atomic,\
                -fprofile-use -fprofile-partial-training -Wno-missing-profile)
else
  VARIANT  := rel
  SANFLAGS :=
  CFLAGS   ?= -O2
  # link-time optimisation: the renderer's per-pixel calls cross files
  # (camera, trace, shade, normal decoding); ~2 % fewer instructions a frame
  LTOFLAGS ?= -flto=auto
  AR       := gcc-ar
endif
ALLCFLAGS := $(BASEFLAGS) $(CFLAGS) $(SANFLAGS) $(LTOFLAGS) $(PGOFLAGS)
ALLLDFLAGS := $(SANFLAGS) $(LTOFLAGS) $(PGOFLAGS) $(LDFLAGS)

# a build for another target (make ARCHFLAGS=...) keeps its own objects
B_SUFFIX := $(if $(filter command line,$(origin ARCHFLAGS)),$(subst =,-,$(word 1,$(ARCHFLAGS))))
B := build/$(VARIANT)$(B_SUFFIX)
PGO_B := build/pgo$(B_SUFFIX)

# One library per layer; a program is its main.c plus the layers it may use,
# and its link line names only those, so a call the wrong way fails to link.
# Layers, and what each may include and link (tests/cli/layers.sh checks
# every #include "..." against this matrix):
#   format/          format/ only (libc and zlib)
#   common/          common/: plumbing (diagnostics, numbers, atomic output,
#                    version, test hooks)
#   common/expr/     + common/        expression engine (scene language,
#                                     tapes, intervals)
#   common/view/     + common/        cameras and images
#   rasterize/       + common/expr/ common/ format/
#   render/          + common/view/ common/expr/ common/ format/  (the expression
#                    engine evaluates the surface tapes a 1.1 file stores)
#   bench/           + render/ common/expr/ common/view/ common/ format/
#                    (measurement tools and their helpers, bench/README.md;
#                    bench/tree_util builds synthetic trees for bench and tests)
#   tests/           everything, bench/ included; nothing includes tests/.
# So tests sit on top and bench below them: bench never reaches into tests/.
FORMAT_SRC    := $(wildcard format/*.c)
COMMON_SRC    := $(wildcard common/*.c)
EXPR_SRC      := $(wildcard common/expr/*.c)
VIEW_SRC      := $(wildcard common/view/*.c)
RASTERIZE_SRC := $(filter-out rasterize/main.c,$(wildcard rasterize/*.c))
RENDER_SRC    := $(filter-out render/main.c,$(wildcard render/*.c))
BENCH_SRC     := $(filter-out bench/%_main.c,$(wildcard bench/*.c))
TEST_SRC      := $(wildcard tests/test_*.c)
TESTLIB_SRC   := $(filter-out tests/test_%.c,$(wildcard tests/*.c))
FUZZ_SRC      := $(filter-out tests/fuzz/replay_main.c,$(wildcard tests/fuzz/fuzz_*.c))

obj = $(patsubst %.c,$(B)/%.o,$(1))

LIB_FORMAT    := $(B)/libformat.a
LIB_COMMON    := $(B)/libcommon.a
# common/ again with DDA_TEST_HOOKS (ATOMIC_FAULT, DDA_FPE_TRAPS): only the
# test suites and the $(B)/testbin programs the CLI tests run link it.
LIB_COMMON_HOOKS := $(B)/libcommon_hooks.a
LIB_EXPR      := $(B)/libexpr.a
LIB_VIEW      := $(B)/libview.a
LIB_RASTERIZE := $(B)/librasterize.a
LIB_RENDER    := $(B)/librender.a
LIB_BENCH     := $(B)/libbench.a
LIB_TEST      := $(B)/libtestutil.a

LIBS_RASTERIZE = $(LIB_RASTERIZE) $(LIB_EXPR) $(1) $(LIB_FORMAT)
LIBS_RENDER    = $(LIB_RENDER) $(LIB_VIEW) $(LIB_EXPR) $(LIB_FORMAT) $(1)
LIBS_BENCH     = $(LIB_BENCH) $(LIB_RENDER) $(LIB_EXPR) $(LIB_VIEW) $(1) $(LIB_FORMAT)
LIBS_TEST      = $(LIB_TEST) $(LIB_BENCH) $(LIB_RENDER) $(LIB_RASTERIZE) $(LIB_EXPR) $(LIB_VIEW) \
                 $(LIB_COMMON_HOOKS) $(LIB_FORMAT)

PROGRAMS   := $(patsubst %/main.c,$(B)/bin/%,$(wildcard rasterize/main.c render/main.c))
TEST_PROGRAMS := $(patsubst $(B)/bin/%,$(B)/testbin/%,$(PROGRAMS))
BENCH_PROGS := $(patsubst bench/%_main.c,$(B)/bin/%,$(wildcard bench/*_main.c))
TEST_BINS  := $(patsubst tests/%.c,$(B)/tests/%,$(TEST_SRC))
# Each fuzz target also links against a plain main() that replays its corpus
# and past crashers, so `make test` runs them without libFuzzer.
REPLAY_BINS := $(patsubst tests/fuzz/%.c,$(B)/tests/replay_%,$(FUZZ_SRC))
FUZZ_BINS   := $(patsubst tests/fuzz/%.c,$(B)/fuzz/%,$(FUZZ_SRC))
FUZZ_TIME   ?= 60

.PHONY: all test check demo bench bench-quick fuzz fuzz-run clean install uninstall deps deps-test tools \
        pgo programs FORCE
.DEFAULT_GOAL := all
# Keep objects that only pattern rules mention (test and fuzz mains).
.PRECIOUS: $(B)/%.o $(B)/hooks/%.o

ifeq ($(VARIANT),rel)
all: $(patsubst $(B)/bin/%,bin/%,$(PROGRAMS))
bin/%: $(B)/bin/%
	@mkdir -p bin
	cp $< $@
else
all: $(PROGRAMS)
endif

tools: $(BENCH_PROGS)
programs: $(PROGRAMS)

# bin/rasterize and bin/render built with profile feedback (GCC): the
# programs instrumented (-fprofile-generate) in $(PGO_B), run on
# bench/pgo_train.sh's workload, compiled again in the same places with the
# counts the training left (-fprofile-use; code the training never ran is
# compiled as without a profile), then checked: they must write the
# training's files again, byte for byte. Rasterizing takes 0-17 % less time
# by scene (docs/perf-log.md); the benchmark runs these.
pgo: deps
	@$(CC) --version 2>/dev/null | grep -q 'Free Software Foundation' || \
	  { echo "make pgo: needs GCC (CC=$(CC)); make all builds without profile feedback" >&2; exit 1; }
	rm -rf $(PGO_B)
	$(MAKE) --no-print-directory PGO=gen programs
	sh bench/pgo_train.sh $(PGO_B)/bin $(PGO_B)/train
	find $(PGO_B) \( -name '*.o' -o -name '*.a' \) -delete
	rm -rf $(PGO_B)/bin
	$(MAKE) --no-print-directory PGO=use programs
	sh bench/pgo_train.sh --check $(PGO_B)/bin $(PGO_B)/train
	rm -rf $(PGO_B)/train
	@mkdir -p bin
	cp $(PGO_B)/bin/rasterize $(PGO_B)/bin/render bin/

$(B)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(ALLCFLAGS) -MMD -MP -c $< -o $@
$(B)/hooks/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(ALLCFLAGS) -DDDA_TEST_HOOKS -MMD -MP -c $< -o $@

# The AVX2 builds of the lane evaluators (common/expr/tape_ilanes.c chooses
# at run time): these files alone get -mavx2 (no FMA), outside link-time
# optimisation so no other code is compiled for AVX2.
ifeq ($(ARCH),x86_64)
$(B)/common/expr/tape_ilanes_avx2.o $(B)/common/expr/tape_lanes_avx2.o \
    $(B)/common/expr/tape_iglanes_avx2.o: ALLCFLAGS += -mavx2 -fno-lto
endif

# --version: VERSION plus the checkout's commit (none outside a checkout).
# The stamp changes only when that string does, so version.o rebuilds then.
DDA_VERSION := $(shell cat VERSION)
# (Only this tree's own .git: an unpacked tarball inside another checkout
# must not take that checkout's commit.)
DDA_COMMIT  := $(if $(wildcard .git),$(shell git describe --always --dirty 2>/dev/null))
VERSION_DEFS := -DDDA_VERSION='"$(DDA_VERSION)"' -DDDA_COMMIT='"$(DDA_COMMIT)"'
$(B)/version.stamp: FORCE
	@mkdir -p $(dir $@)
	@echo '$(VERSION_DEFS)' | cmp -s - $@ || echo '$(VERSION_DEFS)' > $@
$(B)/common/version.o $(B)/hooks/common/version.o: ALLCFLAGS += $(VERSION_DEFS)
$(B)/common/version.o $(B)/hooks/common/version.o: $(B)/version.stamp

$(LIB_FORMAT): $(call obj,$(FORMAT_SRC))
$(LIB_COMMON): $(call obj,$(COMMON_SRC))
$(LIB_COMMON_HOOKS): $(patsubst %.c,$(B)/hooks/%.o,$(COMMON_SRC))
$(LIB_EXPR): $(call obj,$(EXPR_SRC))
$(LIB_VIEW): $(call obj,$(VIEW_SRC))
$(LIB_RASTERIZE): $(call obj,$(RASTERIZE_SRC))
$(LIB_RENDER): $(call obj,$(RENDER_SRC))
$(LIB_BENCH): $(call obj,$(BENCH_SRC))
$(LIB_TEST): $(call obj,$(TESTLIB_SRC))
$(B)/%.a:
	@mkdir -p $(dir $@)
	rm -f $@
	$(AR) rcs $@ $^

$(B)/bin/rasterize $(B)/testbin/rasterize: $(B)/rasterize/main.o
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $^ $(LDLIBS)
$(B)/bin/render $(B)/testbin/render: $(B)/render/main.o
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $^ $(LDLIBS)
$(B)/bin/rasterize: $(call LIBS_RASTERIZE,$(LIB_COMMON))
$(B)/testbin/rasterize: $(call LIBS_RASTERIZE,$(LIB_COMMON_HOOKS))
$(B)/bin/render: $(call LIBS_RENDER,$(LIB_COMMON))
$(B)/testbin/render: $(call LIBS_RENDER,$(LIB_COMMON_HOOKS))

$(B)/bin/%: $(B)/bench/%_main.o $(call LIBS_BENCH,$(LIB_COMMON))
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $^ $(LDLIBS)

$(B)/tests/%: $(B)/tests/%.o $(LIBS_TEST)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $^ $(LDLIBS) -lcmocka -lmpfr -lgmp

$(B)/tests/replay_%: $(B)/tests/fuzz/%.o $(B)/tests/fuzz/replay_main.o $(LIBS_TEST)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $^ $(LDLIBS)
$(B)/fuzz/%: $(B)/tests/fuzz/%.o $(LIBS_TEST)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -fsanitize=fuzzer -o $@ $^ $(LDLIBS)

fuzz:
	$(MAKE) --no-print-directory FUZZ=1 CC=clang fuzz-run
fuzz-run: $(FUZZ_BINS)
	@for f in $(FUZZ_BINS); do n=$$(basename $$f); mkdir -p build/fuzz-corpus/$$n; \
	  echo "fuzz: $$n for $(FUZZ_TIME) s"; \
	  $$f -max_total_time=$(FUZZ_TIME) -timeout=2 -rss_limit_mb=2048 \
	      -artifact_prefix=tests/fuzz/crashers/$$n- build/fuzz-corpus/$$n tests/fuzz/corpus/$$n || exit 1; done

# Missing libraries are installed with the system's package manager (Debian/Ubuntu).
deps:
	@sh tests/deps.sh build
deps-test:
	@sh tests/deps.sh test

# The CLI tests run $(B)/testbin (hooks compiled in); install.sh installs
# and runs the release $(B)/bin programs.
test: deps-test
	$(MAKE) --no-print-directory SANITIZE=$(SANITIZE) $(PROGRAMS) $(TEST_PROGRAMS) $(BENCH_PROGS) \
	    $(TEST_BINS) $(REPLAY_BINS)
	sh tests/run.sh $(B)
check: test

demo: deps
	$(MAKE) --no-print-directory all
	sh scenes/demo.sh

bench: deps
	$(MAKE) --no-print-directory pgo tools
	sh bench/run.sh full
bench-quick: deps
	$(MAKE) --no-print-directory pgo tools
	sh bench/run.sh quick

MANDIR ?= $(PREFIX)/share/man
MAN1   := docs/man/rasterize.1 docs/man/render.1
MAN5   := docs/man/oct.5 docs/man/scene.5
install: $(PROGRAMS)
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(MANDIR)/man5
	install -m 755 $(PROGRAMS) $(DESTDIR)$(PREFIX)/bin/
	install -m 644 $(MAN1) $(DESTDIR)$(MANDIR)/man1/
	install -m 644 $(MAN5) $(DESTDIR)$(MANDIR)/man5/
uninstall:
	rm -f $(patsubst $(B)/bin/%,$(DESTDIR)$(PREFIX)/bin/%,$(PROGRAMS))
	rm -f $(patsubst docs/man/%,$(DESTDIR)$(MANDIR)/man1/%,$(MAN1))
	rm -f $(patsubst docs/man/%,$(DESTDIR)$(MANDIR)/man5/%,$(MAN5))

clean:
	rm -rf build bin demo

-include $(shell find build -name '*.d' 2>/dev/null)

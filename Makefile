# Discrete ray tracing of implicit surfaces (Stolte & Caubet): build, test, demo.
#
#   make                 bin/rasterize and bin/render
#   make test            every cmocka suite and CLI test (-O2 build)
#   make test SANITIZE=1 the same under ASan + UBSan, no recovery
#   make demo            rasterize and render the paper's scenes into demo/*.png
#   make bench           benchmark (see bench/README.md)
#   make fuzz            libFuzzer targets for a bounded time (clang)
#   make install PREFIX=/usr/local

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
else
  VARIANT  := rel
  SANFLAGS :=
  CFLAGS   ?= -O2
  # link-time optimisation: the renderer's per-pixel calls cross files
  # (camera, trace, shade, normal decoding); ~2 % fewer instructions a frame
  LTOFLAGS ?= -flto=auto
  AR       := gcc-ar
endif
ALLCFLAGS := $(BASEFLAGS) $(CFLAGS) $(SANFLAGS) $(LTOFLAGS)
ALLLDFLAGS := $(SANFLAGS) $(LTOFLAGS) $(LDFLAGS)

B := build/$(VARIANT)
# a build for another target (make ARCHFLAGS=...) keeps its own objects
ifeq ($(origin ARCHFLAGS),command line)
  B := build/$(VARIANT)$(subst =,-,$(word 1,$(ARCHFLAGS)))
endif

# One library per layer; a program is its main.c plus the layers below it.
# format/ depends on libc and zlib only; common/ is plumbing (diagnostics,
# numbers, atomic output); common/expr/ the expression engine (scene
# language, tapes, intervals); common/view/ cameras and images.
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
LIB_EXPR      := $(B)/libexpr.a
LIB_VIEW      := $(B)/libview.a
LIB_RASTERIZE := $(B)/librasterize.a
LIB_RENDER    := $(B)/librender.a
LIB_BENCH     := $(B)/libbench.a
LIB_TEST      := $(B)/libtestutil.a
LIBS := $(LIB_RENDER) $(LIB_RASTERIZE) $(LIB_BENCH) $(LIB_EXPR) $(LIB_VIEW) $(LIB_COMMON) $(LIB_FORMAT)

PROGRAMS   := $(patsubst %/main.c,$(B)/bin/%,$(wildcard rasterize/main.c render/main.c))
BENCH_PROGS := $(patsubst bench/%_main.c,$(B)/bin/%,$(wildcard bench/*_main.c))
TEST_BINS  := $(patsubst tests/%.c,$(B)/tests/%,$(TEST_SRC))
# Each fuzz target also links against a plain main() that replays its corpus
# and past crashers, so `make test` runs them without libFuzzer.
REPLAY_BINS := $(patsubst tests/fuzz/%.c,$(B)/tests/replay_%,$(FUZZ_SRC))
FUZZ_BINS   := $(patsubst tests/fuzz/%.c,$(B)/fuzz/%,$(FUZZ_SRC))
FUZZ_TIME   ?= 60

.PHONY: all test demo bench bench-quick fuzz fuzz-run clean install deps deps-test tools
.DEFAULT_GOAL := all
# Keep objects that only pattern rules mention (test and fuzz mains).
.PRECIOUS: $(B)/%.o

ifeq ($(VARIANT),rel)
all: $(patsubst $(B)/bin/%,bin/%,$(PROGRAMS))
bin/%: $(B)/bin/%
	@mkdir -p bin
	cp $< $@
else
all: $(PROGRAMS)
endif

tools: $(BENCH_PROGS)

$(B)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(ALLCFLAGS) -MMD -MP -c $< -o $@

$(LIB_FORMAT): $(call obj,$(FORMAT_SRC))
$(LIB_COMMON): $(call obj,$(COMMON_SRC))
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

$(B)/bin/rasterize: $(B)/rasterize/main.o $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $< $(LIBS) $(LDLIBS)
$(B)/bin/render: $(B)/render/main.o $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $< $(LIBS) $(LDLIBS)
# Benchmarks may build synthetic trees with the test utilities (tests/tree_util).
$(B)/bin/%: $(B)/bench/%_main.o $(LIB_TEST) $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $< $(LIB_TEST) $(LIBS) $(LDLIBS)

$(B)/tests/%: $(B)/tests/%.o $(LIB_TEST) $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $< $(LIB_TEST) $(LIBS) $(LDLIBS) -lcmocka -lmpfr -lgmp

$(B)/tests/replay_%: $(B)/tests/fuzz/%.o $(B)/tests/fuzz/replay_main.o $(LIB_TEST) $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(ALLLDFLAGS) -o $@ $^ $(LDLIBS)
$(B)/fuzz/%: $(B)/tests/fuzz/%.o $(LIB_TEST) $(LIBS)
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

test: deps-test
	$(MAKE) --no-print-directory SANITIZE=$(SANITIZE) $(PROGRAMS) $(BENCH_PROGS) $(TEST_BINS) $(REPLAY_BINS)
	sh tests/run.sh $(B)

demo: deps
	$(MAKE) --no-print-directory all
	sh scenes/demo.sh

bench: deps
	$(MAKE) --no-print-directory all tools
	sh bench/run.sh full
bench-quick: deps
	$(MAKE) --no-print-directory all tools
	sh bench/run.sh quick

install: all
	install -d $(DESTDIR)$(PREFIX)/bin
	install -m 755 bin/rasterize bin/render $(DESTDIR)$(PREFIX)/bin/

clean:
	rm -rf build bin demo

-include $(shell find build -name '*.d' 2>/dev/null)

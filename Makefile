# ombra — build, test, run and bench. Plain make, no configure step.
#   make            the `ombra` command (build/ombra)
#   make run        render the default scene into out/
#   make test       unit and property tests, gcc and clang, -O0 and -O2, + freestanding check
#   make test-sanitize   the suite under ASan + UBSan (make test-32: as a 32-bit program)
#   make bench      benchmark figures (medians of several runs)
#   make cross-test the same frames from every compiler and CPU (qemu)
#   make fuzz       libFuzzer targets, FUZZ_SECONDS each; make test-valgrind
#   make fuzz-regress   the fuzz targets over tests/fuzz/regress/ (part of make check)

CC      ?= cc
OPT     ?= -O2
O       ?= build
WARN    = -std=c99 -Wall -Wextra -Wpedantic -Werror -Wshadow -Wstrict-prototypes
# No FMA contraction, float arithmetic in float (FLT_EVAL_METHOD 0; engine/core/core.h
# refuses other modes): frames must be bit-identical on every CPU. gcc says which
# excess precision it keeps: "standard" rounds to float at every assignment and cast
# (the default under -std=c99, not under -std=gnu*); s390x gcc's standard mode keeps
# float in double, its fast mode computes in float, as the other CPUs do. clang has no
# such flag (it computes in float wherever it does not use x87).
CC_KIND := $(if $(shell $(CC) --version 2>/dev/null | grep -i clang),clang,$(shell $(CC) -dumpmachine 2>/dev/null))
DETERM  = -ffp-contract=off $(if $(findstring clang,$(CC_KIND)),,$(if $(filter s390%,$(CC_KIND)),-fexcess-precision=fast,-fexcess-precision=standard))
CFLAGS_ALL = $(WARN) $(DETERM) $(OPT) -g -Iinclude $(EXTRA)
LDLIBS  = -lm
# The host programs' parallel-for (platform/jobs.c) runs on POSIX threads; the engine
# library needs none (the embedding examples link without it).
PTHREAD = -pthread

ENGINE_SRC   = $(sort $(wildcard engine/*/*.c engine/*/*/*.c))
PLATFORM_SRC = $(sort $(wildcard platform/*.c))
TOOL_SRC     = $(sort $(wildcard tools/*.c))
TEST_SRC     = $(sort $(wildcard tests/*.c tests/unit/*.c tests/method/*.c tests/property/*.c))
BENCH_SRC    = $(sort $(wildcard tests/bench/*.c))

ENGINE_OBJ   = $(ENGINE_SRC:%.c=$(O)/%.o)
PLATFORM_OBJ = $(PLATFORM_SRC:%.c=$(O)/%.o)
TOOL_OBJ     = $(TOOL_SRC:%.c=$(O)/%.o)
TEST_OBJ     = $(TEST_SRC:%.c=$(O)/%.o)

all: $(O)/ombra

# V=1 shows the full compiler lines.
Q = $(if $(V),,@)

$(O)/%.o: %.c $(wildcard include/*.h engine/*.h engine/*/*.h engine/*/*/*.h platform/*.h tools/*.h tests/*.h tests/*/*.h)
	@mkdir -p $(dir $@)
	@$(if $(V),,echo "  CC $(O)/$<")
	$(Q)$(CC) $(CFLAGS_ALL) -c $< -o $@

$(O)/libombra.a: $(ENGINE_OBJ)
	@rm -f $@
	$(Q)ar rcs $@ $^

$(O)/ombra: $(TOOL_OBJ) $(PLATFORM_OBJ) $(O)/libombra.a
	$(Q)$(CC) $(CFLAGS_ALL) -o $@ $^ $(LDLIBS) $(PTHREAD)

$(O)/run-tests: $(TEST_OBJ) $(PLATFORM_OBJ) $(O)/libombra.a
	$(Q)$(CC) $(CFLAGS_ALL) -o $@ $^ $(LDLIBS) $(PTHREAD)

$(O)/bench: $(BENCH_SRC) $(PLATFORM_OBJ) $(O)/libombra.a $(wildcard tests/bench/*.h)
	$(Q)$(CC) $(CFLAGS_ALL) -o $@ $(filter %.c %.o %.a,$^) $(LDLIBS) $(PTHREAD)

# The report's scenes (a scene joins the page with one more entry here; NAME@WxH
# measures it at that size). Where arm-none-eabi-gcc and qemu-system-arm are installed,
# `run` counts the Cortex-M4 figures (CROSS_ONLY=m4-count make cross-test, about two
# minutes) for the page's small-machines section and chips; without them the page shows
# the tables that command last wrote into the firmware's README, with that file's commit.
# RUN_CROSS=0 leaves the count out (CI: make cross-test has just written out/cross).
RUN_CROSS ?= 1
REPORT_SCENES = default,town@1024x768,random-10K@320x240,random-100K@320x240,tests/stability/closeup.scene@160x120
FW_DOC = platform/cortex-m/README.md

run: $(O)/ombra
	@mkdir -p out
	$(O)/ombra render --out out/default.ppm --mask out/default-mask.pgm
	$(MAKE) --no-print-directory stability
	@if [ "$(RUN_CROSS)" = 0 ]; then \
	  echo "run: RUN_CROSS=0: the page shows what out/cross (make cross-test) or $(FW_DOC) has"; \
	elif command -v arm-none-eabi-gcc >/dev/null 2>&1 && command -v qemu-system-arm >/dev/null 2>&1; then \
	  echo "run: counting the Cortex-M4 figures: CROSS_ONLY=m4-count make cross-test (log: out/cross-count.log)"; \
	  CROSS_ONLY=m4-count sh tests/cross/run.sh >out/cross-count.log 2>&1 || \
	    echo "run: the Cortex-M count failed (out/cross-count.log); the page shows what out/cross or $(FW_DOC) has"; \
	else \
	  echo "run: no arm-none-eabi-gcc or qemu-system-arm: the page shows the tables of $(FW_DOC)"; \
	fi
	$(O)/ombra report --scenes $(REPORT_SCENES) --size 640x480 --runs 3 --tri-sweep --equal-memory --out out/report \
	  --cross-doc $(FW_DOC) --cross-doc-rev "$$(git log -1 --format='%h, %cs' -- $(FW_DOC) 2>/dev/null)"

# One suite, four builds: the same tests must pass under gcc and clang at -O0 and -O2.
# gcc -O0 also takes the paths made for microcontrollers (OM_FAST_FLOAT, core.h;
# OM_SMLOOK_DIRECT, smlookup.c), whose frames must be the same bits.
test:
	$(MAKE) --no-print-directory check CC=gcc OPT=-O2 O=build/gcc-O2
	$(MAKE) --no-print-directory check CC=gcc OPT="-O0 -DOM_FAST_FLOAT=1 -DOM_SMLOOK_DIRECT=1" O=build/gcc-O0
	$(MAKE) --no-print-directory check CC=clang OPT=-O2 O=build/clang-O2
	$(MAKE) --no-print-directory check CC=clang OPT=-O0 O=build/clang-O0
	@for b in gcc-O0 clang-O2 clang-O0; do \
	  cmp -s build/gcc-O2/frame-hashes.txt build/$$b/frame-hashes.txt || \
	  { echo "determinism: FAIL — frames from $$b differ from gcc-O2:"; \
	    diff build/gcc-O2/frame-hashes.txt build/$$b/frame-hashes.txt; exit 1; }; done; \
	  echo "determinism: ok — every method's frame is bit-identical across gcc/clang -O0/-O2"
	sh tests/sh/freestanding.sh

# The fuzz targets' entry points without libFuzzer, replayed over the inputs that once
# crashed or hung a target and the hostile inputs of issue 24 (tests/fuzz/regress/),
# and the seeds: part of `make check`, so of `make test` and `make test-sanitize`.
FUZZ_TARGETS = scene obj render api
FUZZ_INPUTS  = $(sort $(wildcard tests/fuzz/regress/* tests/fuzz/seeds/*))

$(O)/fuzz-replay-%: tests/fuzz/fuzz_%.c tests/fuzz/replay.c $(O)/libombra.a
	$(Q)$(CC) $(CFLAGS_ALL) -o $@ $(filter %.c %.a,$^) $(LDLIBS)

REPLAY = for t in $(FUZZ_TARGETS); do printf 'fuzz_%s: ' $$t; $(O)/fuzz-replay-$$t $(FUZZ_INPUTS) || exit 1; done

fuzz-regress: $(FUZZ_TARGETS:%=$(O)/fuzz-replay-%)
	$(Q)$(REPLAY)

# The README's embedding example, built as a user would (the library and the header,
# the project's warnings) and run; readme.sh checks the README shows this very code.
$(O)/embed-render-once: tests/embed/render_once.c $(O)/libombra.a include/ombra.h
	$(Q)$(CC) $(CFLAGS_ALL) -o $@ $(filter %.c %.a,$^) $(LDLIBS)

# The README's second example: arenas from the bytes queries, a whole 640x480 frame;
# sized.sh checks it draws what `ombra render` draws.
$(O)/embed-render-sized: tests/embed/render_sized.c $(O)/libombra.a include/ombra.h
	$(Q)$(CC) $(CFLAGS_ALL) -o $@ $(filter %.c %.a,$^) $(LDLIBS)

# The same example in a firmware with only `sm`: registry.c (the only file that reads
# OM_WITH_*) compiled with every other method off and linked ahead of the library;
# tests/sh/methods.sh checks that no other method's code came along and that the frame
# is the full library's.
ONLY_SM = -DOM_WITH_NONE=0 -DOM_WITH_REF=0 -DOM_WITH_CSM=0 -DOM_WITH_ASM=0 -DOM_WITH_RTW=0 -DOM_WITH_SPSM=0 \
          -DOM_WITH_IZB=0 -DOM_WITH_HYBRID=0
$(O)/embed-only-sm: tests/embed/render_once.c engine/shadow/registry.c $(O)/libombra.a \
                    include/ombra.h $(wildcard engine/*/*.h engine/*/*/*.h)
	$(Q)$(CC) $(CFLAGS_ALL) $(ONLY_SM) -o $@ $(filter %.c %.a,$^) $(LDLIBS)

# The benchmark, stress and stability programs are built (not run), so a change that
# breaks one fails here and not at the next `make bench`.
check: $(O)/run-tests $(O)/ombra $(FUZZ_TARGETS:%=$(O)/fuzz-replay-%) $(O)/embed-render-once \
       $(O)/embed-render-sized $(O)/embed-only-sm $(O)/bench $(O)/stress $(O)/stability
	@echo "== $(O)"
	$(O)/run-tests
	sh tests/sh/cli.sh $(O)/ombra
	$(Q)$(REPLAY)
	$(O)/embed-render-once
	sh tests/embed/sized.sh $(O)
	sh tests/embed/readme.sh
	sh tests/embed/figures.sh $(O)
	sh tests/sh/links.sh
	sh tests/sh/methods.sh $(O)
	SIZE=160x120 sh tests/sh/pairs.sh $(O)/ombra 100 $(O)/pairs

# Every method rendered on 2 threads, whole and through strips, by the command $(1)
# (under $(2), a checker or nothing), into directory $(3): the sanitizers and valgrind
# see the frame's jobs as well as the suite's threaded tests.
THREADED_RENDERS = for m in $$($(1) methods | awk 'NF == 0 {exit} {print $$1}'); do \
	  for s in 0 40; do \
	    $(2) $(1) render --quiet --size 160x120 --method $$m --map 512 --threads 2 \
	      $$([ $$s -gt 0 ] && echo --strip $$s) --out $(3)/threads.ppm || exit 1; \
	  done; done; echo "every method on 2 threads, whole frame and strips: clean"

test-sanitize:
	$(MAKE) --no-print-directory check CC=clang OPT=-O1 O=build/san \
	  EXTRA="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
	@$(call THREADED_RENDERS,build/san/ombra,,build/san)

# The same suite as a 32-bit i386 program (SSE for float, as the determinism promise
# asks) under ASan + UBSan: size arithmetic that wraps only where size_t has 32 bits
# shows here. The raster suite needs 128-bit integers and is skipped; Debian's i386
# multilib has no asm/ headers of its own, and x86-64's hold the same values.
test-32:
	$(MAKE) --no-print-directory check CC=clang OPT=-O1 O=build/i386-san \
	  EXTRA="-m32 -msse2 -mfpmath=sse -idirafter /usr/include/x86_64-linux-gnu -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"

# The threaded tests and a threaded render of every method under clang's
# ThreadSanitizer: the frame's jobs must share nothing they write.
TSAN = build/tsan
test-tsan:
	$(MAKE) --no-print-directory $(TSAN)/run-tests $(TSAN)/ombra CC=clang OPT=-O1 O=$(TSAN) \
	  EXTRA="-fsanitize=thread -fno-omit-frame-pointer"
	TSAN_OPTIONS=halt_on_error=1 $(TSAN)/run-tests same_bits
	TSAN_OPTIONS=halt_on_error=1 $(TSAN)/run-tests fewer_jobs
	@for m in $$($(TSAN)/ombra methods | awk 'NF == 0 {exit} {print $$1}'); do \
	  for s in 0 40; do \
	    TSAN_OPTIONS=halt_on_error=1 $(TSAN)/ombra render --quiet --size 200x150 --method $$m --map 512 \
	      --threads 4 $$([ $$s -gt 0 ] && echo --strip $$s) --out $(TSAN)/tsan.ppm || exit 1; \
	  done; done; echo "tsan: every method, 4 threads, whole frame and strips: clean"

bench:
	$(MAKE) --no-print-directory $(O)/bench $(O)/ombra OPT="-O2 -DNDEBUG"
	$(O)/bench

# Bit-identical frames across compilers and CPUs: x86-64, i386 (and x87, outside the
# promise), aarch64, riscv64, armhf, ppc32, s390x under qemu-user, Cortex-M0/M3/M4/M7
# firmware under qemu-system-arm. CROSS_SKIP_MISSING=1 skips a missing toolchain.
cross-test:
	sh tests/cross/run.sh

# Every method under every budget from 0 to one pass, with guard bytes.
$(O)/stress: tests/stress/stress.c tests/bench/bench_main.c $(PLATFORM_OBJ) $(O)/libombra.a
	$(Q)$(CC) $(CFLAGS_ALL) -DOM_BENCH_NO_MAIN -o $@ $(filter %.c %.o %.a,$^) $(LDLIBS) $(PTHREAD)

stress:
	$(MAKE) --no-print-directory $(O)/stress OPT=-O2
	$(O)/stress

# Every method along the failure cases' paths (tests/stability/*.scene).
$(O)/stability: tests/stability/stability.c tests/bench/bench_main.c $(PLATFORM_OBJ) $(O)/libombra.a
	$(Q)$(CC) $(CFLAGS_ALL) -DOM_BENCH_NO_MAIN -o $@ $(filter %.c %.o %.a,$^) $(LDLIBS) $(PTHREAD)

stability:
	$(MAKE) --no-print-directory $(O)/stability OPT=-O2
	@mkdir -p out/report
	$(O)/stability --csv out/report/stability.csv $(sort $(wildcard tests/stability/*.scene))

# libFuzzer targets (clang, ASan, UBSan): FUZZ_SECONDS per target (default 60).
fuzz: $(O)/ombra
	sh tests/fuzz/run.sh

# The suite under valgrind memcheck (no sanitizers in this build).
test-valgrind:
	$(MAKE) --no-print-directory $(O)/valgrind/run-tests $(O)/valgrind/ombra O=$(O)/valgrind OPT=-O1
	OM_TEST_QUICK=1 valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite -q \
	  $(O)/valgrind/run-tests
	@$(call THREADED_RENDERS,$(O)/valgrind/ombra,valgrind --error-exitcode=1 -q,$(O)/valgrind)

# make install PREFIX=/usr/local DESTDIR=: the library, the header, the command and a
# pkg-config file (`pkg-config --cflags --libs ombra`); make uninstall removes them.
PREFIX  ?= /usr/local
VERSION := $(shell sed -n 's/^\#define OMBRA_VERSION_STRING "\(.*\)"/\1/p' include/ombra.h)

install: $(O)/libombra.a $(O)/ombra
	install -d $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/bin
	install -m 644 $(O)/libombra.a $(DESTDIR)$(PREFIX)/lib/libombra.a
	install -m 644 include/ombra.h include/ombra_measure.h $(DESTDIR)$(PREFIX)/include/
	install -m 755 $(O)/ombra $(DESTDIR)$(PREFIX)/bin/ombra
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' tools/ombra.pc.in \
	  >$(DESTDIR)$(PREFIX)/lib/pkgconfig/ombra.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/lib/libombra.a $(DESTDIR)$(PREFIX)/include/ombra.h $(DESTDIR)$(PREFIX)/include/ombra_measure.h \
	  $(DESTDIR)$(PREFIX)/bin/ombra $(DESTDIR)$(PREFIX)/lib/pkgconfig/ombra.pc

# Installs into a scratch directory, builds the embedding example against that copy
# with pkg-config, runs it, uninstalls (tests/embed/install.sh).
install-check: $(O)/embed-render-once
	sh tests/embed/install.sh $(O)

clean:
	rm -rf build out

.PHONY: all run test check test-sanitize test-32 test-tsan bench cross-test fuzz fuzz-regress test-valgrind stress stability clean \
        install uninstall install-check

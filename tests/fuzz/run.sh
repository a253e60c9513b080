#!/bin/sh
# run.sh — `make fuzz`: builds each libFuzzer target with clang, ASan and UBSan and runs
# it for FUZZ_SECONDS (default 60) from a corpus seeded with the project's own scenes.
# Crashes land in build/fuzz/<target>/crashes; each one found becomes a regression
# test (tests/fuzz/regress/, replayed by `make fuzz-regress`, part of `make test`).
set -u
cd "$(dirname "$0")/../.."
secs=${FUZZ_SECONDS:-60}
out=build/fuzz
mkdir -p "$out"
SRC="$(find engine -name '*.c' | sort | tr '\n' ' ')"
FLAGS="-std=c99 -g -O1 -ffp-contract=off -Iinclude -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all"
status=0
for t in scene obj render api; do
    mkdir -p "$out/$t/corpus" "$out/$t/crashes"
    # seeds: the default scene, the project's small scenes and OBJ files, and every
    # input that once crashed (tests/fuzz/regress)
    build/ombra scene >"$out/$t/corpus/default"
    for f in tests/fuzz/seeds/* tests/fuzz/regress/*; do [ -f "$f" ] && cp "$f" "$out/$t/corpus/"; done
    if ! clang $FLAGS $SRC tests/fuzz/fuzz_$t.c -lm -o "$out/fuzz_$t" 2>"$out/$t.err"; then
        echo "fuzz: FAIL fuzz_$t does not build: $(head -c 400 "$out/$t.err")"
        status=1
        continue
    fi
    "$out/fuzz_$t" -max_total_time="$secs" -max_len=4096 -timeout=20 -rss_limit_mb=4096 \
        -artifact_prefix="$out/$t/crashes/" -print_final_stats=1 "$out/$t/corpus" \
        >"$out/$t.log" 2>&1
    rc=$?
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$out/$t.log" | awk '{print $2}')
    cov=$(grep -o 'cov: [0-9]*' "$out/$t.log" | tail -1 | awk '{print $2}')
    if [ $rc -ne 0 ]; then
        echo "fuzz: FAIL fuzz_$t (exit $rc) — see $out/$t.log and $out/$t/crashes/"
        grep -m3 -E 'ERROR|SUMMARY' "$out/$t.log"
        status=1
    else
        echo "fuzz: fuzz_$t ran ${secs}s: ${execs:-?} executions, coverage ${cov:-?} edges, no crash"
    fi
done
# Every input that once crashed a target is replayed against all of them.
for t in scene obj render api; do
    [ -x "$out/fuzz_$t" ] || continue
    set -- tests/fuzz/regress/*
    [ -f "$1" ] || break
    if ! "$out/fuzz_$t" "$@" >"$out/$t.regress.log" 2>&1; then
        echo "fuzz: FAIL fuzz_$t on a regression input — see $out/$t.regress.log"
        status=1
    fi
done
exit $status

#!/bin/sh
# methods.sh — methods are their own files: the public header names no method's
# settings (they live in each method's table), and a firmware built with only `sm`
# (registry.c under OM_WITH_*=0 for the others) carries none of the other methods'
# code and renders the frame the full library renders.
# Usage: sh tests/sh/methods.sh BUILD_DIR (after make has built embed-render-once and
# embed-only-sm there).
set -u
cd "$(dirname "$0")/../.."
O=$1
fail=0
bad() { fail=1; echo "methods: FAIL — $1"; }

# Per-method fields (map_size, asm_cap, spsm_aa ...) or setting names in ombra.h.
hits=$(grep -nE '\b(map_size|bias_const|bias_slope|normal_offset|pcf|(asm|csm|izb|rtw|spsm|hybrid)_[a-z]+)\b|"(asm|csm|izb|rtw|spsm|hybrid)\.[a-z]+"' include/ombra.h)
[ -z "$hits" ] || bad "include/ombra.h names a method's settings:
$hits"

# Only sm: no table, no function of another method in the program.
full=$("$O/embed-render-once" | sed -n 's/.*frame hash //p')
only=$("$O/embed-only-sm" | sed -n 's/.*frame hash //p')
[ -n "$full" ] && [ "$full" = "$only" ] || bad "the sm-only firmware renders '$only', the full library '$full'"
if command -v nm >/dev/null 2>&1; then
    syms=$(nm "$O/embed-only-sm" | awk '{print $NF}')
    others=$(echo "$syms" | grep -E '^om__method_(none|ref|csm|asm|rtw|spsm|izb|hybrid)$|^om__(csm|asm|spsm|izb|bvh)_|^(csm|asm|rtw|spsm|izb|hybrid|ref)_(bytes|init|resolve)$')
    [ -z "$others" ] || bad "the sm-only firmware links other methods' code: $(echo $others | head -c 300)"
    echo "$syms" | grep -q '^om__method_sm$' || bad "the sm-only firmware has no om__method_sm"
fi
[ $fail -eq 0 ] && echo "methods: the header names no method's settings; an sm-only firmware links sm alone, same frame ($only)"
exit $fail

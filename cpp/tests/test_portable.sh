#!/bin/sh
# The portable core's two promises, checked on the built static library (see CMakeLists.txt):
#  1. every object but the wider lane kernels' is baseline x86-64 code: no VEX/EVEX instruction
#     (AVX and later), so the core runs on any x86-64 until it chooses a wider kernel;
#  2. each wider lane kernels' object defines two global symbols, its tables (the truncated map's
#     and the flow's Taylor kernel's), so none of the inline functions compiled into it with wider
#     instructions can stand in for the core's own; and it
#     does hold its instructions (ymm registers for AVX2, zmm for AVX-512, none of AVX-512's in AVX2).
# usage: test_portable.sh LIBRARY.a WORKDIR AR NM OBJDUMP LEVEL...
set -eu
lib=$1 work=$2 ar=$3 nm=$4 objdump=$5
shift 5
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$ar" x "$lib"
fail=0
for level in "$@"; do
    [ -f "hovering_lanes_$level.o" ] || { echo "FAIL: $lib has no hovering_lanes_$level.o"; fail=1; }
done
checked=0
for o in *.o; do
    asm=$("$objdump" -d --no-show-raw-insn "$o")
    case "$o" in
    hovering_lanes_*.o)
        level=${o#hovering_lanes_}
        level=${level%.o}
        globals=$("$nm" -g --defined-only "$o" | awk '{print $3}' | sort | tr '\n' ' ')
        if [ "$globals" != "hovering_lanes_$level hovering_taylor_$level " ]; then
            echo "FAIL: $o defines global symbols besides its table: $globals" | cut -c1-400
            fail=1
        fi
        case "$level" in
        avx2) want='%ymm' unwanted='%zmm|%k[0-7]' ;;
        avx512) want='%zmm' unwanted='^$' ;;
        *) echo "FAIL: unknown lane level $level"; fail=1; continue ;;
        esac
        printf '%s\n' "$asm" | grep -qE "$want" || { echo "FAIL: $o holds no $want instruction"; fail=1; }
        if printf '%s\n' "$asm" | grep -E "$unwanted" | grep -q .; then
            echo "FAIL: $o holds instructions beyond $level:"
            printf '%s\n' "$asm" | grep -E "$unwanted" | head -3
            fail=1
        fi
        ;;
    *)
        vex=$(printf '%s\n' "$asm" | grep -E '^[[:space:]]+[0-9a-f]+:[[:space:]]+v[a-z]' | head -3 || true)
        if [ -n "$vex" ]; then
            echo "FAIL: $o (baseline code) holds AVX instructions:"
            printf '%s\n' "$vex"
            fail=1
        fi
        ;;
    esac
    checked=$((checked + 1))
done
echo "$checked objects checked"
[ "$checked" -ge 10 ] || { echo "FAIL: only $checked objects in $lib"; fail=1; }
exit $fail

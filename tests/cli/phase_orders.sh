#!/bin/sh
# `atmos phase PRESET --orders` summary: the forward-fraction columns F_n are orders that exist
# (1..N for N <= 6, else 1, 2, 5, 10, 26 up to N and N itself), never orders beyond the last
# (which printed the isotropic 0.5). Run by ctest with ATMOS_CLI = the atmos binary.
. "$(dirname "$0")/common.inc"
cli=$A

# header: the line after the title; columns between "nm" and "legendre_l"
cols() { sed -n 2p "$T/out" | sed 's/^ *nm *//; s/ *legendre_l *$//' | tr -s ' '; }

"$cli" phase air --orders --max-order 4 --no-cache -q >"$T/out" 2>"$T/err" &&
    [ "$(cols)" = "F_1 F_2 F_3 F_4" ] && [ "$(sed -n 3p "$T/out" | wc -w)" -eq 6 ] &&
    ok "--max-order 4: F_1 F_2 F_3 F_4" || bad "--max-order 4: $(cat "$T/out" "$T/err")"
"$cli" phase air --orders --max-order 12 --no-cache -q >"$T/out" 2>"$T/err" &&
    [ "$(cols)" = "F_1 F_2 F_5 F_10 F_12" ] && ok "--max-order 12: F_1 F_2 F_5 F_10 F_12" ||
    bad "--max-order 12: $(cat "$T/out" "$T/err")"
# without --max-order the last column is the last order of the title line ("orders 1..N")
"$cli" phase air --orders --no-cache -q >"$T/out" 2>"$T/err"
n=$(sed -n 's/.*orders 1\.\.\([0-9]*\).*/\1/p' "$T/out")
last=$(cols | awk '{print $NF}')
[ -n "$n" ] && [ "$last" = "F_$n" ] && ok "default: last column F_$n" || bad "default: $(cat "$T/out" "$T/err")"
"$cli" phase --help >"$T/out" 2>&1
grep -q 'F_n' "$T/out" && grep -q 'last order' "$T/out" && ok "help names the columns" || bad "help: $(cat "$T/out")"
exit $fail

#!/bin/sh
# The man pages (scripts/make-man.sh, help2man): one atmos-COMMAND.1 for every command of
# the CLI, and atmos.1 listing each command as its own item. The list of commands is taken
# from the command table in the source (tools/atmos/main.c), not from `atmos --help`, so a
# help layout the script misreads cannot hide a missing page.
# Run by ctest with ATMOS_CLI = the atmos binary, ATMOS_SOURCE_DIR and ATMOS_TEST_TMP.
. "$(dirname "$0")/common.inc"
cli=$A
src=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR must name the source tree}

if ! command -v help2man >/dev/null 2>&1; then
    bad "help2man is missing (scripts/install-deps.sh installs it)"
    exit 1
fi
# The command table's rows: {"NAME", cli_cmd_..., "summary"},
sed -n 's/^ *{"\([a-z][a-z]*\)", *cli_cmd_.*/\1/p' "$src/tools/atmos/main.c" >"$T/table"
n=$(wc -l <"$T/table")
[ "$n" -ge 10 ] && ok "the command table lists $n commands" || bad "only $n commands found in tools/atmos/main.c"

# Every command's summary line in --help has at least two spaces after the name, the
# layout help2man and the script read (the longest name included).
"$cli" --help >"$T/help" 2>&1 || bad "atmos --help exits 0"
while read -r c; do
    grep -Eq "^  $c {2,}[^ ]" "$T/help" && ok "--help: '$c' and its summary apart" || bad "--help: '$c' not followed by two spaces"
done <"$T/table"

sh "$src/scripts/make-man.sh" "$cli" "$T/man" 0.0.0 >"$T/log" 2>&1 || { bad "make-man.sh failed"; cat "$T/log" >&2; }
while read -r c; do
    m=$T/man/atmos-$c.1
    [ -s "$m" ] && grep -q "^\.SH DESCRIPTION" "$m" && ok "man page atmos-$c.1" || bad "no man page atmos-$c.1"
    # in atmos.1 each command is an item of its own (".TP" then the name alone on a line)
    awk -v c="$c" 'p == ".TP" && $0 == c {f = 1} {p = $0} END {exit !f}' "$T/man/atmos.1" &&
        ok "atmos.1 lists '$c' as an item" || bad "atmos.1 does not list '$c' as an item"
done <"$T/table"
# no page for a command that is not in the table
for m in "$T"/man/atmos-*.1; do
    c=${m##*/atmos-}
    c=${c%.1}
    grep -qx "$c" "$T/table" || bad "atmos-$c.1 is not a command"
done
exit $fail

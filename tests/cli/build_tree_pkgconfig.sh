#!/bin/sh
# A C program built against the build tree, as docs/install.md and the README say: the
# build folder's atmos-uninstalled.pc gives the sources' headers and the build's library
# (with an rpath), so the program compiles, links and runs without installing. (The
# build folder's atmos.pc, meant for the installed prefix, pointed two folders up.)
. "$(dirname "$0")/common.inc"
B=$(cd "$(dirname "$A")" && pwd)
S=$(cd "$(dirname "$0")/../.." && pwd)
command -v pkg-config >/dev/null 2>&1 || { echo "skipped: no pkg-config"; exit 0; }
command -v cc >/dev/null 2>&1 || { echo "skipped: no C compiler"; exit 0; }
[ -f "$B/atmos-uninstalled.pc" ] && ok "atmos-uninstalled.pc in the build folder" || bad "no $B/atmos-uninstalled.pc"
flags=$(PKG_CONFIG_PATH="$B" pkg-config --cflags --libs atmos) || bad "pkg-config atmos failed"
case "$flags" in *"-I$S/include"*) ok "cflags: $flags" ;; *) bad "cflags: $flags" ;; esac
cat >"$T/prog.c" <<'C'
#include <atmos/atmos.h>
#include <stdio.h>
int main(void)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    printf("%s %d\n", atmos_version(), s.width > 0);
    return 0;
}
C
# shellcheck disable=SC2086
if cc -std=c11 "$T/prog.c" $flags -lm -o "$T/prog" 2>"$T/err"; then
    ok "compiled and linked with the build tree's pkg-config flags"
else
    bad "compile:"; sed 's/^/  /' "$T/err" >&2
fi
want="$("$A" --version | grep -o '[0-9][0-9.]*[0-9]' | head -n 1) 1"
got=$(env -u LD_LIBRARY_PATH "$T/prog" 2>&1)
[ "$got" = "$want" ] && ok "runs without LD_LIBRARY_PATH: $got" || bad "ran: '$got', expected '$want'"
exit $fail

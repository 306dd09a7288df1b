#!/bin/sh
# The README's C snippets (## Using the library) compile as written, one after the other in a
# main(), against the build tree (as build_tree_pkgconfig.sh), and check every status: the
# program run where the scene file is missing stops at atmos_scene_load and says why (the file
# and "cannot open"), not with a later, confusing error about a scene left unset.
. "$(dirname "$0")/common.inc"
B=$(cd "$(dirname "$A")" && pwd)
S=$(cd "$(dirname "$0")/../.." && pwd)
command -v pkg-config >/dev/null 2>&1 || { echo "skipped: no pkg-config"; exit 0; }
command -v cc >/dev/null 2>&1 || { echo "skipped: no C compiler"; exit 0; }
flags=$(PKG_CONFIG_PATH="$B" pkg-config --cflags --libs atmos) || { bad "pkg-config atmos failed"; exit 1; }
# the ```c blocks of the section: #include lines at the top, the rest the body of main
awk '/^## Using the library/ {on = 1; next} on && /^## / {on = 0}
     on && /^```c$/ {c = 1; n++; next} c && /^```$/ {c = 0; next} c {print > (/^#include/ ? inc : body)}' \
    inc="$T/inc.c" body="$T/body.c" "$S/README.md"
[ -s "$T/body.c" ] && ok "README: C snippets found" || { bad "README: no C snippet under '## Using the library'"; exit 1; }
{ sort -u "$T/inc.c"; echo 'int main(void)'; echo '{'; cat "$T/body.c"; echo 'return 0;'; echo '}'; } >"$T/prog.c"
# shellcheck disable=SC2086
if cc -std=c11 -Wall -Wextra -Werror "$T/prog.c" $flags -lm -o "$T/prog" 2>"$T/err"; then
    ok "README snippets compile with -Wall -Wextra -Werror"
else
    bad "README snippets:"; sed 's/^/  /' "$T/err" "$T/prog.c" >&2; exit 1
fi
mkdir -p "$T/run"
(cd "$T/run" && env -u LD_LIBRARY_PATH XDG_CACHE_HOME="$T/cache" "$T/prog" >"$T/out" 2>"$T/err"); rc=$?
[ $rc -ne 0 ] && ok "the snippets stop when the scene file is missing (rc $rc)" || bad "the snippets ran on without a scene"
grep -q 'scenes/fig11_cumulus_dawn.json: cannot open' "$T/err" && ok "the error names the missing scene file" ||
    { bad "no 'cannot open' of the scene in:"; sed 's/^/  /' "$T/err" >&2; }
grep -q '/image/width' "$T/err" && bad "a later error about the unset scene: $(cat "$T/err")" || ok "no later error"
[ ! -e "$T/run/cumulus.exr" ] && ok "no image written" || bad "an image written without a scene"
exit $fail

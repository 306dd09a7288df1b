#!/bin/sh
# The atmos command line as a user meets it: version and help, exit statuses
# (0 success, 1 runtime error, 2 usage error; `atmos --help`), messages that name the
# offending option / JSON path / file, the three output formats and their headers
# (PNG: IHDR chunk, ISO/IEC 15948 §11.2.2; PFM: "PF\nW H\nscale\n"), atomic writes
# (DESIGN.md §5: no temporary files left behind) and thread-count independence of the
# result (DESIGN.md §6: bit-identical output for any number of threads).
# Run by ctest with ATMOS_CLI = the atmos binary and ATMOS_TEST_TMP = a scratch dir.
set -u
. "$(dirname "$0")/common.inc"
cli=$A

# run NAME WANT_STATUS ARGS... : runs atmos ARGS, stdout/stderr in $T/out, $T/err.
run() {
    name=$1 want=$2
    shift 2
    "$cli" "$@" >"$T/out" 2>"$T/err"
    st=$?
    if [ "$st" -eq "$want" ]; then ok "$name (exit $st)"; else
        bad "$name: exit $st, expected $want"; sed 's/^/  stderr: /' "$T/err" >&2; fi
}
# err_has NAME TEXT : stderr of the last run contains TEXT (fixed string).
err_has() {
    if grep -qF -- "$2" "$T/err"; then ok "$1: stderr names '$2'"; else
        bad "$1: stderr lacks '$2'"; sed 's/^/  stderr: /' "$T/err" >&2; fi
}

# --- version and help -------------------------------------------------------------
run "--version" 0 --version
if grep -Eq '[0-9]+\.[0-9]+\.[0-9]+' "$T/out"; then ok "--version prints a version"; else bad "--version: no version in '$(cat "$T/out")'"; fi

run "--help" 0 --help
# The commands listed under "Commands:" (indented lines up to the next blank line).
cmds=$(awk '/^Commands:/ {on=1; next} on && /^[[:space:]]*$/ {exit} on {print $1}' "$T/out")
if [ -n "$cmds" ]; then ok "--help lists commands: $(echo $cmds)"; else bad "--help lists no commands"; fi
for c in $cmds; do
    run "$c --help" 0 "$c" --help
    if grep -q "Usage" "$T/out"; then ok "$c --help prints Usage"; else bad "$c --help prints no Usage"; fi
    # a terminal of 100 columns shows every line unbroken (bench's sample output lines too)
    long=$(awk 'length > 100' "$T/out" | head -3)
    [ -z "$long" ] && ok "$c --help fits in 100 columns" || bad "$c --help has lines over 100 columns: $long"
    # -h is --help for every command
    run "$c -h" 0 "$c" -h
    if grep -q "Usage" "$T/out"; then ok "$c -h prints Usage"; else bad "$c -h prints no Usage"; fi
done
for c in "bench sky-accuracy" "volume stats"; do
    run "$c --help" 0 $c --help
    long=$(awk 'length > 100' "$T/out" | head -3)
    [ -z "$long" ] && ok "$c --help fits in 100 columns" || bad "$c --help has lines over 100 columns: $long"
done
for c in render sky sun; do
    case " $(echo $cmds) " in *" $c "*) ok "--help lists $c" ;; *) bad "--help does not list $c" ;; esac
done

# --- usage errors: exit 2 with a message --------------------------------------------
run "unknown command" 2 frobnicate
err_has "unknown command" "frobnicate"
run "unknown top-level option" 2 --frobnicate
run "no command" 2
run "render: unknown option" 2 render --frobnicate
err_has "render: unknown option" "--frobnicate"
run "sky: unknown option" 2 sky --frobnicate --sun-elevation 10 --view-elevation 10 --view-azimuth 0
for spec in "--width 0:--width" "--height -3:--height" "--spectral 0:--spectral" "--spectral 129:--spectral" \
            "--camera nope:--camera" "--exposure x:--exposure" "--spp 0:--spp" "--tone sepia:--tone" \
            "--threads 0:--threads" "--width 12abc:--width"; do
    args=${spec%%:*} opt=${spec#*:}
    # shellcheck disable=SC2086
    run "render $args" 2 render $args -q -o "$T/never.png"
    err_has "render $args" "$opt"
    [ -e "$T/never.png" ] && bad "render $args wrote an image"
done

# --- runtime errors on input files: exit 1 naming the path ------------------------
printf '{"camera": {"fov_degs": 50}}\n' >"$T/unknown_key.json"
run "scene with unknown key" 1 render "$T/unknown_key.json" -q -o "$T/never.png"
err_has "scene with unknown key" "/camera/fov_degs"
err_has "scene with unknown key" "unknown_key.json"
printf '{"image": {"width": 64, "height": 32}, "camera": {"fov_deg": 270}}\n' >"$T/bad_fov.json"
run "scene with fov out of range" 1 render "$T/bad_fov.json" -q -o "$T/never.png"
err_has "scene with fov out of range" "/camera/fov_deg"
printf '{"image": {"width": 64,\n' >"$T/truncated.json"
run "truncated scene" 1 render "$T/truncated.json" -q -o "$T/never.png"
err_has "truncated scene" "truncated.json"
run "missing scene file" 1 render "$T/no_such_scene.json" -q -o "$T/never.png"
err_has "missing scene file" "$T/no_such_scene.json"
[ -e "$T/never.png" ] && bad "a failed render wrote an image"

# --- rendering: outputs, formats, atomic writes -----------------------------------
run "render png+exr+pfm" 0 render --width 64 --height 32 -o "$T/a.png" --exr "$T/a.exr" --pfm "$T/a.pfm" -q
for f in a.png a.exr a.pfm; do
    if [ -s "$T/$f" ]; then ok "wrote $f"; else bad "did not write $f"; fi
done
if [ -s "$T/out" ]; then bad "-q render wrote to stdout"; fi
python3 - "$T" <<'EOF' || fail=1
import struct, sys
T = sys.argv[1]
bad = 0
def check(cond, msg):
    global bad
    print(("ok: " if cond else "FAIL: ") + msg, file=sys.stdout if cond else sys.stderr)
    if not cond: bad = 1
png = open(T + "/a.png", "rb").read()
check(png[:8] == b"\x89PNG\r\n\x1a\n", "PNG signature")
length, ctype = struct.unpack(">I4s", png[8:16])
check(ctype == b"IHDR" and length == 13, "PNG first chunk is IHDR")
w, h, depth, colour = struct.unpack(">IIBB", png[16:26])
check((w, h) == (64, 32), "PNG is 64x32 (got %dx%d)" % (w, h))
check(depth in (8, 16) and colour in (2, 6), "PNG is 8/16-bit RGB(A) (depth %d, colour type %d)" % (depth, colour))
exr = open(T + "/a.exr", "rb").read()
check(exr[:4] == b"\x76\x2f\x31\x01", "EXR magic 76 2f 31 01")
import pfm
img = pfm.read(T + "/a.pfm")
check(img.kind == "PF", "PFM is 3-channel 'PF'")
check((img.w, img.h) == (64, 32), "PFM header says 64 32 (got %d %d)" % (img.w, img.h))
check(img.scale < 0, "PFM scale negative (little-endian data), got %g" % img.scale)
check(len(img.payload) == 64 * 32 * 3 * 4, "PFM payload is 64*32*3 floats (%d bytes)" % len(img.payload))
s = pfm.stats(img.v)
check(s.nonfinite == 0 and s.min >= 0, "PFM pixels finite and non-negative")
check(s.max > 0, "PFM image is not black")
sys.exit(bad)
EOF
leftover=$(find "$T" -name '*.tmp*' -o -name '.*tmp*' | head -5)
if [ -z "$leftover" ]; then ok "no temporary files left"; else bad "temporary files left: $leftover"; fi

# Same scene, 1 and 2 threads: identical bytes (DESIGN.md §6).
run "render --threads 1" 0 render --width 96 --height 64 --spectral 8 --sun-elevation 3 --pfm "$T/t1.pfm" --threads 1 -q
run "render --threads 2" 0 render --width 96 --height 64 --spectral 8 --sun-elevation 3 --pfm "$T/t2.pfm" --threads 2 -q
if cmp -s "$T/t1.pfm" "$T/t2.pfm"; then ok "--threads 1 and 2 give identical PFM"; else bad "--threads 1 and 2 differ"; fi
run "render fisheye --threads 1" 0 render --camera fisheye --width 48 --height 48 --pfm "$T/f1.pfm" --threads 1 -q
run "render fisheye --threads 2" 0 render --camera fisheye --width 48 --height 48 --pfm "$T/f2.pfm" --threads 2 -q
if cmp -s "$T/f1.pfm" "$T/f2.pfm"; then ok "fisheye: --threads 1 and 2 identical"; else bad "fisheye: --threads 1 and 2 differ"; fi

# The other cameras render.
run "render --camera fisheye" 0 render --camera fisheye --width 64 --height 64 -o "$T/fish.png" -q
[ -s "$T/fish.png" ] && ok "fisheye PNG written" || bad "fisheye PNG missing"
run "render --camera equirect" 0 render --camera equirect --width 128 --height 64 -o "$T/eq.png" --exr "$T/eq.exr" -q
[ -s "$T/eq.png" ] && [ -s "$T/eq.exr" ] && ok "equirect PNG and EXR written" || bad "equirect outputs missing"

# A failing write (a folder that cannot be made: its parent is a file) is a runtime error,
# and leaves nothing.
: > "$T/a_file"
run "unwritable output" 1 render --width 8 --height 8 -o "$T/a_file/dir/x.png" -q
[ -s "$T/err" ] && ok "unwritable output: message" || bad "unwritable output: no message"
leftover=$(find "$T" -name '*.tmp*' | head -5)
if [ -z "$leftover" ]; then ok "no temporary files left at the end"; else bad "temporary files left: $leftover"; fi

exit $fail

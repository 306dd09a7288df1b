#!/bin/sh
# Long commands show a progress bar with an ETA on a terminal and stay quiet off one
# (issue: "progress with an ETA on a terminal, quiet when not on a terminal"). Each command
# runs twice: on a pseudo-terminal made by script(1) from util-linux, with
# ATMOS_PROGRESS_DELAY=0 so that the bar appears however fast this machine is, and with
# stderr in a file, where no bar and no progress line may appear.
set -u
A=${ATMOS_CLI:?ATMOS_CLI not set}
T=${ATMOS_TEST_TMP:-/tmp}/cli_progress.$$
mkdir -p "$T"
fail=0; pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*" >&2; fail=$((fail + 1)); }
command -v script > /dev/null 2>&1 || { echo "SKIP: script(1) not installed"; exit 0; }

# check STAGE NAME COMMAND...: the bar of STAGE with an ETA on a terminal, silence off it.
check() {
    stage=$1 name=$2
    shift 2
    rm -rf "$T/cache"
    # script(1) takes one command line: quote each word for sh.
    line=""
    for w in "$@"; do line="$line '$w'"; done
    XDG_CACHE_HOME="$T/cache" ATMOS_PROGRESS_DELAY=0 script -qec "$line" /dev/null > "$T/$name.tty" 2>&1 \
        || bad "$name on a terminal failed: $(tail -n 3 "$T/$name.tty")"
    grep -q "$stage \[[#.]*\] *[0-9]*%.*ETA [0-9.]*s" "$T/$name.tty" && ok \
        || bad "$name: no '$stage' bar with an ETA on a terminal: $(tail -c 300 "$T/$name.tty")"
    rm -rf "$T/cache"
    XDG_CACHE_HOME="$T/cache" ATMOS_PROGRESS_DELAY=0 "$@" > "$T/$name.out" 2> "$T/$name.err" \
        || bad "$name off a terminal failed: $(tail -n 3 "$T/$name.err")"
    # no bar off a terminal (log lines, "atmos: STAGE: N %, T s elapsed", every 5 s are fine)
    if grep -q "ETA\|\[#" "$T/$name.err"; then bad "$name: a bar off a terminal: $(head -c 300 "$T/$name.err")"; else ok; fi
}

check "volume generate" generate "$A" volume generate cumulus --voxel-size 40 -o "$T/cu.json"
check "volume load" info "$A" volume info "$T/cu.json"
check "sky tables" sky "$A" sky --model spherical --sun-elevation 10 --view-elevation 20 --view-azimuth 0 --json
check "render sky" render "$A" render --width 32 --height 18 -o "$T/sky.png"
check "phase cloud" phase "$A" phase cloud --fast
check "sky tables" bench_sky "$A" bench sky --models spherical --size 16 --repeat 1
check "sky accuracy: first batch" bench_acc "$A" bench sky-accuracy --quick --paths 64 --models riley --altitudes 0 --suns 45
check "volume load" bench_volume "$A" bench volume --file "$T/cu.json" --repeat 1

# A log off a terminal when asked for: ATMOS_PROGRESS_INTERVAL=0 gives a line per report.
ATMOS_PROGRESS_INTERVAL=0 "$A" volume generate cumulus --voxel-size 40 -o "$T/cu2.json" 2> "$T/log.err" \
    || bad "generate with a progress log"
grep -q "^atmos: volume generate: [0-9]* %, [0-9.]* s elapsed$" "$T/log.err" && ok || bad "no log line: $(cat "$T/log.err")"
# The beam renderer's plan reports its shadow maps (a city's took seconds without a word).
ATMOS_PROGRESS_INTERVAL=0 "$A" render "${ATMOS_SOURCE_DIR:?}/scenes/dobashi_fig04_spotlight.json" --width 12 --height 18 \
    -o "$T/beams.png" 2> "$T/beams.err" || bad "beams render with a progress log"
grep -q "^atmos: beams shadow maps: 100 %, [0-9.]* s elapsed$" "$T/beams.err" && ok || bad "no shadow map log: $(cat "$T/beams.err")"

# Outputs whose folder does not exist yet: made before the work, or refused before it.
"$A" volume generate cumulus --voxel-size 40 -o "$T/new/dir/cu.json" 2> "$T/mk.err" && [ -f "$T/new/dir/cu.json" ] && ok \
    || bad "generate into a new folder: $(cat "$T/mk.err")"
: > "$T/afile"
"$A" volume generate storm -o "$T/afile/x.json" 2> "$T/nd.err"
[ $? -eq 1 ] && grep -q "cannot create the folder" "$T/nd.err" && ok || bad "a file as the folder: $(cat "$T/nd.err")"

rm -rf "$T"
echo "progress: $pass passed, $fail failed"
[ "$fail" -eq 0 ]

#!/bin/sh
# atmos render --mpi as a cluster user runs it (docs/cluster.md), on one machine with
# `mpirun -np N --oversubscribe`: the outputs of 2 and 3 ranks are the bytes of a single
# process for a single image (slice renderer and path tracer, split in bands of rows) and for
# an animation (frames round the ranks); an output that cannot be written is a clear error
# on every rank count with nothing left behind; --mpi without mpirun is a plain render.
# Run by ctest with ATMOS_CLI, ATMOS_SOURCE_DIR, ATMOS_MPIRUN.
set -u
cli=${ATMOS_CLI:?ATMOS_CLI must name the atmos binary}
src=${ATMOS_SOURCE_DIR:?}
mpirun=${ATMOS_MPIRUN:-mpirun}
T=${ATMOS_TEST_TMP:-/tmp}/mpi_render.$$
rm -rf "$T"
mkdir -p "$T" || exit 1
trap 'rm -rf "$T"' EXIT
fail=0
ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }
# Open MPI refuses root without these; the tests run in containers as root.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# mpi N OUTDIR ARGS...: atmos render ARGS --mpi under N ranks (120 s at most: a hang fails).
mpi() {
    n=$1 out=$2
    shift 2
    timeout 120 "$mpirun" -np "$n" "$cli" render "$@" --threads 1 --mpi >"$out.log" 2>&1
}
same() { if cmp -s "$1" "$2"; then ok "$3"; else bad "$3: $1 and $2 differ"; fi; }
# same_png A B WHAT: the same header and image data (IDAT) chunks; text chunks (the render's
# time) may differ.
png_data() {
    python3 -c 'import struct, sys
d = open(sys.argv[1], "rb").read()[8:]
while d:
    n = struct.unpack(">I", d[:4])[0]
    if d[4:8] in (b"IHDR", b"IDAT"): sys.stdout.buffer.write(d[:12 + n])
    d = d[12 + n:]' "$1"
}
# png_text FILE KEY: the value of a tEXt chunk.
png_text() {
    python3 -c 'import struct, sys
d = open(sys.argv[1], "rb").read()[8:]
while d:
    n = struct.unpack(">I", d[:4])[0]
    if d[4:8] == b"tEXt":
        k, v = d[8:8 + n].split(b"\0", 1)
        if k.decode() == sys.argv[2]: print(v.decode())
    d = d[12 + n:]' "$1" "$2"
}
same_png() {
    png_data "$1" >"$1.data" && png_data "$2" >"$2.data" && same "$1.data" "$2.data" "$3"
}

scene=$src/scenes/fig11_cumulus_dawn.json
"$cli" render "$scene" --width 80 --height 45 --threads 1 -q --pfm "$T/one.pfm" -o "$T/one.png" || bad "single-process slice render"
for n in 2 3; do
    if mpi $n "$T/slice$n" "$scene" --width 80 --height 45 --pfm "$T/slice$n.pfm" -o "$T/slice$n.png"; then
        same "$T/one.pfm" "$T/slice$n.pfm" "slice renderer, one image, $n ranks: the single process's PFM"
        same_png "$T/one.png" "$T/slice$n.png" "slice renderer, one image, $n ranks: the single process's PNG pixels"
    else bad "mpirun -np $n slice render"; sed 's/^/  /' "$T/slice$n.log" >&2; fi
done

# The path tracer: every pixel's samples are its own, wherever its band is rendered.
path="-D renderer=path -D path.spp=4 --width 40 --height 24"
# shellcheck disable=SC2086
"$cli" render "$scene" $path --threads 1 -q --pfm "$T/p1.pfm" -o "$T/p1.png" || bad "single-process path render"
# shellcheck disable=SC2086
if mpi 2 "$T/p2" "$scene" $path --pfm "$T/p2.pfm" -o "$T/p2.png"; then
    same "$T/p1.pfm" "$T/p2.pfm" "path tracer, one image, 2 ranks: the single process's PFM"
else bad "mpirun -np 2 path render"; sed 's/^/  /' "$T/p2.log" >&2; fi

# An animation of 5 frames: frames round 2 ranks, written by rank 0 (the exposure locked at
# frame 1's as in one process).
anim="--width 48 --height 27 --frames 5 --sun-elevation 2 --sun-elevation-end 30"
# shellcheck disable=SC2086
"$cli" render "$scene" $anim --threads 1 -q -o "$T/a1/f.png" --pfm "$T/a1/f.pfm" || bad "single-process animation"
# shellcheck disable=SC2086
if mpi 2 "$T/a2" "$scene" $anim -o "$T/a2/f.png" --pfm "$T/a2/f.pfm"; then
    for i in 1 2 3 4 5; do
        same "$T/a1/f_000$i.pfm" "$T/a2/f_000$i.pfm" "animation frame $i, 2 ranks: the single process's PFM"
        same_png "$T/a1/f_000$i.png" "$T/a2/f_000$i.png" "animation frame $i, 2 ranks: the single process's PNG pixels"
    done
    grep -q "rendered by rank 1" "$T/a2.log" && ok "rank 1 rendered frames" || bad "no frame reported from rank 1"
    # Each frame carries its own renderer's metadata (its sun), wherever it was rendered.
    for i in 2 3 4; do
        e1=$(png_text "$T/a1/f_000$i.png" atmos:sun_elevation_deg) e2=$(png_text "$T/a2/f_000$i.png" atmos:sun_elevation_deg)
        [ -n "$e1" ] && [ "$e1" = "$e2" ] && ok "frame $i's sun in its metadata ($e2)" || bad "frame $i's sun: '$e2', expected '$e1'"
    done
else bad "mpirun -np 2 animation"; sed 's/^/  /' "$T/a2.log" >&2; fi

# An output that cannot be written (its folder is a file): a clear error, no hang, nothing left.
: >"$T/file"
mpi 2 "$T/bad" "$scene" --width 32 --height 18 -o "$T/file/x.png"
st=$?
if [ $st -ne 0 ] && [ $st -ne 124 ] && grep -q "file/x.png" "$T/bad.log"; then ok "unwritable output: exit $st naming it"
else bad "unwritable output: exit $st"; sed 's/^/  /' "$T/bad.log" >&2; fi
left=$(find "$T" -name '*.tmp*' | head -n 1)
[ -z "$left" ] && ok "no staging file left behind" || bad "left behind: $left"

# A rank that dies mid-animation (rank 1 killed): the job ends with an error, without a hang,
# and leaves no staging file.
mkdir -p "$T/die"
(mpi 2 "$T/die" "$scene" --renderer path --spp 256 --width 64 --height 36 --frames 8 -o "$T/die/f.png"
 echo $? >"$T/die.rc") &
victim=""
i=0
while [ -z "$victim" ] && [ $i -lt 300 ]; do
    for p in $(pgrep -f "$T/die/f.png" 2>/dev/null); do
        tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=1" && victim=$p
    done
    i=$((i + 1))
    sleep 0.1
done
if [ -n "$victim" ]; then
    sleep 2
    kill -9 "$victim"
    wait
    st=$(cat "$T/die.rc")
    if [ "$st" -ne 0 ] && [ "$st" -ne 124 ]; then ok "a killed rank ends the job (exit $st)"
    else bad "a killed rank: exit $st"; sed 's/^/  /' "$T/die.log" >&2; fi
    left=$(find "$T/die" -name '*.tmp*' | head -n 1)
    [ -z "$left" ] && ok "no staging file left by the killed job" || bad "left behind by the killed job: $left"
else
    wait
    bad "rank 1 of the job to kill was not found"
fi

# --mpi outside mpirun: one rank, a plain render.
"$cli" render "$scene" --width 80 --height 45 --threads 1 -q --mpi --pfm "$T/single.pfm" -o "$T/single.png" \
    && same "$T/one.pfm" "$T/single.pfm" "--mpi without mpirun: the plain render" || bad "--mpi without mpirun"
exit $fail

#!/bin/sh
# Distributed rendering on this machine (docs/cluster.md): a path-traced animation and one
# path-traced image, rendered by 1 rank x 1 thread, 2 ranks x 1 thread (mpirun --mpi) and
# 1 process x 2 threads. One line per run:
#   case=... ranks=R threads=T wall_s=... speedup=... (against 1 x 1) load=...
# and the sizes a scaling model needs (setup, per-frame / per-band render time, bytes sent).
#   sh bench/mpi/run.sh [ATMOS_BINARY] [REPEATS]
# Environment: CASES (default "anim image"), ATMOS_BENCH_IMAGE_W / _H (the still, 640x360).
set -eu
atmos=${1:-build/atmos}
reps=${2:-1}
scene=scenes/fig11_cumulus_dawn.json
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 OMP_WAIT_POLICY=passive
export XDG_CACHE_HOME=$T/cache
anim="-D renderer=path -D path.spp=16 --width 160 --height 90 --frames 16 --sun-elevation 2 --sun-elevation-end 30"
image="-D renderer=path -D path.spp=64 --width ${ATMOS_BENCH_IMAGE_W:-640} --height ${ATMOS_BENCH_IMAGE_H:-360}"
# warm the optics cache so every run measures rendering
"$atmos" render "$scene" --width 32 --height 18 -q -o "$T/warm.png"
now() { date +%s.%N; }
run() { # run CASE RANKS THREADS ARGS...
    c=$1 r=$2 t=$3
    shift 3
    best=""
    i=0
    while [ $i -lt "$reps" ]; do
        t0=$(now)
        if [ "$r" -gt 1 ]; then
            # shellcheck disable=SC2086
            mpirun -np "$r" "$atmos" render "$scene" "$@" --threads "$t" --mpi -q -o "$T/$c/f.png"
        else
            # shellcheck disable=SC2086
            "$atmos" render "$scene" "$@" --threads "$t" -q -o "$T/$c/f.png"
        fi
        w=$(awk -v a="$(now)" -v b="$t0" 'BEGIN { print a - b }')
        if [ -z "$best" ] || awk -v w="$w" -v b="$best" 'BEGIN { exit !(w < b) }'; then best=$w; fi
        i=$((i + 1))
    done
    echo "$best"
}
for c in ${CASES:-anim image}; do
    # shellcheck disable=SC2086
    eval "args=\$$c"
    # shellcheck disable=SC2086
    w11=$(run "$c" 1 1 $args)
    # shellcheck disable=SC2086
    w21=$(run "$c" 2 1 $args)
    # shellcheck disable=SC2086
    w12=$(run "$c" 1 2 $args)
    load=$(cut -d' ' -f1 /proc/loadavg)
    for x in "1 1 $w11" "2 1 $w21" "1 2 $w12"; do
        set -- $x
        printf 'case=%s ranks=%s threads=%s wall_s=%.2f speedup=%.2f load=%s\n' "$c" "$1" "$2" "$3" \
            "$(awk -v a="$w11" -v b="$3" 'BEGIN { print a / b }')" "$load"
    done
done

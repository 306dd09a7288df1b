#!/bin/sh
# The cloud simulation's speed (docs/clouds.md): one time step of a 128^3-cell grid (the
# cumulus_field preset at --grid 128 is 128 x 128 x 64; towering_cumulus at 128 is 128^3),
# and the cumulonimbus preset grown to maturity (its top at the tropopause, its anvil at its
# first maximum: 22-23 min;
# bench/sim/maturity.c prints the top, the updraught and the anvil's area minute by minute) at
# the default grid (64 x 64 x 40 cells of 400 m). Reports the load with each figure; time it
# with /usr/bin/time for the CPU.
# Usage: bench/sim/run.sh [path/to/atmos] [threads]
set -eu
ATMOS=${1:-build/atmos}
T=${2:-2}
echo "load: $(uptime)"
"$ATMOS" bench simulate --threads "$T" # 64^3 and 128^3: wall, best and CPU ms a step, the load
echo "load: $(uptime)"
"$ATMOS" simulate towering_cumulus --grid 128 --bench 5 --threads "$T"
echo "load: $(uptime)"
"$ATMOS" simulate cumulonimbus --grid 64 --minutes 23 --bench 1 --threads "$T"
echo "load: $(uptime)"

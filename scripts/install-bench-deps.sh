#!/bin/sh
# Installs what the optional benchmark against Blender Cycles (bench/cycles/run.sh,
# docs/cycles.md) needs beyond scripts/install-deps.sh: Blender (Debian 12 ships 3.4.1, with
# Cycles, OpenVDB volumes and Python). Large (several hundred MB); not used by the build,
# the tests or CI. Safe to run repeatedly.
exec sh "$(dirname "$0")/install-deps.sh" blender

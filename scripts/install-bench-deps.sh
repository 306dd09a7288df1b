#!/bin/sh
# Installs what the optional benchmark against Blender Cycles (bench/cycles/run.sh,
# docs/cycles.md) needs beyond scripts/install-deps.sh: Blender (Debian 12 ships 3.4.1, with
# Cycles, OpenVDB volumes and Python). Large (several hundred MB); not used by the build,
# the tests or CI. Safe to run repeatedly.
set -eu
if dpkg-query -W -f='${Status}' blender 2>/dev/null | grep -q "install ok installed"; then
    exit 0
fi
echo "atmos: installing Blender (for bench/cycles/run.sh)" >&2
SUDO=""
if [ "$(id -u)" != "0" ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
        echo "atmos: need root (or sudo) to install blender" >&2; exit 1; fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q blender

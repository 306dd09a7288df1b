#!/bin/sh
# Installs the Debian packages atmos needs to build and test, if any are missing; with
# arguments, those packages instead (scripts/install-bench-deps.sh).
# Safe to run repeatedly: it does nothing when everything is present.
set -eu
# FFTW 3 for the cloud simulation's pressure solver. Images: libpng, libjpeg (maps of the Earth), OpenEXR. Meshes: tinyobjloader (OBJ files), GDAL (terrain height maps). Volume readers: NetCDF (WRF/CM1), NanoVDB (PNanoVDB.h), OpenVDB (+ the Boost headers
# its headers include, which Debian does not pull in); gnuplot for 'atmos phase --plot'; SDL2, SDL2_ttf
# and the DejaVu fonts for 'atmos view', Xvfb (and xauth for xvfb-run) for its tests.
# help2man writes the man pages from the CLI's help text; the Python package needs cffi, NumPy and
# Python's headers, its tests pytest and pip; atmos render --mpi Open MPI.
PKGS="build-essential cmake pkg-config libfftw3-dev libpng-dev libjpeg-dev libopenexr-dev libcjson-dev libtinyobjloader-dev libgdal-dev libnetcdf-dev libnanovdb-dev libopenvdb-dev libboost-dev gnuplot-nox python3 libsdl2-dev libsdl2-ttf-dev fonts-dejavu-core xvfb xauth help2man python3-dev python3-cffi python3-numpy python3-pytest python3-pip libopenmpi-dev openmpi-bin"
[ $# -gt 0 ] && PKGS="$*"
missing=""
for p in $PKGS; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
[ -z "$missing" ] && exit 0
echo "atmos: installing missing Debian packages:$missing" >&2
SUDO=""
if [ "$(id -u)" != "0" ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
        echo "atmos: need root (or sudo) to install:$missing" >&2; exit 1; fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends $missing

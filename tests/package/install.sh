#!/bin/sh
# atmos as a user installs and uses it (docs/install.md): `cmake --install` into a fresh
# prefix, then against the installed files only:
#  - the files a package has: headers, libatmos.so with its SONAME, libatmos.a, atmos.pc,
#    the CMake package, the CLI, a man page for the CLI and for every command of its command table;
#  - every public header compiles on its own, in C11 and C++11 (-Wall -Wextra -pedantic -Werror);
#  - a C++ program calls the library (the headers' extern "C");
#  - the examples build through pkg-config (shared, and one static) and through find_package
#    (atmos::atmos, atmos::atmos_static), run, and the static and shared builds write the
#    same bytes.
# Run by ctest with ATMOS_BUILD_DIR (the build tree), ATMOS_SOURCE_DIR, CC, CXX.
set -u
build=${ATMOS_BUILD_DIR:?ATMOS_BUILD_DIR must name the build tree}
src=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR must name the source tree}
CC=${CC:-cc} CXX=${CXX:-c++}
T=${ATMOS_TEST_TMP:-/tmp}/install.$$
rm -rf "$T"
mkdir -p "$T" || exit 1
trap 'rm -rf "$T"' EXIT
fail=0
ok() { printf 'ok: %s\n' "$1"; }
bad() { printf 'FAIL: %s\n' "$1" >&2; fail=1; }
check() { name=$1; shift; if "$@" >"$T/log" 2>&1; then ok "$name"; else bad "$name"; sed 's/^/  /' "$T/log" >&2; fi; }

P=$T/prefix
check "cmake --install into a new prefix" cmake --install "$build" --prefix "$P"
libdir=$(dirname "$(find "$P" -name libatmos.so -print | head -n 1)")
[ -n "$libdir" ] && [ -d "$libdir" ] || { bad "no libatmos.so installed"; exit 1; }
for f in "$P/include/atmos/atmos.h" "$libdir/libatmos.a" "$libdir/pkgconfig/atmos.pc" \
         "$libdir/cmake/atmos/atmos-config.cmake" "$libdir/cmake/atmos/atmos-config-version.cmake" \
         "$P/bin/atmos" "$P/share/man/man1/atmos.1" "$P/share/doc/atmos/README.md" "$P/share/doc/atmos/docs/install.md"; do
    [ -s "$f" ] && ok "installed ${f#"$P"/}" || bad "missing ${f#"$P"/}"
done
soname=$(objdump -p "$libdir/libatmos.so" 2>/dev/null | awk '$1 == "SONAME" {print $2}')
[ "$soname" = libatmos.so.0.2 ] && ok "SONAME libatmos.so.0.2" || bad "SONAME is '$soname', expected libatmos.so.0.2"
"$P/bin/atmos" --version >"$T/v" 2>&1 && grep -q "^atmos [0-9]" "$T/v" && ok "installed atmos --version" || bad "installed atmos --version"
# The commands from the CLI's own table (tools/atmos/main.c), not from the --help text the
# man pages are made from, so a help line the man-page script misreads shows as a missing page.
sed -n 's/^ *{"\([a-z][a-z]*\)", *cli_cmd_.*/\1/p' "$src/tools/atmos/main.c" >"$T/cmds"
[ "$(wc -l <"$T/cmds")" -ge 10 ] || bad "fewer than 10 commands in tools/atmos/main.c's table"
while read -r c; do
    "$P/bin/atmos" --help | grep -q "^  $c " || bad "installed atmos --help does not list '$c'"
done <"$T/cmds"
while read -r c; do
    m=$P/share/man/man1/atmos-$c.1
    [ -s "$m" ] && grep -q "^\.SH DESCRIPTION" "$m" && ok "man page atmos-$c.1" || bad "no man page for 'atmos $c'"
done <"$T/cmds"

# Every public header alone, as C and as C++.
for h in "$P"/include/atmos/*.h; do
    b=$(basename "$h")
    printf '#include <atmos/%s>\n' "$b" >"$T/one.c"
    check "$b alone in C11" "$CC" -std=c11 -Wall -Wextra -pedantic -Werror -I"$P/include" -c "$T/one.c" -o "$T/one.o"
    cp "$T/one.c" "$T/one.cpp"
    check "$b alone in C++11" "$CXX" -std=c++11 -Wall -Wextra -pedantic -Werror -I"$P/include" -c "$T/one.cpp" -o "$T/one.o"
done
cat >"$T/cxx.cpp" <<'CXX'
#include <atmos/atmos.h>
#include <cstdio>
#include <cstring>
int main() { std::printf("%s %s\n", atmos_version(), atmos_status_string(ATMOS_E_IO)); return std::strlen(atmos_version()) ? 0 : 1; }
CXX
check "a C++ program links the library" "$CXX" -std=c++11 -Wall -Wextra -Werror -I"$P/include" "$T/cxx.cpp" -L"$libdir" -latmos -o "$T/cxx"
check "the C++ program runs" env LD_LIBRARY_PATH="$libdir" "$T/cxx"

# The examples through pkg-config.
export PKG_CONFIG_PATH="$libdir/pkgconfig" XDG_CACHE_HOME="$T/cache"
mkdir -p "$T/pc"
for e in orbit sky slice_volume mie_phase; do
    # shellcheck disable=SC2046
    check "examples/$e.c through pkg-config" "$CC" -std=c11 -Wall -Wextra -Werror "$src/examples/$e.c" \
        $(pkg-config --cflags --libs atmos) -lm -o "$T/pc/$e"
done
static_libs=$(pkg-config --static --libs atmos | sed 's/-latmos /-Wl,-Bstatic -latmos -Wl,-Bdynamic /')
# shellcheck disable=SC2046,SC2086
check "examples/sky.c statically through pkg-config --static" "$CC" -std=c11 -Wall -Wextra -Werror \
    "$src/examples/sky.c" $(pkg-config --cflags atmos) $static_libs -o "$T/pc/sky_static"
if [ -x "$T/pc/sky_static" ] && objdump -p "$T/pc/sky_static" >"$T/needed" 2>&1; then
    grep -q "NEEDED.*libatmos" "$T/needed" && bad "the static sky needs libatmos.so" || ok "the static sky does not need libatmos.so"
else bad "no static sky to inspect"; fi
# The examples through find_package, as their own CMake project.
check "examples/ configured with find_package(atmos)" cmake -S "$src/examples" -B "$T/cm" -DCMAKE_PREFIX_PATH="$P" \
    -DCMAKE_C_COMPILER="$CC" -DCMAKE_BUILD_TYPE=Release
check "examples/ built with atmos::atmos and atmos::atmos_static" cmake --build "$T/cm"

# A C++-only project (no C enabled) finds the package and links the library.
mkdir -p "$T/cxxproj"
cp "$T/cxx.cpp" "$T/cxxproj/main.cpp"
cat >"$T/cxxproj/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.16)
project(cxxonly CXX)
find_package(atmos 0.2 REQUIRED)
add_executable(cxxonly main.cpp)
target_link_libraries(cxxonly PRIVATE atmos::atmos)
CM
check "a C++-only CMake project finds atmos" cmake -S "$T/cxxproj" -B "$T/cxxb" -DCMAKE_PREFIX_PATH="$P" -DCMAKE_CXX_COMPILER="$CXX"
check "the C++-only project builds" cmake --build "$T/cxxb"

# Run them (small sizes).
cd "$T" || exit 1
export LD_LIBRARY_PATH="$libdir"
check "pkg-config sky runs" "$T/pc/sky" --size 24 16 --out "$T/sky_pc"
check "pkg-config static sky runs" "$T/pc/sky_static" --size 24 16 --out "$T/sky_pc_static"
check "find_package sky runs" "$T/cm/sky" --size 24 16 --out "$T/sky_cm"
check "find_package static sky runs" "$T/cm/sky_static" --size 24 16 --out "$T/sky_cm_static"
for a in sky_pc_static sky_cm sky_cm_static; do
    cmp -s "$T/sky_pc.pfm" "$T/$a.pfm" && ok "$a.pfm equals the shared pkg-config build's" || bad "$a.pfm differs"
done
check "find_package mie_phase runs" "$T/cm/mie_phase" --fast --preset rain
grep -q "^138," "$T/log" && ok "mie_phase prints the table" || bad "mie_phase printed no 138-degree row"
check "find_package orbit runs" "$T/cm/orbit" --size 24 --frames 2 --out "$T"
[ -s "$T/orbit_01.png" ] && ok "orbit wrote its frames" || bad "orbit wrote no orbit_01.png"
check "pkg-config slice_volume runs" "$T/pc/slice_volume" --size 32 20 -o "$T/slice.png"
[ -s "$T/slice.png" ] && ok "slice_volume wrote its image" || bad "slice_volume wrote no image"
"$T/cm/sky" --size 0 5 >/dev/null 2>&1; [ $? -eq 2 ] && ok "bad --size is a usage error" || bad "sky --size 0 5 did not exit 2"

# The OpenVDB and GDAL readers are modules beside the library, opened on the first file they
# read (src/core/module.h): the installed CLI finds the OpenVDB one from bin/ (no
# LD_LIBRARY_PATH), and without it says what is missing.
vdb=$build/tests/fixtures/volume/small.vdb
if [ -f "$build/libatmos_gdal.so" ]; then
    [ -s "$libdir/libatmos_gdal.so" ] && ok "installed libatmos_gdal.so" || bad "no libatmos_gdal.so beside libatmos.so"
fi
if [ -f "$build/libatmos_openvdb.so" ]; then
    [ -s "$libdir/libatmos_openvdb.so" ] && ok "installed libatmos_openvdb.so" || bad "no libatmos_openvdb.so beside libatmos.so"
    if [ -f "$vdb" ]; then
        check "installed atmos reads a .vdb through the module" env LD_LIBRARY_PATH= "$P/bin/atmos" volume info "$vdb"
        mv "$libdir/libatmos_openvdb.so" "$T/moved.so"
        env LD_LIBRARY_PATH= "$P/bin/atmos" volume info "$vdb" >"$T/log" 2>&1
        grep -q "libatmos_openvdb.so not found" "$T/log" && ok "without the module: not found, said" ||
            bad "without the module: $(cat "$T/log")"
        mv "$T/moved.so" "$libdir/libatmos_openvdb.so"
    else bad "no $vdb (the test fixtures.vdb makes it)"; fi
fi

# The Python package installed by pip against the installed library (a copy of python/, so the
# checkout stays clean; --target: the system's site-packages are left alone).
py=${ATMOS_PYTHON:-python3}
if "$py" -c "import setuptools, cffi, numpy, pip" 2>/dev/null; then
    cp -r "$src/python" "$T/pysrc" && rm -f "$T"/pysrc/atmos/_native*.so "$T"/pysrc/atmos/_build_info.py
    check "pip install ./python against the installed atmos" "$py" -m pip install --no-build-isolation --no-index \
        --no-deps --target "$T/site" "$T/pysrc"
    check "the pip-installed package imports and renders" env PYTHONPATH="$T/site" LD_LIBRARY_PATH= "$py" -c \
        "import atmos, numpy; a = numpy.asarray(atmos.render(width=8, height=6)); assert a.shape == (6, 8, 4), a.shape"
else
    bad "no Python with cffi, NumPy, pip and setuptools (scripts/install-deps.sh installs them)"
fi

exit $fail

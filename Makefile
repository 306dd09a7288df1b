# Convenience front end to the CMake build. The two commands a new user needs:
#   make run    install missing packages, build, render the default scene to out/
#               (RUN_SCENE=scenes/NAME.json picks another scene)
#   make test   install missing packages, build, run the whole test suite (ctest),
#               including an AddressSanitizer + UndefinedBehaviorSanitizer build
#               of the unit tests. WERROR=ON turns warnings into errors (CI does).
#   make install PREFIX=DIR   build, then install the library, headers, pkg-config file,
#               CMake package, CLI, man pages and docs under DIR (default /usr/local;
#               DESTDIR=... stages it, docs/install.md)
JOBS     ?= $(shell nproc 2>/dev/null || echo 2)
BUILD    ?= build
WERROR   ?= OFF

.PHONY: all deps build run test bench install clean
all: build

deps:
	@sh scripts/install-deps.sh

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake -S . -B $(BUILD) -DATMOS_WERROR=$(WERROR) > /dev/null
	cmake --build $(BUILD) -j $(JOBS)

# The default scene: the 22-degree and 46-degree halos in a generated cirrus (Riley et al.
# 2004, Fig. 6), rendered by half-angle slicing. A first run also builds the ice crystal
# phase table and its multiple-scattering functions (cached for later runs).
RUN_SCENE ?= scenes/fig06_halo_cirrus.json
run: build
	@mkdir -p out
	./$(BUILD)/atmos render $(RUN_SCENE) -o out/default.png --exr out/default.exr
	@echo "atmos: wrote out/default.png (tone-mapped sRGB) and out/default.exr (HDR, linear sRGB) from $(RUN_SCENE)"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

PREFIX   ?= /usr/local
install: build
	DESTDIR=$(DESTDIR) cmake --install $(BUILD) --prefix $(PREFIX)

bench: build
	./$(BUILD)/atmos bench sky

clean:
	rm -rf $(BUILD) out

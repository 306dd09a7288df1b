# Convenience front end to the CMake build. The two commands a new user needs:
#   make run    install missing packages, build, render the default scene to out/
#   make test   install missing packages, build, run the whole test suite (ctest),
#               including an AddressSanitizer + UndefinedBehaviorSanitizer build
#               of the unit tests. WERROR=ON turns warnings into errors (CI does).
JOBS     ?= $(shell nproc 2>/dev/null || echo 2)
BUILD    ?= build
WERROR   ?= OFF

.PHONY: all deps build run test bench clean
all: build

deps:
	@sh scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake -S . -B $(BUILD) -DATMOS_WERROR=$(WERROR) > /dev/null
	cmake --build $(BUILD) -j $(JOBS)

run: build
	@mkdir -p out
	./$(BUILD)/atmos render -o out/default.png --exr out/default.exr
	@echo "atmos: wrote out/default.png (tone-mapped sRGB) and out/default.exr (HDR, linear sRGB)"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	./$(BUILD)/atmos bench sky

clean:
	rm -rf $(BUILD) out

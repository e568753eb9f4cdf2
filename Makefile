# ardsim: every target installs what it lacks first (Debian packages, as root), then does its work.
#   make demo    install, build, run the default docking scenario recorded and filmed into runs/<date-time>/
#   make test    install, build, run every gtest and rostest (non-zero exit on any failure)
#   make bench   install, build, run the Google Benchmark programs and print ratios
SHELL := /bin/bash
JOBS ?= $(shell nproc)
CMAKE_ARGS := -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCATKIN_ENABLE_TESTING=ON
WITH_ENV := scripts/with-env

.PHONY: all deps build test demo bench format clean
all: build

deps:
	@scripts/install-deps

build: deps
	@set -o pipefail; $(WITH_ENV) catkin_make -j$(JOBS) $(CMAKE_ARGS) 2>&1 | scripts/quiet-build

test: build
	@scripts/run-tests

demo: build
	@scripts/demo $(ARGS)

bench: build
	@$(WITH_ENV) scripts/bench

format:
	@git ls-files '*.cpp' '*.h' | xargs clang-format -i

clean:
	rm -rf build devel

#!/usr/bin/env bash
# ctest InstallAndFindPackage: install the build tree into a temporary prefix, build the consumer
# against it with find_package(SimGrass COMPONENTS ...), run it, and check
#   * the installed CMake files ask for neither Eigen nor nlohmann_json (header-only, internal);
#   * the consumer's 10-tick hash is the simgrass CLI's, and the CLI verifies its recording.
set -euo pipefail
build_dir="$1"; source_dir="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cmake --install "$build_dir" --prefix "$tmp/prefix" >/dev/null
cmake_dir=$(dirname "$(find "$tmp/prefix" -name SimGrassConfig.cmake)")
if grep -nE 'Eigen3|nlohmann_json' "$cmake_dir"/*Targets*.cmake || grep -nE 'find_dependency\((Eigen3|nlohmann_json)' "$cmake_dir"/SimGrassConfig.cmake; then
  echo "the installed package still requires Eigen or nlohmann_json" >&2; exit 1
fi
echo "installed headers:"; (cd "$tmp/prefix/include/simgrass" && find . -name '*.h' | sort | sed 's/^/  /')
cmake -S "$source_dir/tests/install_consumer" -B "$tmp/build" -G Ninja -DCMAKE_PREFIX_PATH="$tmp/prefix" \
      -DCMAKE_BUILD_TYPE=Release >"$tmp/configure.log" || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/build" >"$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }
got=$("$tmp/build/consumer" "$tmp/consumer.sgr")
want=$("$build_dir/replay/simgrass" run --ticks 10 --json | python3 -c 'import json,sys; print("tick 10 hash "+json.load(sys.stdin)["finalHash"])')
echo "consumer: $got"; echo "cli:      $want"
[ "$got" = "$want" ]
"$build_dir/replay/simgrass" replay --verify "$tmp/consumer.sgr"

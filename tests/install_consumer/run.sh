#!/usr/bin/env bash
# ctest: install the build tree into a temporary prefix, build the consumer against it with
# find_package(SimGrass), run it, and compare its hash with the simgrass CLI's for 10 ticks.
set -euo pipefail
build_dir="$1"; source_dir="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cmake --install "$build_dir" --prefix "$tmp/prefix" >/dev/null
cmake -S "$source_dir/tests/install_consumer" -B "$tmp/build" -G Ninja -DCMAKE_PREFIX_PATH="$tmp/prefix" \
      -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/build" >/dev/null
got=$("$tmp/build/consumer")
want=$("$build_dir/replay/simgrass" run --ticks 10 --json | python3 -c 'import json,sys; print("tick 10 hash "+json.load(sys.stdin)["finalHash"])')
echo "consumer: $got"; echo "cli:      $want"
[ "$got" = "$want" ]

#!/bin/sh
# ctest Fuzz<Target>Bounded: SECONDS of fuzzing from scratch copies of TARGET's seeds (and any
# extra folder); new inputs go to the copies, crash files to SCRATCH; the committed corpora are
# never written. Uses tests/fuzz/dict/TARGET.dict when there is one.
#   bounded.sh FUZZER TARGET SOURCE_DIR SCRATCH SECONDS [EXTRA_DIR...]
set -eu
fuzzer=$1 target=$2 src=$3 scratch=$4 seconds=$5
shift 5
rm -rf "$scratch" && mkdir -p "$scratch/seeds"
cp -R "$src/corpus/$target/." "$scratch/seeds/"
dirs="$scratch/seeds"
n=0
for extra in "$@"; do
  n=$((n + 1))
  cp -R "$extra" "$scratch/extra$n"
  dirs="$dirs $scratch/extra$n"
done
dict=""
[ -f "$src/dict/$target.dict" ] && dict="-dict=$src/dict/$target.dict"
# shellcheck disable=SC2086
exec "$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
  -artifact_prefix="$scratch/" $dict $dirs

#!/bin/sh
# ctest Fuzz<Target>Corpus: runs FUZZER once over every committed input of TARGET (its seed
# corpus, its crash reproducers and any extra folder), except the reproducers listed in
# known-failures.txt (crashes found in another helper's parser, waiting on their fix).
#   replay.sh FUZZER TARGET SOURCE_DIR [EXTRA_DIR...]
set -eu
fuzzer=$1 target=$2 src=$3
shift 3
list=$(mktemp)
trap 'rm -f "$list"' EXIT
for dir in "$src/corpus/$target" "$src/crashes/$target" "$@"; do
  [ -d "$dir" ] || continue
  find "$dir" -maxdepth 1 -type f ! -name '.*' ! -name README.md | sort >> "$list"
done
known=$(sed -n "s|^$target/||p" "$src/known-failures.txt" | cut -d' ' -f1)
files=""
count=0
while IFS= read -r f; do
  skip=0
  for k in $known; do [ "$(basename "$f")" = "$k" ] && skip=1; done
  [ $skip -eq 1 ] && continue
  files="$files
$f"
  count=$((count + 1))
done < "$list"
echo "$target: $count committed inputs"
[ $count -gt 0 ] || exit 0
# File arguments: libFuzzer runs each once and stops (a crash fails the test with its stack).
printf '%s\n' "$files" | sed '/^$/d' | tr '\n' '\0' | xargs -0 "$fuzzer" -rss_limit_mb=2048 -timeout=30

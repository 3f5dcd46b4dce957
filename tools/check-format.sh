#!/bin/sh
# Fails (exit 1) when a C++ file of the tree differs from what clang-format (.clang-format)
# makes of it, naming the files; `tools/check-format.sh --fix` rewrites them instead.
# Run by the default test suite (ctest label fast) and so by CI.
set -e
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || { echo "clang-format is not installed (sh tools/install-deps.sh)"; exit 1; }
FILES=$(find app bench io render sim tests -name '*.cpp' -o -name '*.h' | sort)
if [ "$1" = "--fix" ]; then
  clang-format -i $FILES
  exit 0
fi
BAD=""
for f in $FILES; do
  clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || BAD="$BAD $f"
done
if [ -n "$BAD" ]; then
  echo "not formatted (run tools/check-format.sh --fix):"
  for f in $BAD; do echo "  $f"; done
  exit 1
fi
echo "all $(echo "$FILES" | wc -l) C++ files formatted"

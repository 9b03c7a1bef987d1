#!/usr/bin/env bash
# has_target.sh BUILD_DIR TARGET: exit 0 when the configured build in BUILD_DIR has TARGET,
# 1 when not, 2 on a usage error. Used by scripts/demo.sh; tested by tests/cli/has_target.sh.
#
# The target list is captured whole before it is searched: `cmake --build ... --target help
# | grep -q` under `set -o pipefail` failed whenever grep found the name (make's later
# echoes hit a closed pipe, "Broken pipe", and the pipeline's status was make's failure),
# so demo.sh never built the cycle-benchmark ELF.
set -euo pipefail
if [ $# -ne 2 ]; then
  echo "usage: $0 BUILD_DIR TARGET" >&2
  exit 2
fi
targets=$(cmake --build "$1" --target help 2>/dev/null) || {
  echo "has_target.sh: cannot list the targets of '$1' (not a configured build folder?)" >&2
  exit 2
}
# Makefiles: "... NAME" or "... NAME (comment)"; Ninja: "NAME: phony".
while IFS= read -r line; do
  line=${line#... }
  line=${line%%:*}
  line=${line%% *}
  [ "$line" = "$2" ] && exit 0
done <<<"$targets"
exit 1

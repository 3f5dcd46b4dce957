#!/bin/sh
# The per-ISA objects (sim/mpm/stress_batch_avx*.cpp, sim/mpm/transfer_blocks_avx*.cpp,
# sim/contact/shell_blocks_avx*.cpp, sim/contact/contact_lanes_avx*.cpp)
# must define nothing but their entry points: an inline function emitted there (a weak symbol) could be the copy the linker
# keeps for every other translation unit, which would then need AVX2 or AVX-512.
# Usage: check-isa-symbols.sh OBJECT... (the others are ignored)
status=0
found=0
for obj in "$@"; do
  case "$obj" in
    *stress_batch_avx* | *transfer_blocks_avx* | *shell_blocks_avx* | *contact_lanes_avx*) ;;
    *) continue ;;
  esac
  found=$((found + 1))
  if ! syms=$(nm -C --defined-only "$obj"); then
    echo "nm could not read $obj"
    status=1
    continue
  fi
  extra=$(echo "$syms" | grep -v ' [tTrRbBdD] ' | grep -v '^$' | grep -v ':$')
  strong=$(echo "$syms" | grep ' T ' | grep -v 'shellmpm::stress_batch::run_avx' |
    grep -v 'shellmpm::transfer_blocks::[pg]2[gp]_avx' |
    grep -v 'shellmpm::shell_blocks::[a-z0-9_]*_avx' |
    grep -v 'shellmpm::contact_lanes::[a-z]*_avx')
  if [ -n "$extra$strong" ]; then
    echo "$obj defines more than its entry point:"
    echo "$extra"
    echo "$strong"
    status=1
  fi
done
if [ "$found" -ne 8 ]; then
  echo "expected the eight per-ISA objects, found $found"
  status=1
fi
exit $status

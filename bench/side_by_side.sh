#!/bin/sh
# bench/side_by_side.sh: shellmpm against a peer (ziran2020) on the same elastic cube,
# timed in one alternating run (A B A B ..., medians of the rounds), so that both see the
# same machine state. It builds nothing.
#
#   bench/side_by_side.sh [--shellmpm BENCH] [--peer 'COMMAND {threads}'] [--rounds N]
#                         [--threads "1 2"] [--transfer apic|mls] [--steps S]
#
# BENCH: the mpm_throughput program (default build/bench/mpm_throughput). COMMAND: the
# peer's command line for the same cube (262,144 particles, 8 per cell, dx 1/128, fixed
# corotated, float, dt 1e-4, S steps), with {threads} where its thread count goes; without
# --peer, shellmpm alone is timed. Both are timed as whole processes (set-up included) by
# wall clock, and the rate is 262,144 x S / seconds; shellmpm's own steady-state rate (set-up
# excluded) is printed next to it.
set -eu
bench=build/bench/mpm_throughput
peer=""
rounds=3
threads="1 2"
transfer=apic
steps=200
while [ $# -gt 0 ]; do
  [ $# -ge 2 ] || { echo "side_by_side.sh: $1 needs a value" >&2; exit 2; }
  case "$1" in
    --shellmpm) bench=$2 ;;
    --peer) peer=$2 ;;
    --rounds) rounds=$2 ;;
    --threads) threads=$2 ;;
    --transfer) transfer=$2 ;;
    --steps) steps=$2 ;;
    *) echo "side_by_side.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift 2
done
[ -x "$bench" ] || { echo "side_by_side.sh: $bench is not an executable (build it first)" >&2; exit 2; }
case "$rounds" in ''|*[!0-9]*|0) echo "side_by_side.sh: --rounds must be a positive integer" >&2; exit 2 ;; esac
particles=262144
work=$((particles * steps))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

now() { date +%s.%N; }
median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

echo "side_by_side: elastic cube, $particles particles, $transfer, $steps steps, $rounds rounds (A B A B)"
for t in $threads; do
  : > "$tmp/a.$t"; : > "$tmp/ai.$t"; : > "$tmp/b.$t"
done
r=1
while [ "$r" -le "$rounds" ]; do
  for t in $threads; do
    t0=$(now)
    "$bench" --particles $particles --steps "$steps" --transfer "$transfer" --threads "$t" > "$tmp/out"
    t1=$(now)
    echo "$t0 $t1" | awk -v w=$work '{print w / ($2 - $1) / 1e6}' >> "$tmp/a.$t"
    sed -n 's/.* \([0-9.]*\) M particle-steps\/s.*/\1/p' "$tmp/out" >> "$tmp/ai.$t"
    if [ -n "$peer" ]; then
      cmd=$(printf '%s' "$peer" | sed "s/{threads}/$t/g")
      t0=$(now)
      sh -c "$cmd" > "$tmp/peer.out" 2>&1 || { echo "side_by_side.sh: the peer command failed: $cmd" >&2; cat "$tmp/peer.out" >&2; exit 1; }
      t1=$(now)
      echo "$t0 $t1" | awk -v w=$work '{print w / ($2 - $1) / 1e6}' >> "$tmp/b.$t"
    fi
  done
  r=$((r + 1))
done
for t in $threads; do
  a=$(median < "$tmp/a.$t")
  ai=$(median < "$tmp/ai.$t")
  if [ -n "$peer" ]; then
    b=$(median < "$tmp/b.$t")
    echo "$t thread(s): shellmpm $a M particle-steps/s (steady state $ai), peer $b, ratio $(echo "$a $b" | awk '{printf "%.2f", $1 / $2}')x"
  else
    echo "$t thread(s): shellmpm $a M particle-steps/s whole process (steady state $ai); no --peer given"
  fi
done

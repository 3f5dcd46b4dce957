#!/bin/sh
# bench/point_cost.sh: what a shell control point or contact particle costs against a bulk
# particle-step, timed in one alternating run (contact_throughput, mpm_throughput,
# contact_throughput, ...) so that both see the same machine state. It builds nothing.
#
#   bench/point_cost.sh [--build DIR] [--rounds N] [--threads "1 2"] [--steps S]
#                       [--contact-at surface|stencil]
#
# DIR: the build folder holding bench/contact_throughput and bench/mpm_throughput
# (default build). S: contact_throughput's timed steps (default 100: the shell guard's
# list rebuilds, every few dozen steps there, must fall in the window). Per round and
# thread count it prints the contact benchmark's ms per step, its cost per point (ms per
# step over its control points and contact particles), the bulk particle-step and their
# ratio; then the ratio's range over the rounds. --contact-at: the contact benchmark's
# shot.contact_at (default surface, the scenes' default).
set -eu
build=build
rounds=3
threads="1 2"
steps=100
contact_at=surface
while [ $# -gt 0 ]; do
  [ $# -ge 2 ] || { echo "point_cost.sh: $1 needs a value" >&2; exit 2; }
  case "$1" in
    --build) build=$2 ;;
    --rounds) rounds=$2 ;;
    --threads) threads=$2 ;;
    --steps) steps=$2 ;;
    --contact-at) contact_at=$2 ;;
    *) echo "point_cost.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift 2
done
contact=$build/bench/contact_throughput
bulk=$build/bench/mpm_throughput
for b in "$contact" "$bulk"; do
  [ -x "$b" ] || { echo "point_cost.sh: $b is not an executable (build it first)" >&2; exit 2; }
done
case "$rounds" in ''|*[!0-9]*|0) echo "point_cost.sh: --rounds must be a positive integer" >&2; exit 2 ;; esac
case "$steps" in ''|*[!0-9]*|0) echo "point_cost.sh: --steps must be a positive integer" >&2; exit 2 ;; esac
case "$contact_at" in surface|stencil) ;; *) echo "point_cost.sh: --contact-at must be surface or stencil" >&2; exit 2 ;; esac
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
r=1
while [ "$r" -le "$rounds" ]; do
  for t in $threads; do
    "$contact" --threads "$t" --steps "$steps" --contact-at "$contact_at" > "$tmp/c" 2>&1 ||
      { echo "point_cost.sh: $contact failed:" >&2; cat "$tmp/c" >&2; exit 1; }
    "$bulk" --threads "$t" > "$tmp/b" 2>&1 ||
      { echo "point_cost.sh: $bulk failed:" >&2; cat "$tmp/b" >&2; exit 1; }
    # Points: "(N control points, M contact particles)"; ms: "threads T: X ms per step";
    # bulk: "threads T: ... R M particle-steps/s".
    awk -v t="$t" -v r="$r" '
      FNR == NR {
        if (match($0, /\([0-9]+ control points, [0-9]+ contact particles\)/)) {
          split(substr($0, RSTART + 1, RLENGTH - 2), w, " ");
          points = w[1] + w[4];
        }
        if ($1 == "threads" && $2 == t ":") ms = $3;
        next;
      }
      $1 == "threads" && $2 == t ":" {
        for (i = 3; i <= NF; ++i) if ($(i + 1) == "M" && $(i + 2) == "particle-steps/s") rate = $i;
      }
      END {
        if (!points || !ms || !rate) { print "point_cost.sh: could not read the benchmarks'"'"' output" > "/dev/stderr"; exit 1 }
        pt = ms * 1000 / points; bk = 1 / rate;
        printf "round %d, %s thread(s): %.1f ms per step, %.3f us per point, bulk %.4f us per particle-step: %.2fx\n", r, t, ms, pt, bk, pt / bk;
        printf "%s %.4f\n", t, pt / bk >> "'"$tmp/ratios"'";
      }' "$tmp/c" "$tmp/b"
  done
  r=$((r + 1))
done
for t in $threads; do
  awk -v t="$t" '$1 == t { if (n == 0 || $2 < lo) lo = $2; if (n == 0 || $2 > hi) hi = $2; ++n }
    END { printf "%s thread(s): %.2f-%.2fx over %d round(s)\n", t, lo, hi, n }' "$tmp/ratios"
done

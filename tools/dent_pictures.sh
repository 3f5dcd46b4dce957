#!/bin/sh
# The steel dent, explicit and implicit, seen from below the sheet one frame after the
# strike (t = 2/24 s), ray traced: docs/images/steel_dent_explicit.png and
# steel_dent_implicit.png, which docs/implicit.md shows side by side. Runs
# scenes/sheet_metal_dent.yaml twice (implicit at its cfl 0.125, about 2 s; explicit at
# CFL 0.5, about 35 s on 2 cores) into out/dent_pictures/.
# Usage: sh tools/dent_pictures.sh [path/to/shellmpm]
set -eu
bin=${1:-./build/shellmpm}
out=out/dent_pictures
mkdir -p docs/images
for mode in implicit explicit; do
  case $mode in
    implicit) extra="" ;;
    explicit) extra="--set shot.integrator=explicit --set shot.cfl=0.5" ;;
  esac
  # shellcheck disable=SC2086 # $extra is a list of flags
  "$bin" run scenes/sheet_metal_dent.yaml --frames 1-3 -o "$out/$mode" --quiet $extra \
    --set 'shells[0].output_refine=2' \
    --set 'render.cameras=[{name: below, position: [0.08, -0.3, 0.34], target: [0, 0.1, 0], fov: 42}]' \
    --set render.ground=false --set 'render.key_light=[1, -0.3, 0.15]' \
    --set render.renderer=raytrace --set render.samples=16 --set 'render.size=[640, 400]'
  "$bin" render "$out/$mode" --frames 3
  cp "$out/$mode/preview.0003.png" "docs/images/steel_dent_$mode.png"
  echo "wrote docs/images/steel_dent_$mode.png"
done

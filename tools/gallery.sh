#!/usr/bin/env bash
# The gallery: one contact-sheet thumbnail per example scene (scenes/*.yaml, top level only;
# not scenes/stress, scenes/study or scenes/batches), written to docs/gallery/<scene>.png.
#
#   tools/gallery.sh [--only SCENE]... [--frames A-B] [--out DIR] [--quality Q]
#                    [--tiles N] [--tile-size WxH] [--threads N] [--shellmpm PATH] [--keep]
#
# Each scene is run with `shellmpm run --preview` at the `draft` quality preset (shot.quality;
# 2x coarser dx and sheets) into a temporary folder, its previews rendered by the raster
# renderer at the tile size (192x108); N frames (4) spread evenly over the frames written
# are laid out 2 x 2 (tools/gallery_sheet.py, the layout of shellmpm's contact_sheet.png,
# labelled with their frame numbers): a 396x228 PNG of some 20-40 KB per scene. Each
# scene's time is printed. A scene that fails is named with the end of its log; the others
# still run, and the script exits 1 at the end. Images are replaced only for scenes that
# succeed.
#
#   --only SCENE    a scene name (sand_pour) or YAML path; repeatable (default: every scene)
#   --frames A-B    passed to `shellmpm run` (frames before A are simulated, not written)
#   --out DIR       where the PNGs go (default: docs/gallery)
#   --quality Q     shot.quality preset: draft, preview, production or final (draft)
#   --tiles N       frames per sheet (4); 2 columns up to 4 tiles, 3 up to 9, then 4
#   --tile-size WxH preview size of each frame (192x108)
#   --threads N     threads of each run (0: all cores; default 0)
#   --shellmpm P    the binary (default: $SHELLMPM, else build/shellmpm)
#   --keep          keep the temporary run folders (their path is printed)
#
# Measured on the 2-core development machine (niced, beside a build): see docs/gallery/
# in the commit that last regenerated the images.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SHEET="$ROOT/tools/gallery_sheet.py"
SHELLMPM_BIN="${SHELLMPM:-$ROOT/build/shellmpm}"
OUT="$ROOT/docs/gallery"
QUALITY=draft
TILES=4
TILE_SIZE=192x108
THREADS=0
FRAMES=""
KEEP=0
ONLY=()

die() {
  echo "gallery: $*" >&2
  exit 2
}

usage() {
  sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d' | sed 's/^# \{0,1\}//'
}

while [[ $# -gt 0 ]]; do
  case "$1" in
    --only) [[ $# -ge 2 ]] || die "--only needs a scene"; ONLY+=("$2"); shift 2 ;;
    --frames) [[ $# -ge 2 ]] || die "--frames needs A-B"; FRAMES="$2"; shift 2 ;;
    --out) [[ $# -ge 2 ]] || die "--out needs a folder"; OUT="$2"; shift 2 ;;
    --quality) [[ $# -ge 2 ]] || die "--quality needs a preset"; QUALITY="$2"; shift 2 ;;
    --tiles) [[ $# -ge 2 ]] || die "--tiles needs a number"; TILES="$2"; shift 2 ;;
    --tile-size) [[ $# -ge 2 ]] || die "--tile-size needs WxH"; TILE_SIZE="$2"; shift 2 ;;
    --threads) [[ $# -ge 2 ]] || die "--threads needs a number"; THREADS="$2"; shift 2 ;;
    --shellmpm) [[ $# -ge 2 ]] || die "--shellmpm needs a path"; SHELLMPM_BIN="$2"; shift 2 ;;
    --keep) KEEP=1; shift ;;
    -h | --help) usage; exit 0 ;;
    *) die "unknown argument '$1' (see tools/gallery.sh --help)" ;;
  esac
done

[[ "$TILES" =~ ^[1-9][0-9]?$ && "$TILES" -le 24 ]] || die "--tiles $TILES: expected 1 to 24"
[[ "$TILE_SIZE" =~ ^([1-9][0-9]*)x([1-9][0-9]*)$ ]] || die "--tile-size $TILE_SIZE: expected WxH"
TILE_W="${BASH_REMATCH[1]}"
TILE_H="${BASH_REMATCH[2]}"
[[ "$THREADS" =~ ^[0-9]+$ ]] || die "--threads $THREADS: expected a number"
case "$QUALITY" in draft | preview | production | final) ;; *)
  die "--quality $QUALITY: expected draft, preview, production or final" ;;
esac
[[ -x "$SHELLMPM_BIN" ]] || die "$SHELLMPM_BIN: no shellmpm binary (build it, or give --shellmpm PATH)"
command -v python3 >/dev/null || die "python3 is not installed (tools/gallery_sheet.py needs it)"

# The scenes: every top-level scenes/*.yaml, or the --only ones.
SCENES=()
if [[ ${#ONLY[@]} -eq 0 ]]; then
  for f in "$ROOT"/scenes/*.yaml; do SCENES+=("$f"); done
  [[ ${#SCENES[@]} -gt 0 && -f "${SCENES[0]}" ]] || die "no scenes in $ROOT/scenes"
else
  for s in "${ONLY[@]}"; do
    if [[ -f "$s" ]]; then
      SCENES+=("$(cd "$(dirname "$s")" && pwd)/$(basename "$s")")
    elif [[ -f "$ROOT/scenes/$s.yaml" ]]; then
      SCENES+=("$ROOT/scenes/$s.yaml")
    else
      die "--only $s: neither a file nor scenes/$s.yaml"
    fi
  done
fi

case "$TILES" in
  1 | 2 | 3) COLUMNS="$TILES" ;;
  4) COLUMNS=2 ;;
  5 | 6 | 7 | 8 | 9) COLUMNS=3 ;;
  *) COLUMNS=4 ;;
esac

mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
WORK="$(mktemp -d "${TMPDIR:-/tmp}/shellmpm-gallery.XXXXXX")"
cleanup() {
  if [[ "$KEEP" == 1 ]]; then
    echo "gallery: run folders kept in $WORK"
  else
    rm -rf "$WORK"
  fi
}
trap cleanup EXIT

# Seconds since the epoch, with fractions.
now() { date +%s.%N; }

FAILED=()
T_ALL="$(now)"
for scene in "${SCENES[@]}"; do
  name="$(basename "$scene" .yaml)"
  run="$WORK/$name"
  log="$WORK/$name.log"
  t0="$(now)"
  args=(run "$scene" -q --quality "$QUALITY" --threads "$THREADS" --preview -o "$run"
    --set "render.size=[$TILE_W,$TILE_H]" --set render.renderer=raster
    --set 'render.pattern="preview.####.png"' --set render.contact_sheet=false
    --set render.movie=false)
  # Without a plane collider the preview's floor sits under the first frame's content: a
  # sheet that starts on it flickers through it, one that swings or falls goes under it.
  # Such scenes are drawn without a floor.
  if ! grep -Eq 'type: *plane' "$scene"; then args+=(--set render.ground=false); fi
  [[ -n "$FRAMES" ]] && args+=(--frames "$FRAMES")
  status=0
  "$SHELLMPM_BIN" "${args[@]}" >"$log" 2>&1 || status=$?
  if [[ $status -ne 0 ]]; then
    echo "gallery: scene '$name' ($scene) failed: shellmpm run exited $status; the end of its log:" >&2
    tail -n 15 "$log" | sed 's/^/  /' >&2
    FAILED+=("$name")
    continue
  fi
  # The frames written, in order; N of them spread evenly (first and last included).
  mapfile -t frames < <(cd "$run" && ls preview.[0-9]*.png 2>/dev/null | sort)
  n=${#frames[@]}
  if [[ $n -eq 0 ]]; then
    echo "gallery: scene '$name' ($scene) failed: the run wrote no preview.####.png" >&2
    FAILED+=("$name")
    continue
  fi
  k=$((n < TILES ? n : TILES))
  tiles=()
  labels=()
  for ((i = 0; i < k; ++i)); do
    if [[ $k -eq 1 ]]; then j=0; else j=$(((2 * i * (n - 1) + (k - 1)) / (2 * (k - 1)))); fi
    f="${frames[$j]}"
    tiles+=("$run/$f")
    num="${f#preview.}"
    num="${num%.png}"
    labels+=("$((10#$num))")
  done
  tmp_png="$WORK/$name.png"
  status=0
  python3 "$SHEET" sheet "$tmp_png" --columns "$((k < COLUMNS ? k : COLUMNS))" \
    --labels "$(IFS=,; echo "${labels[*]}")" "${tiles[@]}" >"$WORK/$name.sheet.log" 2>&1 || status=$?
  if [[ $status -ne 0 ]]; then
    echo "gallery: scene '$name' ($scene) failed: the contact sheet could not be made:" >&2
    sed 's/^/  /' "$WORK/$name.sheet.log" >&2
    FAILED+=("$name")
    continue
  fi
  cp "$tmp_png" "$OUT/.$name.png.tmp"
  mv -f "$OUT/.$name.png.tmp" "$OUT/$name.png"
  [[ "$KEEP" == 1 ]] || rm -rf "$run"
  secs="$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')"
  printf 'gallery: %-20s %6s s  frames %s of %d  %s (%d bytes)\n' "$name" "$secs" \
    "$(IFS=,; echo "${labels[*]}")" "$n" "$OUT/$name.png" "$(stat -c %s "$OUT/$name.png")"
done
total="$(awk -v a="$T_ALL" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')"
if [[ ${#FAILED[@]} -gt 0 ]]; then
  echo "gallery: ${#FAILED[@]} of ${#SCENES[@]} scenes failed: ${FAILED[*]} (${total} s)" >&2
  exit 1
fi
echo "gallery: ${#SCENES[@]} scenes in ${total} s, images in $OUT"

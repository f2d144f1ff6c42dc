#!/usr/bin/env bash
# Renders the help page's gesture pictures from our hand model (sim/fixtures, OSMesa) with
# `gbdcs fixture render --frame`: one small still per gesture into web/src/assets/gestures/.
# The PNGs are committed (the web build does not need the C++ build); rerun after a change to
# the hand model:   web/scripts/render-gesture-pictures.sh [path/to/gbdcs]
set -euo pipefail
WEB="$(cd "$(dirname "$0")/.." && pwd)"
ROOT="$(cd "$WEB/.." && pwd)"
GBDCS="${1:-$ROOT/build/app/gbdcs}"
OUT="$WEB/src/assets/gestures"
[[ -x "$GBDCS" ]] || { echo "render-gesture-pictures: $GBDCS not found; build it first (ci/build)" >&2; exit 1; }
"$GBDCS" fixture render --help >/dev/null 2>&1 || {
  echo "render-gesture-pictures: this gbdcs has no 'fixture render' (the fixtures renderer is not built in)" >&2; exit 1; }
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
mkdir -p "$OUT"
for g in OPEN_PALM FIST THUMB_UP THUMB_DOWN POINT_LEFT POINT_RIGHT POINT_UP VICTORY I_LOVE_YOU; do
  cat > "$TMP/$g.json" <<JSON
{
  "name": "help_$g", "seed": 3, "width": 240, "height": 180, "fps": 10, "fov_deg": 50,
  "hand": {"skin_tone": "medium", "handedness": "right"},
  "placement": {"x": 0.5, "y": 0.52, "distance_m": 0.5},
  "motion": {"kind": "still"},
  "lighting": {"preset": "studio"},
  "background": {"kind": "gradient", "colour": [0.82, 0.86, 0.9], "colour2": [0.62, 0.68, 0.76]},
  "camera": {"noise": 0, "blur_px": 0, "jpeg_quality": 100},
  "segments": [{"pose": "$g", "duration_s": 1, "transition_s": 0}]
}
JSON
  "$GBDCS" fixture render "$TMP/$g.json" -o "$TMP/$g" --frame 5 >/dev/null
  cp "$TMP/$g/frame_5.png" "$OUT/$g.png"
  echo "render-gesture-pictures: $OUT/$g.png"
done

#!/usr/bin/env bash
# The view pages as a person sees them: check-view.sh TIGHTBVH_BINARY SOURCE_DIR OUT_DIR
# Writes a `tightbvh view` page, two `tightbvh collide --view` pages (all_pairs with --contacts, whose
# page must hold the intersection curve; first_hit, its
# descent panel opened with #boxes-only so that it must draw node boxes) and a `tightbvh distance
# --view` page, opens each in headless
# Chromium (WebGL through SwiftShader, networking off) and fails when a page references the
# network, its scripts throw or leave a panel blank (the page logs "tightbvh-view-status: ok" to
# the console only when every panel drew pixels; Chromium's log shows it), or the screenshot
# shows too little drawn geometry (png_colored_pixels.py). Also checks that a broken page is
# caught. One Chromium run per page (each takes seconds to start).
# Screenshots stay in OUT_DIR/*.png to look at.
set -euo pipefail
bin=$1 src=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$out"
mkdir -p "$out"
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT

"$bin" view "$src/meshes/knot1.off" --level 3 -o "$out/trees" >/dev/null
"$bin" collide "$src/meshes/knot1.off" "$src/meshes/elephant.off" --pose "0 -1 0 1 0 0 0 0 1 0.1 0 0" \
  --fitter pca --all-pairs --contacts --view "$out/contacts" >/dev/null
"$bin" collide "$src/meshes/knot1.off" "$src/meshes/elephant.off" --pose "0 -1 0 1 0 0 0 0 1 0.1 0 0" \
  --view "$out/descent" >/dev/null
"$bin" distance "$src/meshes/knot1.off" "$src/meshes/elephant.off" --pose "0 -1 0 1 0 0 0 0 1 1.3 0 0" \
  --view "$out/distance" >/dev/null
grep -q '"descent":' "$out/descent/index.html" || { echo "check-view: no descent in the first_hit page" >&2; exit 1; }
grep -q '"curve":\[[-0-9]' "$out/contacts/index.html" || { echo "check-view: no intersection curve in the contacts page" >&2; exit 1; }

# status_of PAGE PNG [#HASH]: screenshots file://PAGE#HASH into PNG and prints the status the page logged.
status_of() {
  timeout 120 chromium --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
    --disable-background-networking --disable-component-update --disable-sync --no-first-run \
    --enable-logging=stderr --v=0 --user-data-dir="$profile" --virtual-time-budget=15000 \
    --window-size=1200,1000 --screenshot="$2" "file://$1${3:-}" >"$profile/run.log" 2>&1 || true
  cat "$profile/run.log" >>"$profile/log"
  sed -n 's/.*"tightbvh-view-status: \([^"]*\)".*/\1/p' "$profile/run.log" | head -1
}

failed=0
for name in trees contacts descent distance; do
  page="$out/$name/index.html"
  if grep -Eq "(src|href)=['\"]?https?:" "$page"; then
    echo "check-view: $name page references the network" >&2; failed=1; continue
  fi
  hash=""
  [ "$name" = descent ] && hash="#boxes-only"
  status=$(status_of "$page" "$out/$name.png" "$hash")
  if [ "$status" != "ok" ]; then
    echo "check-view: $name page status '${status:-none}' (expected ok)" >&2; failed=1; continue
  fi
  [ -s "$out/$name.png" ] || { echo "check-view: no screenshot of the $name page" >&2; failed=1; continue; }
  /usr/bin/python3 "$here/png_colored_pixels.py" "$out/$name.png" 0.03 || {
    echo "check-view: the $name screenshot shows too little geometry" >&2; failed=1; }
done

# The checks themselves: a page whose scene is corrupt must report an error, and its screenshot
# (text, no drawing) must fail the pixel count.
sed 's/"positions":\[/"positions":[oops,/' "$out/trees/index.html" > "$out/broken.html"
status=$(status_of "$out/broken.html" "$out/broken.png")
case "$status" in
  error*) ;;
  *) echo "check-view: a broken page was not caught (status '${status:-none}')" >&2; failed=1 ;;
esac
if /usr/bin/python3 "$here/png_colored_pixels.py" "$out/broken.png" 0.03 >/dev/null; then
  echo "check-view: the broken page's screenshot passed the pixel count" >&2; failed=1
fi
# A descent with no node pairs drawn leaves its panel blank under #boxes-only: caught.
sed 's/"steps":\[[^]]*\]/"steps":[]/' "$out/descent/index.html" > "$out/no-steps.html"
status=$(status_of "$out/no-steps.html" "$out/no-steps.png" "#boxes-only")
case "$status" in
  error*) ;;
  *) echo "check-view: a descent panel without boxes was not caught (status '${status:-none}')" >&2; failed=1 ;;
esac

if [ "$failed" -ne 0 ]; then
  echo "check-view: chromium log:" >&2
  grep -e CONSOLE -e ERROR "$profile/log" | grep -v -e dbus -e Fontconfig | tail -20 >&2 || true
  exit 1
fi
echo "check-view: ok (screenshots in $out)"

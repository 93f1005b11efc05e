#!/usr/bin/env bash
# The view pages as a person sees them: check-view.sh TIGHTBVH_BINARY SOURCE_DIR OUT_DIR
# Writes a `tightbvh view` page and a `tightbvh collide --view` page, opens each in headless
# Chromium (WebGL through SwiftShader, networking off) and fails when a page references the
# network, its scripts throw or leave a panel blank (the page's <body data-status>, read with
# --dump-dom, is "ok" only when every panel drew pixels), or the screenshot shows too little
# drawn geometry (png_colored_pixels.py). Also checks that a broken page is caught.
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
  --fitter pca --all-pairs --view "$out/contacts" >/dev/null

browse() {  # browse PAGE ARGS...: one headless Chromium run on file://PAGE
  local page=$1; shift
  timeout 120 chromium --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
    --disable-background-networking --disable-component-update --disable-sync --no-first-run \
    --user-data-dir="$profile" --virtual-time-budget=15000 --window-size=1200,1000 "$@" "file://$page" \
    2>>"$profile/log"
}
status_of() {  # the page's data-status after its scripts ran
  browse "$1" --dump-dom | sed -n 's/.*<body data-status="\([^"]*\)".*/\1/p' | head -1
}

failed=0
for name in trees contacts; do
  page="$out/$name/index.html"
  if grep -Eq "(src|href)=['\"]?https?:" "$page"; then
    echo "check-view: $name page references the network" >&2; failed=1; continue
  fi
  status=$(status_of "$page")
  if [ "$status" != "ok" ]; then
    echo "check-view: $name page status '${status:-none}' (expected ok)" >&2; failed=1; continue
  fi
  rm -f "$out/$name.png"
  browse "$page" --screenshot="$out/$name.png" >/dev/null
  [ -s "$out/$name.png" ] || { echo "check-view: no screenshot of the $name page" >&2; failed=1; continue; }
  /usr/bin/python3 "$here/png_colored_pixels.py" "$out/$name.png" 0.03 || {
    echo "check-view: the $name screenshot shows too little geometry" >&2; failed=1; }
done

# The check itself: a page whose scene is corrupt must not pass as "ok".
sed 's/"positions":\[/"positions":[oops,/' "$out/trees/index.html" > "$out/broken.html"
status=$(status_of "$out/broken.html")
case "$status" in
  error*) ;;
  *) echo "check-view: a broken page was not caught (status '${status:-none}')" >&2; failed=1 ;;
esac

if [ "$failed" -ne 0 ]; then
  echo "check-view: chromium log:" >&2
  grep -v -e dbus -e "Fontconfig" "$profile/log" | tail -20 >&2 || true
  exit 1
fi
echo "check-view: ok (screenshots in $out)"

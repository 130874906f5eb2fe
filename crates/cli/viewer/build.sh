#!/usr/bin/env bash
# Build the page's script bundle (docs/viewer.md, "How the page is built"):
#   crates/cli/viewer/src/*.js + three.js  →  crates/cli/assets/viewer/viewer.js
# one minified classic script (IIFE: the page must work from file://, where module scripts and
# fetch are refused), and three.js's licence beside it. Deterministic: the same sources and
# lock file give the same bytes. Run from anywhere; needs node and npm (the npm registry).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
assets="$here/../assets/viewer"
cd "$here"
if [[ "${1:-}" != "--no-install" ]]; then
  npm ci --no-audit --no-fund --loglevel=error
fi
three_version="$(node -p 'JSON.parse(require("fs").readFileSync("node_modules/three/package.json", "utf8")).version')"
./node_modules/.bin/esbuild src/main.js \
  --bundle \
  --format=iife \
  --platform=browser \
  --target=es2020 \
  --minify \
  --legal-comments=none \
  --charset=utf8 \
  --banner:js="/* atelier viewer (crates/cli/viewer, built by build.sh) with three.js ${three_version}: MIT licence, see THREE-LICENSE.txt */" \
  --log-level=warning \
  --outfile="$assets/viewer.js"
cp node_modules/three/LICENSE "$assets/THREE-LICENSE.txt"
printf '%s\n' index.html viewer.js viewer.css THREE-LICENSE.txt > "$assets/FILES"
echo "built $assets/viewer.js ($(wc -c < "$assets/viewer.js") bytes, three.js $three_version, esbuild $(./node_modules/.bin/esbuild --version))"

#!/usr/bin/env bash
# The browser test of `atelier view` (docs/viewer.md, "The browser test"); .ci/run calls it
# after `cargo test`. Run from anywhere:
#
#   bash crates/cli/viewer/test.sh                 # the checks; screenshots in target/viewer-test/shots/
#   bash crates/cli/viewer/test.sh --update-docs   # also the wet run, and the screenshots into docs/img/viewer/
#
# It installs Debian's chromium when /usr/bin/chromium is missing, the page's npm packages
# (npm ci: three, esbuild, playwright-core, as package-lock.json pins them), builds the atelier
# program, runs a drape and a garment scenario into target/viewer-test/, writes their pages with
# `atelier view`, and opens each page from its file:// URL in headless Chromium
# (test/browser.mjs): one line per check, a count at the end, exit status 1 when one failed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
update_docs=false
for arg in "$@"; do
  case "$arg" in
    --update-docs) update_docs=true ;;
    *) echo "usage: $0 [--update-docs]" >&2; exit 1 ;;
  esac
done
start=$SECONDS
step() { echo "== $* ($((SECONDS - start)) s)"; }

if [[ ! -x /usr/bin/chromium ]]; then
  step "installing Debian's chromium"
  sudo=""
  if [[ "$(id -u)" != 0 ]]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq chromium >/dev/null
fi

step "npm ci (crates/cli/viewer)"
(cd "$here" && npm ci --no-audit --no-fund --loglevel=error)

# As `cargo test --workspace --release` builds it: a no-op after that command (.ci/run), where
# `cargo build -p atelier-cli` would rebuild most of the program with other features.
step "cargo test --workspace --release --no-run"
(cd "$root" && cargo test --workspace --release --no-run --quiet)
atelier="$root/target/release/atelier"

out="$root/target/viewer-test"
shots="$out/shots"
rm -rf "$out"
mkdir -p "$shots"

run() { # NAME SCENARIO: a run folder with its page
  step "atelier run $2"
  # Status 2 (an expectation missed, a step not converged) still writes every output.
  # From the repository's root, so that the report names the scenario file as the docs show it.
  (cd "$root" && "$atelier" run "fixtures/scenarios/$2" --out "$out/$1") >"$out/$1.log" 2>&1 || [[ $? == 2 ]] || {
    cat "$out/$1.log" >&2
    exit 1
  }
  "$atelier" view "$out/$1" >/dev/null
}
run drape drape_thesis_silk.ron
run garment skirt_sewn.ron
cases=(drape="$out/drape" garment="$out/garment")
if $update_docs; then
  run wet wet_pinch1_air0.ron
  cases+=(wet="$out/wet")
fi

# A run folder whose run.glb is gone, and a page whose viewer-data.js is gone.
# `atelier view` writes the page all the same, names the problem on stderr and exits with 2.
cp -r "$out/drape" "$out/missing-glb"
rm "$out/missing-glb/run.glb"
# (browser.mjs checks the status and the message it left in missing-glb.view).
status=0
"$atelier" view "$out/missing-glb" >/dev/null 2>"$out/missing-glb.log" || status=$?
{ echo "$status"; cat "$out/missing-glb.log"; } >"$out/missing-glb.view"
cp -r "$out/garment" "$out/no-data"
rm "$out/no-data/viewer-data.js"
cases+=(missing-glb="$out/missing-glb" no-data="$out/no-data")

step "browser checks"
node "$here/test/browser.mjs" --shots "$shots" "${cases[@]}"

if $update_docs; then
  mkdir -p "$root/docs/img/viewer"
  for shot in drape garment garment-strain wet missing-glb; do
    cp "$shots/$shot.png" "$root/docs/img/viewer/$shot.png"
  done
  echo "copied the screenshots into docs/img/viewer/"
fi
step "done"

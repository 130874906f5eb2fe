#!/bin/sh
# Issue 10's peers on atelier's scenes: rapier-cloth 0.3.0 (Rust, crates.io) and pypbd 2.2.2
# (PositionBasedDynamics' Python package, PyPI). Writes OUT_DIR/peers_rapier.json and
# OUT_DIR/peers_pypbd.json (OUT_DIR: the first argument, default benches/peers/out).
#   sh benches/peers/run.sh [OUT_DIR] [--quick]
# --quick: a smoke run, the 50 x 50 sheet with each peer's defaults only.
# Fails if a peer cannot run at all; a diverging case is a recorded row, not a failure.
set -eu

HERE=$(cd "$(dirname "$0")" && pwd)
OUT_DIR="$HERE/out"
QUICK=""
for arg in "$@"; do
  case "$arg" in
    --quick) QUICK="--quick" ;;
    *) OUT_DIR="$arg" ;;
  esac
done
mkdir -p "$OUT_DIR"
OUT_DIR=$(cd "$OUT_DIR" && pwd)

# rapier-cloth: a publish = false crate with its own workspace and target dir.
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HERE/target}" \
  cargo run --release --locked --manifest-path "$HERE/Cargo.toml" -- \
  --out "$OUT_DIR/peers_rapier.json" $QUICK

# pypbd: a venv beside this script, the package pinned.
PY="${PYTHON:-python3}"
if [ ! -x "$HERE/.venv/bin/python" ]; then
  "$PY" -m venv "$HERE/.venv"
fi
"$HERE/.venv/bin/python" -m pip install --quiet --disable-pip-version-check "pypbd==2.2.2" "numpy>=1.24"
"$HERE/.venv/bin/python" "$HERE/pypbd_scenes.py" --out "$OUT_DIR/peers_pypbd.json" $QUICK

echo "wrote $OUT_DIR/peers_rapier.json and $OUT_DIR/peers_pypbd.json"

#!/usr/bin/env bash
# The Python bindings' tests (docs/python.md): build and install the module `atelier` from
# source into a virtual environment under target/ exactly as a user would (`pip install
# ./crates/python`: pip fetches maturin as the build backend and builds the Rust extension),
# build the `atelier` program the tests compare with, and run pytest on crates/python/tests.
#
#   crates/python/test.sh [PYTEST ARGS…]
#
# Environment: PYTHON (the interpreter the venv is made from, ≥ 3.9; default python3),
# ATELIER_PYTHON_VENV (default target/python-venv). Prints the time of each part at the end.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
venv=${ATELIER_PYTHON_VENV:-$root/target/python-venv}
python=${PYTHON:-python3}
export PYTHONDONTWRITEBYTECODE=1 PIP_DISABLE_PIP_VERSION_CHECK=1

now() { date +%s.%N; }
took() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }

t0=$(now)
if [ ! -x "$venv/bin/python" ]; then
  "$python" -m venv "$venv"
fi
# numpy (the module's one dependency) and pytest; then the module itself, rebuilt every time
# (--force-reinstall: the version does not change when the sources do).
"$venv/bin/python" -m pip install --quiet numpy pytest
"$venv/bin/python" -m pip install --quiet --no-deps --force-reinstall ./crates/python
t1=$(now)
# The reference the tests compare with: the `atelier` program as `cargo test --workspace
# --release` builds it (a no-op after that command, which .ci/run runs first). Not `cargo build
# -p atelier-cli`: that resolves the crates' features for the one package, so after the
# workspace's tests it rebuilt most of the program (258 s in session 19's CI run).
cargo test --workspace --release --no-run --quiet
t2=$(now)
status=0
ATELIER_CLI="$root/target/release/atelier" "$venv/bin/python" -m pytest -p no:cacheprovider -q \
  crates/python/tests "$@" || status=$?
t3=$(now)
echo "crates/python/test.sh: wheel build and install $(took "$t0" "$t1") s, atelier program build $(took "$t1" "$t2") s, pytest $(took "$t2" "$t3") s"
exit $status

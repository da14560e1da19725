#!/usr/bin/env bash
# Builds the clutchpack wheel (crates/python, maturin, release) and installs it into a fresh
# virtual environment, target/pyenv-wheel (or $CARGO_TARGET_DIR/pyenv-wheel), with the pinned
# packages of tests/python/wheel-requirements.txt; prints that environment's python on
# stdout (the only thing printed there). The extension builds in its own target folder
# (target/python-ext): the tests' cargo holds the main one.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
py="$(bash "$root/tests/python/setup.sh")"
wheels="$target/wheels"
rm -rf "$wheels"
CARGO_TARGET_DIR="$target/python-ext" "$py" -m maturin build --release --quiet \
    --manifest-path "$root/crates/python/Cargo.toml" --out "$wheels" --interpreter "$py" >&2
wheel="$(ls "$wheels"/clutchpack-*.whl)"
venv="$target/pyenv-wheel"
"${PYTHON:-python3}" -m venv --clear "$venv" >&2
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r "$root/tests/python/wheel-requirements.txt" "$wheel" >&2
echo "$venv/bin/python"

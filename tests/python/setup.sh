#!/usr/bin/env bash
# Creates the virtual environment target/pyenv (or $CARGO_TARGET_DIR/pyenv) with the pinned
# packages of tests/python/requirements.txt, and prints the path of its python on stdout
# (the only thing printed on stdout). Idempotent: it does nothing when the environment is
# already there with the same requirements.
#
#   py=$(bash tests/python/setup.sh) && "$py" tests/python/read_mcap.py FILE.mcap
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
venv="$target/pyenv"
req="$root/tests/python/requirements.txt"
stamp="$venv/.requirements.sha256"
want="$(sha256sum "$req" | cut -d' ' -f1)"
if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
    echo "$venv/bin/python"
    exit 0
fi
python="${PYTHON:-python3}"
command -v "$python" >/dev/null || { echo "setup.sh: $python not found" >&2; exit 1; }
mkdir -p "$target"
"$python" -m venv --clear "$venv" >&2
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req" >&2
echo "$want" > "$stamp"
echo "$venv/bin/python"

#!/usr/bin/env bash
# Builds the Python package `rwt-noise` (crates/rwt_py) into a fresh virtual environment with what
# its tests need, and runs them: `scripts/python_env.sh [pytest args]`. The environment is
# target/py-venv; `source target/py-venv/bin/activate` to use it afterwards.
#   RWT_PY_KEEP=1 scripts/python_env.sh   # reuse the environment (only rebuild the package)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/py-venv
# pip runs maturin (the build backend) from the environment's bin.
export PATH=$PWD/$venv/bin:$PATH
if [ "${RWT_PY_KEEP:-0}" != 1 ] || [ ! -x "$venv/bin/python" ]; then
    rm -rf "$venv"
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --upgrade pip
    # Without compiling every module to bytecode up front (about 14 s of CPU): Python
    # compiles the few the tests import when they first do.
    "$venv/bin/pip" install --quiet --no-compile "maturin>=1.7,<2" numpy pytest scipy "dask[array]" matplotlib mypy \
        shapely geopandas
fi
# The wheel a user installs: one abi3 wheel for every CPython from 3.9 on, with the license
# texts; the tests run on the package installed from it.
rm -rf target/wheels
"$venv/bin/maturin" build --quiet --release --manifest-path crates/rwt_py/Cargo.toml --out target/wheels
wheel=$(ls target/wheels/rwt_noise-*-cp39-abi3-*.whl)
"$venv/bin/python" - "$wheel" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
for wanted in ("LICENSE-MIT", "LICENSE-APACHE"):
    assert any(n.endswith(wanted) for n in names), f"{wanted} is not in {sys.argv[1]}"
PY
"$venv/bin/pip" install --quiet --force-reinstall --no-deps "$wheel"
# The CLI comparison runs `rwt points`: the debug build `cargo test` made, or one made now.
[ -x target/debug/rwt ] || cargo build --quiet -p rwt_cli
export RWT_CLI=$PWD/target/debug/rwt
cd crates/rwt_py
"../../$venv/bin/python" -m pytest -q "$@"

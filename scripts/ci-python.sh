#!/usr/bin/env bash
# Builds the Python wheel (python/, pyo3 + maturin, abi3 for Python >= 3.9), installs it into a
# virtualenv with the test dependencies, and runs the pytest suite in python/tests against it.
# Creates (or reuses) the virtualenv in target/python-venv. Exits non-zero when the build, the
# install or any test fails, and when pytest collects no test at all.
set -euo pipefail
cd "$(dirname "$0")/.."

venv=target/python-venv
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import maturin, pytest, numpy, trimesh, dask.distributed" 2>/dev/null; then
  echo "ci-python: setting up $venv (maturin, pytest, numpy, trimesh, dask[distributed])"
  python3 -m venv "$venv" || { echo "ci-python: python3 -m venv failed" >&2; exit 2; }
  "$venv/bin/pip" install --quiet --upgrade pip
  "$venv/bin/pip" install --quiet maturin pytest numpy trimesh "dask[distributed]" \
    || { echo "ci-python: pip install failed" >&2; exit 2; }
fi

echo "ci-python: building the wheel (release)"
rm -rf target/wheels
"$venv/bin/maturin" build --quiet --release -m python/Cargo.toml -o target/wheels -i "$venv/bin/python"
wheel=$(ls target/wheels/roar-*.whl)
"$venv/bin/pip" install --quiet --force-reinstall --no-deps "$wheel"

echo "ci-python: pytest"
status=0
(cd python/tests && "../../$venv/bin/python" -m pytest -q -p no:cacheprovider .) || status=$?
if [ "$status" -eq 5 ]; then
  echo "ci-python: pytest collected no test" >&2
  exit 1
fi
exit "$status"

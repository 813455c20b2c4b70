#!/usr/bin/env bash
# Runs every tubemem test: formatting, clippy, the Rust workspace tests, the Python reference
# tests and the tests of the Python API (the PyO3 module built by maturin), in a virtual
# environment that this script creates (./.venv) and fills from PyPI.
# This is the README's test command, and .ci/run calls exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."

# A clean run builds the workspace in the release profile (the tests, the binary and the
# Python module share its dependencies; the tests run on the optimized code that ships) plus
# the wheel of the pip check, and clippy's check build: about 12 GiB. Say so up front rather
# than let pip or the linker die of ENOSPC half-way.
FREE_KIB=$(df -Pk . | awk 'NR==2 {print $4}')
echo "== free disk here: $((FREE_KIB / 1048576)) GiB"
if [ "$FREE_KIB" -lt $((12 * 1048576)) ]; then
  echo "warning: less than 12 GiB free; a clean test run may fail with 'No space left on device'" >&2
fi

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy (all targets, warnings are errors)"
cargo clippy --workspace --all-targets -- -D warnings
echo "== cargo doc (library docs, rustdoc warnings are errors)"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --lib
echo "== module cycles (a module may not depend on one that depends on it)"
python3 scripts/module-cycles.py
# the man-page test renders every page with groff, as man does
if ! command -v groff > /dev/null; then
  echo "== installing groff-base (the man-page test renders the pages with groff)"
  apt-get install -y -qq groff-base > /dev/null || sudo -n apt-get install -y -qq groff-base > /dev/null
fi
# In the release profile: a second optimized build (the dev profile's) would cost several
# minutes of a cold run. What the tests give up is the dev profile's integer overflow checks
# and debug assertions (the workspace has one `debug_assert!`).
echo "== cargo test (workspace, release profile)"
cargo test --workspace --release
# The Python tests drive the release binary (the same one users run). Built for the CLI alone,
# its crates' features differ from the workspace test build's, so the app and the CLI compile
# once more (about a minute); the dependencies are shared.
cargo build --release -p tubemem-cli

echo "== Python reference tests"
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -r python_ref/requirements.txt
.venv/bin/python -m pip install --quiet -e python_ref
echo "== Python API: maturin develop (crates/py, release)"
.venv/bin/python -m pip install --quiet "maturin>=1.16,<2"
VIRTUAL_ENV="$PWD/.venv" .venv/bin/maturin develop --release --quiet -m crates/py/Cargo.toml
echo "== tubemem verify verify/ci.toml (FE against closed form, references and gold files)"
TUBEMEM_PYTHON="$PWD/.venv/bin/python" target/release/tubemem verify verify/ci.toml --out target/verify-ci
echo "== tubemem atlas atlas/ci.toml (the small atlas: 6 FE runs, fits, maps; about 10 s)"
rm -rf target/atlas-ci
target/release/tubemem atlas atlas/ci.toml --out target/atlas-ci
target/release/tubemem atlas predict target/atlas-ci --lambda-s-star 1.3 --rho 0.8 --length-ratio 80
echo "== pytest: python_ref/tests"
TUBEMEM_BIN="$PWD/target/release/tubemem" .venv/bin/python -m pytest python_ref/tests -q
echo "== the Python package installs with plain pip in a fresh venv (no maturin beforehand)"
WHEEL_VENV=$(mktemp -d)
"$PY" -m venv "$WHEEL_VENV"
"$WHEEL_VENV/bin/python" -m pip install --quiet ./crates/py
"$WHEEL_VENV/bin/python" -c "import numpy, tubemem; w = tubemem.gps_inflate(numpy.array([1.3]))['w'][0]; assert abs(w - 0.6514226) < 1e-6, w; print('pip install ./crates/py: ok, gps_inflate(1.3) =', w)"
rm -rf "$WHEEL_VENV"
echo "== pytest: crates/py/tests (the Python API)"
.venv/bin/python -m pytest crates/py/tests -q
echo "== the book (docs/): pages generated, README headline current, one verification family rerun, mdBook build, links, examples"
MDBOOK_VERSION=0.5.4
TOOLS="${TUBEMEM_TOOLS:-$HOME/.cache/tubemem/tools}"
if ! "$TOOLS/bin/mdbook" --version 2>/dev/null | grep -qx "mdbook v$MDBOOK_VERSION"; then
  echo "   installing mdbook $MDBOOK_VERSION into $TOOLS (once; several minutes on 2 cores)"
  cargo install --locked --quiet mdbook --version "$MDBOOK_VERSION" --no-default-features \
    --features search --root "$TOOLS"
fi
export TUBEMEM="$PWD/target/release/tubemem" PYTHON="$PWD/.venv/bin/python"
python3 scripts/docs.py generate
python3 scripts/docs.py check
python3 scripts/docs.py refresh-one invariance
rm -rf docs/book
"$TOOLS/bin/mdbook" build docs
python3 scripts/docs.py linkcheck docs/book
python3 scripts/docs.py examples

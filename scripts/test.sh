#!/usr/bin/env bash
# The README's test command: installs what the suite needs (uv; Chromium for the browser check when running as
# root with apt-get), checks lint and formatting (ruff), then runs pytest on every core (pytest-xdist; a module's
# tests stay on one worker so its shared runs are made once; modules go out in the order tests/conftest.py sets:
# the browser checks first). Extra arguments go to pytest.
# Python's bytecode is cached under .pytest_cache/bytecode even when PYTHONDONTWRITEBYTECODE is set: the suite
# starts hundreds of Python processes (xdist workers, the console scripts in real processes), and without a cache
# each one compiles every module it imports (numpy, scipy, rerun, the devkit...) from source again, 1.5 s of CPU
# for `gnnpmb` alone; the cache stays out of the source tree and the venv.
set -euo pipefail
cd "$(dirname "$0")/.."
if command -v uv >/dev/null 2>&1; then
    UV=(uv)
else
    python3 -m pip install --quiet --disable-pip-version-check uv
    UV=(python3 -m uv)
fi
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    if ! command -v chromium >/dev/null 2>&1; then
        echo "installing Chromium for the browser check (apt-get)" >&2
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
    fi
    # Chromium can be installed here, so the browser check must run rather than skip.
    export GNNPMB_REQUIRE_BROWSER="${GNNPMB_REQUIRE_BROWSER:-1}"
fi
unset PYTHONDONTWRITEBYTECODE
export PYTHONPYCACHEPREFIX="${PYTHONPYCACHEPREFIX:-$PWD/.pytest_cache/bytecode}"
"${UV[@]}" run ruff check .
"${UV[@]}" run ruff format --check .
exec "${UV[@]}" run pytest -n auto --dist loadscope --no-loadscope-reorder "$@"

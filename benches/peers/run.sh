#!/usr/bin/env bash
# Side-by-side benchmarks: our Python binding against the library a user would otherwise
# pick, on the same inputs. Sets up its own virtualenv of peer libraries, builds the wscg
# wheel into it in release mode, runs every benches/peers/<name>.py (or the ones named on
# the command line, e.g. `run.sh wscg_math`; a script must not be named after a standard module) and prints one table per script:
# workload, ours (s), peer (s), ratio peer/ours (> 1 means wscg is faster).
#
# Environment: WSCG_PEERS_VENV (default benches/peers/.venv), CARGO_TARGET_DIR.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=${WSCG_PEERS_VENV:-$PWD/benches/peers/.venv}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$PWD/target}
if ! "$venv/bin/python" -c 'import sys' >/dev/null 2>&1; then
  rm -rf "$venv"
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r benches/peers/requirements.txt
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps \
  -r benches/peers/requirements-nodeps.txt
VIRTUAL_ENV=$venv PATH="$venv/bin:$PATH" "$venv/bin/maturin" develop --release --quiet \
  --manifest-path py/Cargo.toml
if [ $# -gt 0 ]; then
  scripts=()
  for name in "$@"; do scripts+=("benches/peers/$name.py"); done
else
  scripts=(benches/peers/[0-9a-z]*.py)
fi
echo "machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
for s in "${scripts[@]}"; do
  echo
  echo "== $s"
  "$venv/bin/python" "$s"
done

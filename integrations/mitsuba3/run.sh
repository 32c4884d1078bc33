#!/usr/bin/env bash
# The Guiding Light Tree inside Mitsuba 3, against Mitsuba's own light
# choice: makes a venv, installs Mitsuba 3.9.1 from PyPI and the crate's
# Python bindings from this checkout, and runs compare.py with the
# arguments given (`--quick`: a few minutes, one line per scene at the end).
#
#   integrations/mitsuba3/run.sh --quick
#   integrations/mitsuba3/run.sh --seconds 60 --sheet docs/images
#
# Dr.Jit's CPU backend loads LLVM at run time: Debian's libllvm19 (LLVM 15
# fails), installed here when missing.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="${GUIDING_MITSUBA_VENV:-$root/target/mitsuba3-venv}"

llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ ! -e "$llvm" ]; then
    as_root=""
    [ "$(id -u)" -ne 0 ] && as_root="sudo -n"
    $as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $as_root apt-get install -y -qq --no-install-recommends libllvm19 >/dev/null
fi
export DRJIT_LIBLLVM_PATH="$llvm"

[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install -q --upgrade pip
"$venv/bin/pip" install -q "mitsuba==3.9.1" pillow "$root/python"
cd "$root"
exec "$venv/bin/python" "$here/compare.py" "$@"

#!/bin/sh
# The rs_pbrt comparison in one command, from a fresh clone: cargo fetches
# rs_pbrt 0.9.12 from crates.io, builds it with the glue, renders the
# committed scenes (scenes/) with rs_pbrt's light strategies (uniform,
# power, spatial) and the GLT at equal samples and at equal time against a
# long reference (rendered once into out/, then reused), and prints the
# tables docs/results.md shows. Extra arguments go to the program, e.g.
#   ./run.sh --scene two_rooms --spp 64
#   ./run.sh --check      # CI: builds the glue, renders a tiny scene
set -eu
cd "$(dirname "$0")"
exec cargo run --release --quiet -- "$@"

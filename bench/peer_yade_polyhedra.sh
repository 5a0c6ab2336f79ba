#!/usr/bin/env bash
# Yade's convex-polyhedra deposition (the peer anchor of bench/rigid_deposition.py), run on this
# machine from a scratch copy of the peer scripts, printing Yade's RESULT line.
#
# Usage: bench/peer_yade_polyhedra.sh [N=200] [THREADS=1]
#   WALLCAP (s, default 110) caps Yade's run as in shared/peers/dem/RESULTS.md; MAXSTEPS caps steps.
#   PEER_DIR overrides the peer folder (default /work/shared/peers/dem/yade).
# Needs Yade: apt-get update && apt-get install -y yade (Debian 12: Yade 2023.02a, ~2.3 GB).
# RESULT fields: pps = body-steps/s over the whole run, medChunkPps = the same over the median
# 250-step chunk; meanContacts/lastContacts = Yade's real interactions (walls included).
set -euo pipefail

n_bodies=${1:-200}
threads=${2:-1}
peer_dir=${PEER_DIR:-/work/shared/peers/dem/yade}

if ! command -v yade > /dev/null; then
    echo "yade is not installed: apt-get update && apt-get install -y yade" >&2
    exit 2
fi
if [ ! -f "$peer_dir/bench_polyhedra.py" ]; then
    echo "no bench_polyhedra.py in $peer_dir (set PEER_DIR)" >&2
    exit 2
fi

scratch=$(mktemp -d /tmp/riprap-peer-yade.XXXXXX)
trap 'rm -rf "$scratch"' EXIT
cp "$peer_dir"/*.py "$scratch"/
log="$scratch/yade_polyhedra_n${n_bodies}_j${threads}.log"

echo "yade polyhedra N=$n_bodies threads=$threads WALLCAP=${WALLCAP:-110} $(date -u +%FT%TZ)"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
(cd "$scratch" && WALLCAP=${WALLCAP:-110} yade -n -x -j"$threads" bench_polyhedra.py "$n_bodies" \
    > "$log" 2>&1) || { tail -20 "$log" >&2; exit 1; }
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
grep -E '^(N=|PROGRESS)' "$log" || true
# Yade's CGAL polyhedra print many "Unhandled switch case" warnings; count rather than show them.
echo "warnings in log: $(grep -c -i 'warn\|unhandled' "$log" || true)"
grep '^RESULT' "$log"

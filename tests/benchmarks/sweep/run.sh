#!/usr/bin/env bash
# The sweep benchmark of the README (issue "Sweeps beyond one machine"): a
# 40 x 40 map of the forced Duffing oscillator (w x F, order 10, 8 random
# starts per point) on 1, 2 and 4 MPI ranks (oversubscribed on a small
# machine), the files compared byte for byte, then a 3-rank run with one
# rank killed part-way and resumed on 4 ranks: same bytes, no point twice.
#   bash tests/benchmarks/sweep/run.sh [build-dir]
set -euo pipefail
build=${1:-build}
rmhb=$(realpath "$build/rmhb")
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
grid="--grid w=0.5:2.5:40 --grid F=0.1:1.5:40 --order 10 --starts 8"

printf "%6s %10s %10s %16s %14s %10s\n" ranks computing seconds points/s per-rank/s "MiB/rank"
for ranks in 1 2 4; do
  if [ "$ranks" = 1 ]; then launch=""; else launch="mpirun -n $ranks"; fi
  $launch "$rmhb" sweep duffing $grid --out "$dir/r$ranks.h5" --json > "$dir/r$ranks.json"
  python3 - "$dir/r$ranks.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print("%6d %10d %10.2f %16.1f %14.1f %10.0f" % (r["ranks"], r["computing_ranks"], r["seconds"],
      r["points_per_second"], r["points_per_second_per_rank"], r["peak_memory_mib_per_rank"]))
PY
done
cmp "$dir/r1.h5" "$dir/r2.h5" && cmp "$dir/r1.h5" "$dir/r4.h5" && echo "1, 2 and 4 ranks: identical files"

mpirun -n 3 "$rmhb" sweep duffing $grid --out "$dir/k.h5" --log "$dir/k.log" > /dev/null 2>&1 &
job=$!
while [ "$(cat "$dir/k.log" 2>/dev/null | wc -l)" -lt 600 ]; do sleep 0.1; done
pkill -KILL -n -f "rmhb sweep duffing .*$dir/k.h5" || true
wait $job || true
echo "killed one of 3 ranks after $(wc -l < "$dir/k.log") points; resuming on 4 ranks"
mpirun -n 4 "$rmhb" sweep duffing $grid --out "$dir/k.h5" --log "$dir/k.log" --resume | sed -n 2,3p
cmp "$dir/r1.h5" "$dir/k.h5" && echo "killed + resumed: identical file"
echo "log lines: $(wc -l < "$dir/k.log"), points computed twice: $(awk '{print $2}' "$dir/k.log" | sort | uniq -d | wc -l)"

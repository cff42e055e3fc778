#!/bin/bash
# The device measurements of docs/distributed.md's session-21 table: the path tracer at 4K,
# 64 spp, 1 x 16 threads against 4 x 4 ranks, alternated three times on one machine (each
# 4 x 4 run right after its 1 x 16 run), then 2 x 8 and 8 x 2 at 16 spp and a GPU rank
# beside a CPU rank at 64 spp. Copy to /work/main/build-carry-<name>/go.sh beside
# bundle.tar.xz (scripts/gpu-bundle.sh, then scripts/gpu-bundle-mpi.sh, then tar + xz of
# .gpu-bundle) and run with that folder carried. LUCENT_RANK_REBALANCE=off and
# LUCENT_RANK_SHARED=0 (mpirun -x) give the rows of the sessions before.
here=$(cd "$(dirname "$0")" && pwd); cd "$here/.."
t0=$(date +%s)
tar xJf "$here/bundle.tar.xz"
B=$PWD/.gpu-bundle
L="$B/run $B/bin/lucent"
M="$B/mpirun --bind-to none --oversubscribe"
{ nproc; nvidia-smi -L; lscpu | grep -E "Model name"; echo "untar $(( $(date +%s) - t0 )) s"; } > $OUT/machine.txt 2>&1
PT="render --sample pathtracer --size 3840x2160 --backend cpu"
stamp() { echo "== $1: $(( $(date +%s) - t0 )) s since start"; }
{
for round in 1 2 3; do
stamp "1x16 64spp round $round"; timeout 60 $L $PT --spp 64 --threads 16 --out /tmp/pt-1x16.pfm
stamp "4x4 64spp re-balanced + shared tail round $round"; timeout 60 $M -np 4 -x LUCENT_MULTI_TRACE=1 $L $PT --spp 64 --threads 4 --out /tmp/pt-4x4.pfm
cmp /tmp/pt-1x16.pfm /tmp/pt-4x4.pfm && echo "4x4 image == 1x16 image (cmp)"
done
stamp "1x16 16spp"; timeout 40 $L $PT --spp 16 --threads 16 --out /tmp/pt-1x16-16.pfm
stamp "2x8 16spp"; timeout 40 $M -np 2 $L $PT --spp 16 --threads 8 --out /tmp/pt-2x8.pfm
stamp "8x2 16spp"; timeout 40 $M -np 8 $L $PT --spp 16 --threads 2 --out /tmp/pt-8x2.pfm
cmp /tmp/pt-1x16-16.pfm /tmp/pt-8x2.pfm && echo "8x2 image == 1x16 image (cmp)"
cmp /tmp/pt-1x16-16.pfm /tmp/pt-2x8.pfm && echo "2x8 image == 1x16 image (cmp)"
stamp "gpu alone 64spp"; timeout 50 $L render --sample pathtracer --size 3840x2160 --backend cuda --spp 64 --out /tmp/pt-gpu.pfm
stamp "gpu rank + cpu rank (15 threads) 64spp"; timeout 40 $M -x LUCENT_MULTI_TRACE=1 -np 1 $L render --sample pathtracer --size 3840x2160 --backend cuda --spp 64 --out /tmp/pt-mix.pfm : -np 1 $L $PT --spp 64 --threads 15 --out /tmp/pt-mix.pfm
$L compare /tmp/pt-gpu.pfm /tmp/pt-mix.pfm
stamp done
} > $OUT/pathtracer.txt 2>&1
grep -v "^distributed" $OUT/pathtracer.txt | tail -40

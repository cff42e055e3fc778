#!/bin/bash
# The second device call of docs/distributed.md ("Figures"): CPU ranks bound to cores.
here=$(cd "$(dirname "$0")" && pwd); cd "$here/.."
t0=$(date +%s)
tar xJf "$here/bundle.tar.xz"
B=$PWD/.gpu-bundle
L="$B/run $B/bin/lucent"
export PMIX_MCA_pcompress_base_silence_warning=1
M="$B/mpirun --oversubscribe"
PT="render --sample pathtracer --size 3840x2160 --backend cpu"
stamp() { echo "== $1: $(( $(date +%s) - t0 )) s since start"; }
{
stamp "1x16 16spp"; timeout 30 $L $PT --spp 16 --threads 16 --out /tmp/a.pfm
stamp "4x4 16spp unbound"; timeout 30 $M --bind-to none -np 4 $L $PT --spp 16 --threads 4 --out /tmp/b.pfm
stamp "4x4 16spp bound PE=4"; timeout 30 $M -np 4 --map-by slot:PE=4 --bind-to core -x LUCENT_MULTI_TRACE=1 $L $PT --spp 16 --threads 4 --out /tmp/c.pfm
stamp "4x4 16spp bound PE=4, 64 pieces per rank"; timeout 30 $M -np 4 --map-by slot:PE=4 --bind-to core -x LUCENT_RANK_PIECES=64 $L $PT --spp 16 --threads 4 --out /tmp/d.pfm
stamp "2x8 16spp bound PE=8"; timeout 30 $M -np 2 --map-by slot:PE=8 --bind-to core $L $PT --spp 16 --threads 8 --out /tmp/e.pfm
stamp "8x2 16spp bound PE=2"; timeout 30 $M -np 8 --map-by slot:PE=2 --bind-to core $L $PT --spp 16 --threads 2 --out /tmp/f.pfm
for x in c d e f; do cmp /tmp/a.pfm /tmp/$x.pfm && echo "$x == 1x16 (cmp)"; done
stamp "4x4 64spp bound PE=4"; timeout 45 $M -np 4 --map-by slot:PE=4 --bind-to core $L $PT --spp 64 --threads 4 --out /tmp/g.pfm
stamp done
} > $OUT/pathtracer2.txt 2>&1
grep -E "==|launch \(frame\)|render  " $OUT/pathtracer2.txt | tail -30

#!/usr/bin/env bash
# Before/after figures on a GPU machine, in one run: the same commands through two bundles,
# run alternately (A B A B ...) so that clock and thermal drift fall on both alike.
# Usage: scripts/gpu-compare.sh BASE_BUNDLE NEW_BUNDLE [ROUNDS]  (bundles made by
# scripts/gpu-bundle.sh; BASE is typically the bundle of the previous main, unpacked).
# Prints each figure per round, then the median per bundle and the ratio new/base.
set -uo pipefail
base=$1 new=$2 rounds=${3:-3}
out=${OUT:-gpu-out}
mkdir -p "$out" /work/shared/scenes
[ -f /work/shared/scenes/sponza.obj ] || tar xzf "$new/scenes.tgz" -C /work/shared/scenes
igi_scene=$(ls bench/scenes/sponza-igi.json bench/*/scenes/sponza-igi.json 2>/dev/null | head -1)
export LUCENT_SCENE_PATH=/work/shared/scenes
log="$out/compare.log"
: > "$log"

# figure NAME BUNDLE CMD...: runs CMD with the bundle's lucent and appends "NAME BUNDLE VALUE".
figure() {
    local name=$1 bundle=$2; shift 2
    local text value
    text=$("$bundle/run" "$bundle/bin/lucent" "$@" 2>&1)
    case $name in
        whitted_fps) value=$(echo "$text" | awk '/^  launch/ {print 1000 / $2; exit}') ;;
        pathtracer_spp_s) value=$(echo "$text" | awk '/steady state/ {for (i = 1; i <= NF; ++i) if ($i == "state") print $(i + 1); exit}') ;;
        igi_*) value=$(echo "$text" | python3 -c "import json,sys; d=json.load(sys.stdin); print(' '.join(f\"{r['configuration'].replace(' ', '_')}={r['fps']:.2f}\" for r in d['rows'] if r.get('vpls', 180) == 180))") ;;
        fog_fps) value=$(echo "$text" | python3 -c "import json,sys; d=json.load(sys.stdin); print(' '.join(f\"{r['configuration'].replace(' ', '_')}={r['fps']:.2f}\" for r in d['rows']))") ;;
        rays_*) value=$(echo "$text" | python3 -c "import json,sys; d=json.load(sys.stdin); print(json.dumps(d)[:2000])") ;;
    esac
    [ -n "$value" ] || { echo "$name $bundle: no figure; output:"; echo "$text" | tail -15; }
    echo "$name $(basename "$bundle") $value" | tee -a "$log"
}

for round in $(seq "$rounds"); do
    for b in "$base" "$new"; do
        figure whitted_fps "$b" render --sample whitted --backend cuda --size 1024x1024 --repeat 500 --out "$out/w.png"
        figure pathtracer_spp_s "$b" render --sample pathtracer --scene cornell --backend cuda --size 1024x1024 --spp 256 --out "$out/p.png"
        figure igi_sponza "$b" bench igi --backend cuda --scene "$igi_scene" --frames 50 --vpls 180 --json
        figure fog_fps "$b" bench fog --backend cuda --frames 100 --json
    done
done
for b in "$base" "$new"; do
    figure rays_sponza "$b" bench rays --backend cuda --scene /work/shared/scenes/sponza.obj --repeat 9 --json
done
python3 - "$log" "$(basename "$base")" "$(basename "$new")" <<'PY'
import sys, statistics, collections
log, base, new = sys.argv[1:]
vals = collections.defaultdict(list)
for line in open(log):
    parts = line.split()
    if len(parts) < 3 or parts[0].startswith("rays_"): continue
    name, bundle = parts[0], parts[1]
    for item in parts[2:]:
        key, _, v = item.rpartition("=")
        try: vals[(name + (":" + key if key else ""), bundle)].append(float(v))
        except ValueError: pass
names = sorted({k for k, _ in vals})
print(f"{'figure':40s} {'base median (spread)':>26s} {'new median (spread)':>26s}  new/base")
for n in names:
    a, b = vals.get((n, base), []), vals.get((n, new), [])
    if not a or not b: continue
    ma, mb = statistics.median(a), statistics.median(b)
    print(f"{n:40s} {ma:12.2f} ({min(a):.1f}-{max(a):.1f}) {mb:12.2f} ({min(b):.1f}-{max(b):.1f})  {mb / ma:.3f}")
PY

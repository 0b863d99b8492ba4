#!/bin/bash
# Side by side (BENCHMARKS.md, "Beside Embree"): lumiere (render_ms from --stats-json, median of 3) and embree_native --packet 1 (median of 3), per lab row, 2 threads.
cd "$(dirname "$0")/.."
L=target/release/lumiere; E=${EMBREE_NATIVE:-/tmp/embree-native/embree_native}
median() { sort -n | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}'; }
row() { label=$1; lmode=$2; emode=$3; n=$4
  lt=$(for i in 1 2 3; do $L render --threads 2 --mode $lmode $( [ -n "$n" ] && echo --samples $n ) --stats-json /tmp/s.json -o /tmp/s.pfm 2>/dev/null; python3 -c "import json;print(json.load(open('/tmp/s.json'))['render_ms'])"; done | median)
  et=$($E --mode $emode $( [ -n "$n" ] && echo --samples $n ) --threads 2 --packet 1 --repeat 3 2>/dev/null | grep '^RESULT' | tail -1 | cut -d, -f9)
  echo "| $label | $lt | $et | $(python3 -c "print(f'{$et/$lt:.2f}x')") |"
}
echo "| row | lumiere ms | embree_native --packet 1 ms | lumiere vs Embree |"
echo "|---|---|---|---|"
row "hard shadows" shadows shadows ""
row "soft N=16" direct direct 16
row "soft N=64" direct direct 64
row "soft N=256" direct direct 256
row "AO N=16" ao ao 16
row "AO N=64" ao ao 64
row "AO N=256" ao ao 256

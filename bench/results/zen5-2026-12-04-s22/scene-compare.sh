#!/bin/bash
# usage: scene-compare OLD NEW ROUNDS SCENE [NEW_KERNEL [OLD_KERNEL]]
old=$1; new=$2; rounds=$3; scene=$4; k=${5:+--kernel $5}; ko=${6:+--kernel $6}
for r in $(seq 1 $rounds); do
  if [ $((r % 2)) = 1 ]; then order="old new"; else order="new old"; fi
  for w in $order; do
    if [ $w = old ]; then b="$old $ko"; else b="$new $k"; fi
    $b --scene $scene --sizes 128,256 --threads 1,2 --repeats 5 | awk -v w=$w -v r=$r '$4=="fast"{print w, r, $1, $5, $7}'
  done
done > /tmp/scene-compare.out
python3 - <<'PY'
import statistics as st
d={}
for l in open('/tmp/scene-compare.out'):
    w,r,s,t,ns=l.split(); d.setdefault((int(s),int(t)),{}).setdefault(r,{})[w]=float(ns)
print("| grid | threads | old ns/spring-step (median) | new | new / old (median of paired ratios) | range |")
print("|---|---:|---:|---:|---:|---|")
for (s,t),v in sorted(d.items()):
    rs=[x['new']/x['old'] for x in v.values() if len(x)==2]
    print("| %d x %d | %d | %.2f | %.2f | %.2f | %.2f-%.2f |"%(s,s,t,st.median(x['old'] for x in v.values()), st.median(x['new'] for x in v.values()), st.median(rs), min(rs), max(rs)))
PY

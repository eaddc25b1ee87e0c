#!/bin/bash
old=/work/wt12/build/release/src/clothsim
new=/work/main/build/release/src/clothsim
for scene in hanging drape-sphere; do
  for rep in 1 2 3; do
    for which in old new; do
      exe=$([ $which = old ] && echo $old || echo $new)
      $exe --headless --scene $scene --set cloth.rows=128 --set cloth.cols=128 --auto-substeps 0.5 --duration 0.5 --json 2>/dev/null | python3 -c "
import json,sys; j=json.load(sys.stdin); p=j['profile']
st={s['stage']:s['ms_per_step'] for s in p['stages'] if s['state']=='runs'}
coll=sum(v for k,v in st.items() if k in ('broad phase','sphere','cube','ground'))
print('$scene $which', 'wall %.3f'%j['wall_seconds'], 'substeps', j['substeps_per_step'], 'collision ms/step %.3f'%coll, 'total ms/step %.3f'%(p['total_ms']/j['steps']))"
    done
  done
done

#!/bin/bash
# Level-3 cases of an earlier run of the main preset (tag results-archive-52bef5c: results/table1_mf_mixed.sqlite; mixed precision, t_end 40) re-run at time.dt_accuracy=$1.
# Usage: results/time_steps/whole_cases/run.sh 0.04; run.sh 0.08   (one case after another, 1 thread)
dta=$1
B=${CAPSIM:-build/bin/capsim}   # run 2026-12-05 with a copy of commit bdae181
while read law ab ca; do
  d=${OUT:-runs}/${law}_${ab}_${ca}_dta${dta}
  mkdir -p $d
  $B run - --set capsule.law=$law --set capsule.aspect_ratio=$ab --set capsule.skalak_C=1.0 --set flow.capillary_number=$ca \
    --set mesh.level=3 --set numerics.kernel_precision=mixed --set time.t_end=40 --set time.dt_accuracy=$dta \
    --out $d --threads 1 --json < /dev/null > $d.json 2> $d.err
done <<LIST
neo-hookean 2.0 0.3
neo-hookean 0.5 0.05
neo-hookean 0.5 0.625
skalak 2.0 0.363
skalak 1.0 2.46
LIST

#!/bin/bash
# usage: coll.sh "ENV" steps N...
v=$1; steps=$2; shift 2
cd /work/wt/h53
for N in "$@"; do nx=$((N*5)); nz=$((N*3/2)); env $v OMP_NUM_THREADS=1 /usr/bin/time -f "%U" -o /tmp/coll_time build/muflow cases/collapse.ini domain.nx=$nx domain.nz=$nz domain.ly=$(python3 -c "print(1/$N)") solver.max_steps=$steps solver.preconditioner=${PREC:-multigrid} output.dir=/tmp/h53c_mg_$N output.quiet=on output.fields=off >/dev/null 2>&1; awk -F, -v N=$N -v v="$v" -v t="$(tail -1 /tmp/coll_time)" 'NR>1{s+=$8; n++; if($8>m)m=$8} END{printf "%s N=%d steps %d mean its %.2f max %d user %s\n", v, N, n, s/n, m, t}' /tmp/h53c_mg_$N/history.csv; done

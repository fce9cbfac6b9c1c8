#!/usr/bin/python3
# The level-3 cases of a campaign database that ran to t_end without a periodic stop: per shape period (between
# successive significant minima of D12 — an approximation of solver/diagnostics/period_analysis, without its
# steady rules), min D12 and max tau_min, and where a looser time.period_tolerance (2e-3, 5e-3, 1e-2) would have
# stopped them, with the answer change. Needs the case folders (case.h5) of the database; not part of the product.
# Usage: /usr/bin/python3 results/time_steps/whole_cases/period_stop.py [DB [CAPSIM]]  (default: results/table1/table1_mf_mixed.sqlite,
# build/bin/capsim; reads the cases through `capsim query cases`)
import json
import subprocess
import sys

import h5py
import numpy as np

db = sys.argv[1] if len(sys.argv) > 1 else "results/table1/table1_mf_mixed.sqlite"
capsim = sys.argv[2] if len(sys.argv) > 2 else "build/bin/capsim"
cases = json.loads(subprocess.run([capsim, "query", "cases", "--db", db, "--format", "json"], check=True,
                                  capture_output=True, text=True).stdout)
rows = [(c["law"], c["aspect_ratio"], c["capillary_number"], c["h5_path"], c["t_final"], c["min_D12"],
         c["max_tau_min"], c["wall_s"], json.loads(c["params"]).get("time.dt", "auto"))
        for c in cases if c["mesh_level"] == 3 and c["status"] == "done"]
def windows(t,D,tau):
    # D12 minima with prominence
    idx=[]
    half=D[len(D)//2:]; prom=max(1e-4,0.2*(half.max()-half.min()))
    for i in range(1,len(D)-1):
        if D[i]<=D[i-1] and D[i]<D[i+1]:
            # prominence check both sides
            l=D[:i].max() if i>0 else D[i]; r=D[i+1:].max()
            # local: rise to next max on both sides
            j=i
            while j>0 and D[j-1]>=D[j]: j-=1
            k=i
            while k<len(D)-1 and D[k+1]>=D[k]: k+=1
            if D[j]-D[i]>=prom*0.5 and D[k]-D[i]>=prom*0.5: idx.append(i)
    w=[]
    for a,b in zip(idx[:-1],idx[1:]):
        w.append((t[a],t[b],D[a:b+1].min(),tau[a:b+1].max()))
    return w
tot_wall=0; saved={5e-3:0,1e-2:0}
for law,ab,ca,out,tf,md,mt,wall,dt in rows:
    if tf<39.9: continue
    f=h5py.File(out,'r'); t=f['timeseries/t'][:]; D=f['timeseries/D12'][:]; tau=f['timeseries/tau_min'][:]
    n=np.searchsorted(t, tf+1e-9); t,D,tau=t[:n],D[:n],tau[:n]
    w=windows(t,D,tau)
    tot_wall+=wall
    line=f"{law[:2]} ab{ab} Ca{ca} dt{dt} tf{tf:.0f} final(minD12 {md:.4f}, maxtau {mt:.4f}) periods:"
    for a,b,m,x in w[-5:]: line+=f" [{a:.1f},{b:.1f}] {m:.4f}/{x:.4f};"
    print(line)
    for tol in (2e-3,5e-3,1e-2):
        stop=None
        for k in range(1,len(w)):
            p0,p1=w[k-1],w[k]
            if abs(p1[2]-p0[2])<=tol and abs(p1[3]-p0[3])<=tol and abs((p1[1]-p1[0])/(p0[1]-p0[0])-1)<=0.02:
                stop=(p1[1],p1[2],p1[3]); break
        if stop: print(f"   tol {tol}: stop at {stop[0]:.1f}: minD12 {stop[1]:.4f} ({stop[1]-md:+.1e}) maxtau {stop[2]:.4f} ({stop[2]-mt:+.1e})")
        else: print(f"   tol {tol}: no stop")
        if stop and tol in saved: saved[tol]+=wall*(1-stop[0]/tf)
print("wall of t_end cases", tot_wall, "saved", saved)

"""Run time against error for the two reference problems (see scripts/pareto).

(a) sphere, Skalak C = 1, Ca = 0.3: the steady Taylor parameter D12 (interpolated at γ̇t = 5.9; the table
    gives the remaining drift |dD12/dt| over γ̇t ∈ [5, 5.9], which bounds how far from steady it still is);
(b) a/b = 2, Skalak C = 1, Ca = 0.3: the first minimum of D12 (a parabola fitted to D12² at the five lowest
    samples: the section becomes almost round there, and D12 itself has a cusp).
Each variant changes one numerical knob from the default (level, time.dt_accuracy of RKC, the rk2 scheme,
numerics.regular_degree, numerics.far_degree); the error is measured against the finest run of the study
(level 4, default knobs): level 5 would take days on this machine, so the level-4 points have no error bar
of their own and the level-3 errors include the level-4 error (≈ the level-3/4 difference is an upper bound).
"""
import argparse
import json
import os
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

STUDIES = {
    "sphere": dict(title="sphere, Skalak, Ca = 0.3: steady D12", base=["capsule.aspect_ratio=1", "time.t_end=6"],
                   metric="steady_D12"),
    "prolate": dict(title="a/b = 2, Skalak, Ca = 0.3: first min D12", base=["capsule.aspect_ratio=2", "time.t_end=4.5"],
                    metric="first_min_D12"),
}
COMMON = ["capsule.law=skalak", "capsule.skalak_C=1", "flow.capillary_number=0.3", "time.check_interval=1000"]


def variants(levels, far):
    v = []
    for L in levels:
        v.append((f"L{L}_default", [f"mesh.level={L}"]))
        if L == max(levels):
            continue  # the reference: one run at the finest level
        for dta in (0.01, 0.04):
            v.append((f"L{L}_dt{dta}", [f"mesh.level={L}", f"time.dt_accuracy={dta}"]))
        v.append((f"L{L}_deg6", [f"mesh.level={L}", "numerics.regular_degree=6"]))
        v.append((f"L{L}_rk2", [f"mesh.level={L}", "time.scheme=rk2"]))
        if far:
            for fd, fr in ((1, 4.0), (2, 3.0), (2, 4.0)):
                v.append((f"L{L}_far{fd}r{fr:g}", [f"mesh.level={L}", f"numerics.far_degree={fd}",
                                                   f"numerics.far_radius={fr}"]))
    return v


def metric(case_file, kind):
    with h5py.File(case_file, "r") as f:
        t = f["timeseries/t"][:]
        d = f["timeseries/D12"][:]
    if kind == "steady_D12":
        t_eval = 5.9
        slope = (np.interp(t_eval, t, d) - np.interp(5.0, t, d)) / (t_eval - 5.0)
        return float(np.interp(t_eval, t, d)), float(abs(slope))
    mask = t >= 1.0  # the first minimum: γ̇t ≈ 3.5 at every level
    t, d = t[mask], d[mask]
    # D12 = (L1 − L2)/(L1 + L2) has a cusp where the section is nearly round (L1 − L2 is the modulus of a
    # smooth tensor difference), but D12² is smooth: fit the parabola to D12² through the five lowest samples.
    i = int(np.argmin(d))
    i = min(max(i, 2), len(d) - 3)
    a, b, c = np.polyfit(t[i - 2:i + 3], d[i - 2:i + 3] ** 2, 2)
    tm = -b / (2 * a)
    return float(np.sqrt(max(np.polyval([a, b, c], tm), 0.0))), float(tm)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--levels", default="2,3,4")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--only", choices=list(STUDIES))
    ap.add_argument("--far", action="store_true", help="include the distance-adaptive quadrature variants")
    ap.add_argument("--capsim", default=os.path.join(HERE, "build", "bin", "capsim"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "pareto"))
    ap.add_argument("--fig-dir", default=os.path.join(HERE, "results", "pareto"))
    ap.add_argument("--runs", default=None, help="where the case folders go (default: OUT/runs, not committed)")
    args = ap.parse_args()
    levels = [int(x) for x in args.levels.split(",")]
    runs = args.runs or os.path.join(args.out, "runs")
    if not os.access(args.capsim, os.X_OK):
        sys.exit(f"pareto: {args.capsim} not found: build first (cmake --build build)")
    md = ["# Run time against error (`scripts/pareto`)", ""]
    figs = []
    for name, st in STUDIES.items():
        if args.only and name != args.only:
            continue
        os.makedirs(os.path.join(args.out, name), exist_ok=True)
        rows = []
        for vname, sets in variants(levels, args.far):
            jf = os.path.join(args.out, name, vname + ".json")
            if not os.path.exists(jf):
                cmd = [args.capsim, "run", "-", "--json", "--threads", str(args.threads),
                       "--out", os.path.join(runs, name, vname)]
                for s in COMMON + st["base"] + sets:
                    cmd += ["--set", s]
                print("pareto:", " ".join(cmd), flush=True)
                out = subprocess.run(cmd, capture_output=True, text=True)
                if out.returncode != 0:
                    print(out.stderr[-2000:], file=sys.stderr)
                    sys.exit(f"pareto: {vname} failed (exit {out.returncode})")
                j = json.loads(out.stdout.strip().splitlines()[-1])
                j["metric"], j["metric_t"] = metric(j["case_file"], st["metric"])
                j["variant"], j["sets"] = vname, sets
                with open(jf, "w") as f:
                    json.dump(j, f, indent=1)
            with open(jf) as f:
                rows.append(json.load(f))
        ref = [r for r in rows if r["variant"] == f"L{max(levels)}_default"][0]
        for r in rows:
            r["error"] = abs(r["metric"] - ref["metric"])
        # Pareto front: no other run is both faster and more accurate.
        for r in rows:
            r["front"] = not any(o is not r and o["wall_s"] <= r["wall_s"] and o["error"] < r["error"] for o in rows
                                 if o is not ref) and r is not ref
        col = "drift dD12/dt" if st["metric"] == "steady_D12" else "at γ̇t"
        md += [f"## {st['title']}", "",
               f"Reference: {ref['variant']} = {ref['metric']:.6f} ({col}: {ref['metric_t']:.3g}), "
               f"{ref['flow_evaluations']} evaluations, {ref['wall_s']:.0f} s on {ref['threads']} threads.", "",
               f"| variant | evaluations | wall s | metric | {col} | error vs reference | on the front |",
               "|---|---|---|---|---|---|---|"]
        for r in sorted(rows, key=lambda r: r["wall_s"]):
            md.append(f"| {r['variant']} | {r['flow_evaluations']} | {r['wall_s']:.1f} | {r['metric']:.6f} | "
                      f"{r['metric_t']:.3g} | {r['error']:.2e} | {'yes' if r['front'] else ''} |")
        md.append("")
        figs.append((name, st, rows, ref))
    with open(os.path.join(args.out, "pareto.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig_dir = args.fig_dir
    os.makedirs(fig_dir, exist_ok=True)
    for name, st, rows, ref in figs:
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        pts = [r for r in rows if r is not ref]
        for r in pts:
            lvl = r["mesh_level"]
            ax.loglog(r["wall_s"], max(r["error"], 1e-9), "o", color=f"C{lvl}", ms=7 if r["front"] else 5,
                      mfc="none" if not r["front"] else f"C{lvl}")
            ax.annotate(r["variant"], (r["wall_s"], max(r["error"], 1e-9)), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
        front = sorted([r for r in pts if r["front"]], key=lambda r: r["wall_s"])
        ax.loglog([r["wall_s"] for r in front], [max(r["error"], 1e-9) for r in front], "k--", lw=0.8,
                  label="Pareto front")
        ax.set_xlabel(f"wall time [s] ({ref['threads']} threads)")
        ax.set_ylabel(f"|error| vs {ref['variant']}")
        ax.set_title(st["title"])
        ax.legend()
        fig.tight_layout()
        path = os.path.join(fig_dir, f"pareto_{name}.png")
        fig.savefig(path, dpi=120)
        print("pareto: wrote", path)


if __name__ == "__main__":
    main()

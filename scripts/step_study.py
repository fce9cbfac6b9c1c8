"""Flow evaluations per unit of simulated time against time-step error (see scripts/step_study).

Three reference cases, mesh level 3, shear flow from rest, γ̇t ∈ [0, 4]:
  (a) oblate a/b = 0.5, neo-Hookean, Ca = 0.02   (stiff: RKC with many stages)
  (b) prolate a/b = 2, Skalak C = 1, Ca = 0.1
  (c) prolate a/b = 2, Skalak C = 1, Ca = 0.9    (mild stiffness: few stages)
Each variant is `capsim run` with some `--set`s on top of the case. The cost is flow_evaluations / t_final
(deterministic, unlike wall time). The error is against the converged reference of the same case, the
default scheme at a fixed time.dt = 0.005 (a quarter of the old automatic dt 0.02): the largest
|ΔD12| and |ΔτMin| over the variant's samples with γ̇t ∈ [1, 4], the reference interpolated linearly in time
(its samples are 0.005 apart: the interpolation error is ≈ 3e-6 in D12). The criterion of the issue is
max |ΔD12| ≤ 2e-4 and max |ΔτMin| ≤ 1e-3.

Resumable: a variant whose JSON exists in OUT/<case>/ is not run again (delete it to re-run). The case
folders (case.h5) go to OUT/runs/, which is not committed. Writes OUT/step_study.md.
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CASES = {
    "a": dict(title="(a) oblate a/b = 0.5, neo-Hookean, Ca = 0.02",
              sets=["capsule.law=neo-hookean", "capsule.aspect_ratio=0.5", "flow.capillary_number=0.02"]),
    "b": dict(title="(b) prolate a/b = 2, Skalak, Ca = 0.1",
              sets=["capsule.law=skalak", "capsule.skalak_C=1", "capsule.aspect_ratio=2",
                    "flow.capillary_number=0.1"]),
    "c": dict(title="(c) prolate a/b = 2, Skalak, Ca = 0.9",
              sets=["capsule.law=skalak", "capsule.skalak_C=1", "capsule.aspect_ratio=2",
                    "flow.capillary_number=0.9"]),
}
COMMON = ["mesh.level=3", "time.t_end=4", "time.check_interval=1000"]
REFERENCE = ("reference", ["time.dt=0.005"])
WINDOW = (1.0, 4.0)
D12_TOL, TAU_TOL = 2e-4, 1e-3


def parse_variants(specs):
    """'name:key=v,key=v' → (name, [key=v, ...]); 'name:' is the build's defaults."""
    out = []
    for spec in specs:
        name, _, sets = spec.partition(":")
        out.append((name, [s for s in sets.split(",") if s]))
    return out


DEFAULT_VARIANTS = [
    "default:",
]


def series(case_file):
    with h5py.File(case_file, "r") as f:
        return f["timeseries/t"][:], f["timeseries/D12"][:], f["timeseries/tau_min"][:]


def errors(case_file, ref_file, window=WINDOW):
    t, d, tau = series(case_file)
    tr, dr, taur = series(ref_file)
    m = (t >= window[0] - 1e-9) & (t <= min(window[1], tr[-1]) + 1e-9)
    if not m.any():
        return float("nan"), float("nan")
    dD = np.abs(d[m] - np.interp(t[m], tr, dr))
    dT = np.abs(tau[m] - np.interp(t[m], tr, taur))
    return float(np.max(dD)), float(np.max(dT))


# Where in time the error arises: the same maxima per unit interval (the start-up from rest is [0, 1]).
PROFILE = [(0.0, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 3.0), (3.0, 4.0)]


def run(capsim, threads, out_dir, case, vname, sets):
    cmd = ["nice", "-n", "19", capsim, "run", "-", "--json", "--threads", str(threads), "--out", out_dir]
    for s in COMMON + CASES[case]["sets"] + sets:
        cmd += ["--set", s]
    print("step_study:", " ".join(cmd), flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True)
    lines = p.stdout.strip().splitlines()
    if not lines:
        raise RuntimeError(f"{case}/{vname} failed (exit {p.returncode}): {p.stderr[-2000:]}")
    j = json.loads(lines[-1])
    j["variant"], j["sets"], j["exit_code"] = vname, sets, p.returncode
    return j


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="a,b,c")
    ap.add_argument("--variant", action="append", default=None,
                    help="name:key=value,key=value (repeatable; default: the build's defaults only)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2, help="runs at once (each with --threads)")
    ap.add_argument("--capsim", default=os.path.join(HERE, "build", "bin", "capsim"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "time_steps"))
    ap.add_argument("--table-only", action="store_true", help="no runs: tabulate the JSONs in OUT")
    args = ap.parse_args()
    cases = args.cases.split(",")
    variants = parse_variants(args.variant or DEFAULT_VARIANTS)
    if not args.table_only and not os.access(args.capsim, os.X_OK):
        sys.exit(f"step_study: {args.capsim} not found: build first")

    def jpath(case, vname):
        return os.path.join(args.out, case, vname + ".json")

    def rundir(case, vname):
        return os.path.join(args.out, "runs", case, vname)

    if args.table_only:
        # Refresh the errors from the case folders where they are present (they are not committed).
        for c in cases:
            d = os.path.join(args.out, c)
            ref_case = os.path.join(rundir(c, REFERENCE[0]), "case.h5")
            for fn in sorted(os.listdir(d)) if os.path.isdir(d) else []:
                if not fn.endswith(".json") or not os.path.exists(ref_case):
                    continue
                with open(os.path.join(d, fn)) as fh:
                    j = json.load(fh)
                if os.path.exists(j["case_file"]):
                    j["max_dD12"], j["max_dtau_min"] = errors(j["case_file"], ref_case)
                    j["error_profile"] = [[a, b, *errors(j["case_file"], ref_case, (a, b))] for a, b in PROFILE]
                    with open(os.path.join(d, fn), "w") as fh:
                        json.dump(j, fh, indent=1)
    if not args.table_only:
        for c in cases:
            os.makedirs(os.path.join(args.out, c), exist_ok=True)
        todo = [(c, *REFERENCE) for c in cases] + [(c, n, s) for c in cases for n, s in variants]
        todo = [t for t in todo if not os.path.exists(jpath(t[0], t[1]))]
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as ex:
            futs = {ex.submit(run, args.capsim, args.threads, rundir(c, n), c, n, s): (c, n) for c, n, s in todo}
            for f in concurrent.futures.as_completed(futs):
                c, n = futs[f]
                j = f.result()
                with open(jpath(c, n) + ".raw", "w") as fh:
                    json.dump(j, fh, indent=1)
                print(f"step_study: {c}/{n}: {j['status']} {j['flow_evaluations']} evaluations", flush=True)
        # Errors once every reference exists.
        for c in cases:
            for n, _ in [REFERENCE] + variants:
                raw = jpath(c, n) + ".raw"
                if not os.path.exists(raw):
                    continue
                with open(raw) as fh:
                    j = json.load(fh)
                ref_case = os.path.join(rundir(c, REFERENCE[0]), "case.h5")
                j["max_dD12"], j["max_dtau_min"] = errors(j["case_file"], ref_case)
                j["error_profile"] = [[a, b, *errors(j["case_file"], ref_case, (a, b))] for a, b in PROFILE]
                with open(jpath(c, n), "w") as fh:
                    json.dump(j, fh, indent=1)
                os.remove(raw)

    md = ["# Flow evaluations per unit time against time-step error (`scripts/step_study`)", "",
          "Level 3, shear flow from rest to γ̇t = 4, 1 thread. Cost = flow_evaluations / t_final. Errors: largest "
          f"difference from the reference (time.dt = 0.005) over γ̇t ∈ [{WINDOW[0]:g}, {WINDOW[1]:g}]; criterion "
          f"|ΔD12| ≤ {D12_TOL:g}, |ΔτMin| ≤ {TAU_TOL:g}.", ""]
    for c in cases:
        d = os.path.join(args.out, c)
        if not os.path.isdir(d):
            continue
        rows = []
        for fn in sorted(os.listdir(d)):
            if fn.endswith(".json"):
                with open(os.path.join(d, fn)) as fh:
                    rows.append(json.load(fh))
        md += [f"## {CASES[c]['title']}", "",
               "| variant | sets | status | t_final | steps | evaluations | per unit time | mean stages | "
               "max abs dD12 | max abs dtau_min | meets criterion |",
               "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in sorted(rows, key=lambda r: -r["flow_evaluations"] / max(r["t_final"], 1e-30)):
            per = r["flow_evaluations"] / r["t_final"] if r["t_final"] else float("nan")
            ok = r["status"] == "done" and r["max_dD12"] <= D12_TOL and r["max_dtau_min"] <= TAU_TOL
            ok = "reference" if r["variant"] == REFERENCE[0] else ("yes" if ok else "**no**")
            md.append(f"| {r['variant']} | {' '.join(r['sets']) or '(defaults)'} | {r['status']} | "
                      f"{r['t_final']:.3f} | {r['steps']} | {r['flow_evaluations']} | {per:.0f} | "
                      f"{r['flow_evaluations'] / max(r['steps'], 1):.2f} | {r['max_dD12']:.2e} | "
                      f"{r['max_dtau_min']:.2e} | {ok} |")
        md += ["", "Where the error arises (max abs dD12 / max abs dtau_min per interval of γ̇t):", "",
               "| variant | " + " | ".join(f"[{a:g}, {b:g}]" for a, b in PROFILE) + " |",
               "|---|" + "---|" * len(PROFILE)]
        for r in sorted(rows, key=lambda r: -r["flow_evaluations"] / max(r["t_final"], 1e-30)):
            if r["variant"] == REFERENCE[0] or "error_profile" not in r:
                continue
            md.append(f"| {r['variant']} | " + " | ".join(f"{e[2]:.1e} / {e[3]:.1e}" for e in r["error_profile"]) + " |")
        md.append("")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "step_study.md"), "w") as fh:
        fh.write("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    main()

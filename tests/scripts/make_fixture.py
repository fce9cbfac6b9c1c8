#!/usr/bin/python3
"""Synthetic campaign database for the tests of scripts/plot and scripts/table1.

usage: make_fixture.py SOURCE_DIR OUT.sqlite [CASE_H5]

Applies the real schema (schemas/001_campaign_v1.sql, so `capsim query` reads the result), then adds one campaign
'fixture' with done/unstable cases for figure 3 and a transitions table built from results/seed_table1.json so
that, against the seed, exactly: 3 cells agree, 2 disagree, 5 are missing. CASE_H5, if given, becomes the case
file of the Skalak a/b = 2, Ca = 0.9 case (figure 2 from the database).
"""
import json
import os
import sqlite3
import sys

src, out = sys.argv[1], sys.argv[2]
h5 = sys.argv[3] if len(sys.argv) > 3 else None
with open(os.path.join(src, "schemas", "001_campaign_v1.sql")) as f:
    schema = f.read()
with open(os.path.join(src, "results", "seed_table1.json")) as f:
    seed = {(c["law"], c["aspect_ratio"]): c for c in json.load(f)["cells"]}

if os.path.exists(out):
    os.remove(out)
con = sqlite3.connect(out)
con.executescript(schema)
now = "2026-01-01T00:00:00Z"
con.execute("INSERT INTO campaigns(campaign_id, name, spec_json, created_at, updated_at) "
            "VALUES (1, 'fixture', '{}', ?, ?)", (now, now))

cases = []  # law, a/b, Ca, status, min_D12, max_tau_min
for law in ("neo-hookean", "skalak"):
    for ca, d, tau in [(0.01, 0.20, 0.10), (0.02, 0.08, 0.05), (0.03, 0.03, 0.02), (0.05, 0.04, 0.01),
                       (0.1, 0.12, -0.01), (1.0, 0.3, -0.2)]:
        cases.append((law, 0.5, ca, "done", d, tau if law == "neo-hookean" else tau + 0.05))
    for ca, d, tau in [(0.1, 0.17, 0.2), (0.2, 0.08, 0.1), (0.3, 0.02, 0.05), (0.5, 0.12, 0.02), (0.9, 0.27, -0.01)]:
        cases.append((law, 2.0, ca, "done", d + (0.02 if law == "skalak" else 0), tau))
cases.append(("skalak", 2.0, 2.0, "unstable", 0.35, -0.3))

for i, (law, ar, ca, status, d, tau) in enumerate(cases):
    cid = f"case{i:04d}"
    path = h5 if (h5 and law == "skalak" and ar == 2.0 and ca == 0.9) else None
    con.execute("INSERT INTO cases(case_id, params_json, capillary_number, aspect_ratio, law, skalak_C, mesh_level, "
                "solver_version, status, created_at, h5_path) VALUES (?, '{}', ?, ?, ?, ?, 1, '1', ?, ?, ?)",
                (cid, ca, ar, law, 1.0 if law == "skalak" else None, status, now, path))
    con.execute("INSERT INTO campaign_cases(campaign_id, case_id) VALUES (1, ?)", (cid,))
    con.execute("INSERT INTO results(case_id, status, min_D12, max_tau_min, regime, raw_json, recorded_at) "
                "VALUES (?, ?, ?, ?, ?, '{}', ?)",
                (cid, status, d, tau, "tumbling" if d > 0.1 and ca < 0.2 else "swinging", now))


def transition(law, ar, lo=None, hi=None, h=None, h_lo=None, h_hi=None, note=""):
    con.execute("INSERT INTO transitions(campaign_id, law, aspect_ratio, skalak_C, mesh_level, d12_threshold, "
                "n_samples, ca_star_low, ca_star_high, ca_h, ca_h_low, ca_h_high, method, note, updated_at) "
                "VALUES (1, ?, ?, ?, 1, 0.05, 5, ?, ?, ?, ?, ?, 'grid', ?, ?)",
                (law, ar, 1.0 if law == "skalak" else -1.0, lo, hi, h, h_lo, h_hi, note, now))


nh05, nh2, sk05 = seed[("neo-hookean", 0.5)], seed[("neo-hookean", 2.0)], seed[("skalak", 0.5)]
# agrees: overlapping Ca* interval, CaH within 3 %
transition("neo-hookean", 0.5, nh05["ca_star_low"] + 0.01, nh05["ca_star_high"] + 0.01, nh05["ca_h"] * 1.03,
           nh05["ca_h"] * 0.9, nh05["ca_h"] * 1.1)
# disagrees: Ca* interval above the seed's; CaH only bounded from below, far above the seed's
transition("neo-hookean", 2.0, nh2["ca_star_high"] + 0.05, nh2["ca_star_high"] + 0.10, None, 2.0, None,
           "max_tau_min >= 0 at the largest sampled Ca: CaH above 2")
# Ca* missing (not bracketed), CaH agrees
transition("skalak", 0.5, None, None, sk05["ca_h"] * 0.92, 2.0, 2.5,
           "min_D12 never below 0.05 (smallest 0.06 at Ca=0.03)")
# skalak a/b = 2 and both a/b = 1: no transition row (not sampled)
con.commit()
con.close()
print(out)

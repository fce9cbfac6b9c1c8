-- capsim campaign database, schema version 3: transitions keyed by group.
-- A transition is computed per group of cases that agree in every identity key except Ca; a grid axis over
-- any key (time.dt, numerics.*) makes several groups with the same law, a/b, C and level, so the key of a
-- row is its group_key: the canonical JSON object of those identity keys (the solver's resolved values, as in
-- the case identity). SQLite cannot change a primary key in place, so the table is rebuilt. The store applies
-- this file once, to a database older than version 3, inside the migration transaction (a fresh database
-- gets 001..003 in order); version-2 databases are read as they are (no group_key column: one group per
-- law, a/b, C and level, as they were computed).

PRAGMA user_version = 3;

CREATE TABLE transitions_v3 (
  campaign_id      INTEGER NOT NULL REFERENCES campaigns(campaign_id),
  group_key        TEXT NOT NULL,             -- JSON: every identity key of the group except flow.capillary_number
  law              TEXT NOT NULL,
  aspect_ratio     REAL NOT NULL,
  skalak_C         REAL NOT NULL DEFAULT -1,  -- -1 for neo-hookean
  mesh_level       INTEGER NOT NULL,
  d12_threshold    REAL NOT NULL,
  n_samples        INTEGER NOT NULL,          -- finished cases (done) used
  ca_star_low      REAL,                      -- smallest sampled Ca with min_D12 < threshold
  ca_star_high     REAL,                      -- largest sampled Ca with min_D12 < threshold
  ca_star_below    REAL,                      -- nearest sampled Ca under the interval (min_D12 >= threshold)
  ca_star_above    REAL,                      -- nearest sampled Ca over the interval
  ca_min_d12       REAL,                      -- sampled Ca with the smallest min_D12
  ca_h             REAL,                      -- zero of max_tau_min, linear between the bracket samples
  ca_h_low         REAL,                      -- bracket: last Ca with max_tau_min >= 0
  ca_h_high        REAL,                      -- bracket: first Ca above it with max_tau_min < 0
  ca_h_low_case    TEXT REFERENCES cases(case_id),
  ca_h_high_case   TEXT REFERENCES cases(case_id),
  method           TEXT NOT NULL,             -- 'grid' or 'adaptive'
  note             TEXT NOT NULL DEFAULT '',
  updated_at       TEXT NOT NULL,
  PRIMARY KEY (campaign_id, group_key)
);

-- Rows of version 2 were one per (law, a/b, C, level): their key names those four (the next analysis of
-- the campaign replaces them with full group keys).
INSERT INTO transitions_v3
  SELECT campaign_id,
         json_object('capsule.law', law, 'capsule.aspect_ratio', aspect_ratio, 'mesh.level', mesh_level,
                     'capsule.skalak_C', CASE WHEN skalak_C < 0 THEN NULL ELSE skalak_C END, 'schema', 2),
         law, aspect_ratio, skalak_C, mesh_level, d12_threshold, n_samples, ca_star_low, ca_star_high,
         ca_star_below, ca_star_above, ca_min_d12, ca_h, ca_h_low, ca_h_high, ca_h_low_case, ca_h_high_case,
         method, note, updated_at
  FROM transitions;
DROP TABLE transitions;
ALTER TABLE transitions_v3 RENAME TO transitions;

-- capsim campaign database, schema version 1.
-- Embedded into the binary at build time (cmake/EmbedSchema.cmake -> capsim::kSchemaSql) and applied once,
-- in one transaction, when a new database is created, before any worker starts. The version lives in
-- PRAGMA user_version (and application_id marks the file as a capsim database); a database with another
-- version is refused with a clear error. Later versions add 00N_*.sql files (see 002_slurm_v2.sql) and raise it.
-- Only the campaign manager writes this file (WAL journal); queries open it read-only.

PRAGMA application_id = 1129336909;  -- 0x4350534D, "CPSM"
PRAGMA user_version = 1;

-- Key/value facts about the database itself (creation time, creating code version).
CREATE TABLE IF NOT EXISTS meta (
  key   TEXT PRIMARY KEY,
  value TEXT NOT NULL
);

-- One row per campaign file name; spec_json is the validated campaign as last run.
CREATE TABLE IF NOT EXISTS campaigns (
  campaign_id  INTEGER PRIMARY KEY,
  name         TEXT NOT NULL UNIQUE,
  description  TEXT NOT NULL DEFAULT '',
  source_path  TEXT,
  spec_json    TEXT NOT NULL,
  created_at   TEXT NOT NULL,
  updated_at   TEXT NOT NULL
);

-- One row per case identity (hash of the parameters that change results + solver version). The same case
-- in two campaigns is one row.
CREATE TABLE IF NOT EXISTS cases (
  case_id          TEXT PRIMARY KEY,
  params_json      TEXT NOT NULL,          -- every case key, dotted names
  capillary_number REAL NOT NULL,
  aspect_ratio     REAL NOT NULL,
  law              TEXT NOT NULL,
  skalak_C         REAL,                   -- NULL for neo-hookean (not part of its identity)
  mesh_level       INTEGER NOT NULL,
  solver_version   TEXT NOT NULL,          -- version that entered the identity
  status           TEXT NOT NULL DEFAULT 'queued'
                   CHECK (status IN ('queued', 'running', 'done', 'unstable', 'failed')),
  resumable        INTEGER NOT NULL DEFAULT 0,  -- 1: a checkpoint exists, the next start passes --resume
  attempts         INTEGER NOT NULL DEFAULT 0,
  est_cost         REAL NOT NULL DEFAULT 1,
  created_at       TEXT NOT NULL,
  started_at       TEXT,
  finished_at      TEXT,
  wall_s           REAL,                   -- manager-measured wall time of the last attempt
  host             TEXT,
  worker_pid       INTEGER,
  exit_code        INTEGER,
  code_version     TEXT,                   -- reported by the worker
  error            TEXT,                   -- reason of failure/instability, stderr tail
  out_dir          TEXT,
  h5_path          TEXT
);
CREATE INDEX IF NOT EXISTS cases_status ON cases(status);
CREATE INDEX IF NOT EXISTS cases_group ON cases(law, aspect_ratio, skalak_C, mesh_level, capillary_number);

-- Membership; origin = 'grid' (expanded from the file) or 'adaptive' (added by the analysis).
CREATE TABLE IF NOT EXISTS campaign_cases (
  campaign_id INTEGER NOT NULL REFERENCES campaigns(campaign_id),
  case_id     TEXT NOT NULL REFERENCES cases(case_id),
  origin      TEXT NOT NULL DEFAULT 'grid' CHECK (origin IN ('grid', 'adaptive')),
  PRIMARY KEY (campaign_id, case_id)
);

-- The recorded outcome of a case (status done or unstable); exactly one row per finished case.
CREATE TABLE IF NOT EXISTS results (
  case_id      TEXT PRIMARY KEY REFERENCES cases(case_id),
  status       TEXT NOT NULL CHECK (status IN ('done', 'unstable')),
  min_D12      REAL,
  max_tau_min  REAL,
  mean_D12     REAL,
  period       REAL,
  regime       TEXT,
  volume_drift REAL,
  steps        INTEGER,
  dt           REAL,
  t_final      REAL,
  wall_s       REAL,                       -- reported by the worker
  code_version TEXT,
  raw_json     TEXT NOT NULL,              -- the worker's full JSON line
  recorded_at  TEXT NOT NULL
);

-- Every start and end of a worker, for audits ("each case finished exactly once").
CREATE TABLE IF NOT EXISTS attempts (
  attempt_id  INTEGER PRIMARY KEY,
  case_id     TEXT NOT NULL REFERENCES cases(case_id),
  started_at  TEXT NOT NULL,
  finished_at TEXT,
  host        TEXT,
  worker_pid  INTEGER,
  resumed     INTEGER NOT NULL DEFAULT 0,
  outcome     TEXT,   -- done | unstable | failed | interrupted | orphaned | ingested
  exit_code   INTEGER,
  error       TEXT
);
CREATE INDEX IF NOT EXISTS attempts_case ON attempts(case_id);

-- Critical capillary numbers per (campaign, law, a/b, C, mesh level), recomputed after every run.
CREATE TABLE IF NOT EXISTS transitions (
  campaign_id      INTEGER NOT NULL REFERENCES campaigns(campaign_id),
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
  PRIMARY KEY (campaign_id, law, aspect_ratio, skalak_C, mesh_level)
);
